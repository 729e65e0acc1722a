// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

#ifndef palpate_app_application_h
#define palpate_app_application_h

#include <iosfwd>

namespace palpate
{
  /** Exit statuses of the palpate program. */
  namespace ExitStatus
  {
    /** Everything asked for was done. */
    constexpr int success = 0;
    /** An internal error: a bug, or the machine ran out of something. */
    constexpr int internal_error = 1;
    /** Bad input: a scene, mesh or command-line problem the user can fix. */
    constexpr int input_error = 2;
    /** The scene asks for something this version cannot do yet. */
    constexpr int not_available = 3;
    /** A static solve ended in a failure point (no equilibrium found). */
    constexpr int solve_failed = 4;
    /** An MPI solver server was lost during the run (the summary says
     * which and why); what the others computed was used. A server whose
     * client was lost ends with it too. */
    constexpr int server_lost = 5;
    /** The run finished, but an output file could not be written. */
    constexpr int output_failed = 6;
    /** The run was stopped by SIGINT (Ctrl-C); what it finished is kept
     * and its outputs are written. SIGTERM and SIGHUP give 128 + their
     * number (143, 129), the shells' convention (StopRequest). */
    constexpr int interrupted = 130;
  } // namespace ExitStatus

  /**
   * The palpate command line: everything main() does after setting up the
   * Environment. Never throws: every error becomes a banner on @p err that
   * says what failed, in which input, and what to do, plus an exit status
   * from ExitStatus.
   */
  int
  run_application(int argc, char **argv, std::ostream &out, std::ostream &err);
} // namespace palpate

#endif
