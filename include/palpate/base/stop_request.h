// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

#ifndef palpate_base_stop_request_h
#define palpate_base_stop_request_h

#include <stdexcept>
#include <string>

namespace palpate
{
  /**
   * A stop asked for from outside: SIGINT (Ctrl-C), SIGTERM (kill, a batch
   * system, mpirun passing one on) and SIGHUP (the terminal closed).
   *
   * While an object lives, these signals only set a flag; the driver that
   * created it polls requested() where it waits anyway (the interaction's
   * watch loop, serve's main loop, the study between runs, precompute
   * between progress lines) and ends through its normal path, so that the
   * run summary, the force log, the CSV/JSON summaries and the PVD index are
   * written as after a run that ended by itself. Then the driver returns
   * exit_status(): 128 + the signal's number, the shells' convention
   * (130 for Ctrl-C), documented in doc/bad-input.md.
   *
   * A second such signal ends the process at once (the default action): a
   * user who presses Ctrl-C twice means it. One that comes within 0.5 s
   * of the first is the same stop delivered twice (`timeout` and process
   * managers signal the process and its group) and is ignored.
   *
   * SIGPIPE is not among them: the program ignores it (see
   * ignore_broken_pipes()), so that a closed pipe on standard output
   * becomes a write error the drivers see and handle, not a silent death.
   *
   * Only one StopRequest may live at a time (the handlers are process
   * wide); the destructor puts back the handlers that were there before.
   */
  class StopRequest
  {
  public:
    StopRequest();
    ~StopRequest();

    StopRequest(const StopRequest &) = delete;
    StopRequest &
    operator=(const StopRequest &) = delete;

    /** Whether a stop signal arrived. Async-signal-safe to call. */
    bool
    requested() const noexcept;

    /** Whether a StopRequest lives and a stop signal arrived: for work
     * deep below the driver that must end early (meshing in a child
     * process), without the driver's object at hand. */
    static bool
    pending() noexcept;

    /** The signal that asked for the stop (0 if none). */
    int
    signal_number() const noexcept;

    /** "SIGINT (Ctrl-C)", "SIGTERM", "SIGHUP (the terminal closed)". */
    std::string
    description() const;

    /** 128 + signal_number(): what a shell expects after that signal. */
    int
    exit_status() const noexcept;

    /** Ask for a stop as if @p signal had arrived (tests; a driver's own
     * reasons to stop early). */
    static void
    request(const int signal) noexcept;
  };

  /**
   * Ignore SIGPIPE for the whole process: writing to a closed pipe (`palpate
   * scene.prm | head -1`) or socket then fails with EPIPE, which the
   * writers see as an error, instead of killing palpate before it wrote its
   * files. Called once by the program at start.
   */
  void
  ignore_broken_pipes() noexcept;

  /**
   * Work that a stop signal (StopRequest) ended before it could produce
   * anything, with nothing left behind (meshing: the child killed, its
   * temporary files removed). The driver reports it and returns
   * exit_status, 128 + the signal's number.
   */
  class StoppedError : public std::runtime_error
  {
  public:
    /** @p what: what was stopped, e.g. "meshing 'liver.stl'". */
    explicit StoppedError(const std::string &what);

    int exit_status;
  };
} // namespace palpate

#endif
