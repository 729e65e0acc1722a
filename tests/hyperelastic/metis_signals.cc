// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

// METIS must leave palpate's stop handler as it was. GKlib (METIS's
// library) sets SIGTERM to its own handler during every call and puts the
// previous one back with System V signal(), as a one-shot (SA_RESETHAND):
// a second SIGTERM within the 0.5 s that palpate takes for one stop
// delivered twice (`timeout` signals a process and its group) would then
// kill `palpate precompute` before it wrote its summary and released the
// store's lock. Here: with a StopRequest living,
// MUMPS analyses a 400-unknown five-point pattern with the METIS ordering
// (palpate's own call of METIS_NodeND), and the SIGTERM disposition must be
// unchanged (handler and flags); then two SIGTERMs raised back to back
// must be one stop, with the process alive to say so.

#include <palpate/base/stop_request.h>
#include <palpate/hyperelastic/linear_solver.h>

#include <signal.h>

#include <set>

#include "../tests.h"

namespace
{
  /** -Laplace(u) + u on an m x m grid (five-point stencil), pattern only. */
  palpate::SparsityCSR
  five_point(const unsigned int m)
  {
    palpate::SparsityCSR p;
    p.n_rows = m * m;
    p.row_start.push_back(0);
    for (unsigned int i = 0; i < m; ++i)
      for (unsigned int j = 0; j < m; ++j)
        {
          const unsigned int     k   = i * m + j;
          std::set<unsigned int> row = {k};
          if (i > 0)
            row.insert(k - m);
          if (j > 0)
            row.insert(k - 1);
          if (j + 1 < m)
            row.insert(k + 1);
          if (i + 1 < m)
            row.insert(k + m);
          p.column.insert(p.column.end(), row.begin(), row.end());
          p.row_start.push_back(p.column.size());
        }
    return p;
  }
} // namespace

int
main(int argc, char **argv)
{
  palpate::Environment env(argc, argv);
  initlog();
  const palpate::StopRequest stop;
  struct sigaction           before
  {
  }, after{};
  sigaction(SIGTERM, nullptr, &before);

  const palpate::SparsityCSR pattern = five_point(20);
  const auto solver = palpate::LinearSolver::create("MUMPS", "METIS");
  solver->analyze(pattern);
  deallog << "analysed with " << solver->name() << ", n = " << pattern.n_rows
          << ", " << pattern.n_nonzeros() << " entries" << std::endl;

  sigaction(SIGTERM, nullptr, &after);
  deallog << "SIGTERM handler unchanged: "
          << (after.sa_handler == before.sa_handler ? "yes" : "no")
          << std::endl;
  deallog << "SIGTERM flags unchanged: "
          << (after.sa_flags == before.sa_flags ? "yes" : "no") << std::endl;
  deallog << "one-shot (SA_RESETHAND): "
          << ((after.sa_flags & SA_RESETHAND) != 0 ? "yes" : "no") << std::endl;

  // raise() runs the handler before it returns: on the old code the
  // second one found SIG_DFL and ended the test here, with no more output.
  raise(SIGTERM);
  raise(SIGTERM);
  deallog << "two SIGTERMs back to back: alive, stop requested by "
          << stop.description() << std::endl;
}
