// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

// MumpsLibrary lends each MUMPS solver a copy of the library of its own,
// so that solver workers factorise at the same time: two leases held at
// once are private; a released copy is lent again (no new load); with
// private copies switched off a lease is the shared, linked MUMPS. Two
// MUMPS solvers (double, then single precision) factorise and solve a
// 3-D Laplacian (n = 4,096) in two threads at once, 20 times each, through
// their own copies; every solution equals the one the shared copy gives
// alone to 1e-13 relative (double) and 1e-5 (single: the library built
// otherwise rounds otherwise, and single precision's forward error on this
// matrix is up to cond(A) eps = 120 x 6e-8). The same pair through the shared
// copy, under its lock, checks the reference path.

#include <palpate/base/environment.h>
#include <palpate/hyperelastic/linear_solver.h>
#include <palpate/hyperelastic/mumps_library.h>

#include <cmath>
#include <thread>

#include "../tests.h"

namespace
{
  /** Factorise and solve for a right-hand side of ones, @p rounds times;
   * the last solution. */
  std::vector<double>
  solve(palpate::LinearSolver &solver,
        const Laplacian       &system,
        const unsigned int     rounds)
  {
    std::vector<double> x;
    solver.analyze(system.pattern);
    for (unsigned int r = 0; r < rounds; ++r)
      {
        x.assign(system.pattern.n_rows, 1.0);
        if (!solver.factorize(system.values) || !solver.solve(x))
          return {};
      }
    return x;
  }

  double
  relative_difference(const std::vector<double> &a,
                      const std::vector<double> &b)
  {
    if (a.size() != b.size() || a.empty())
      return 1;
    double diff = 0, size = 0;
    for (unsigned int i = 0; i < a.size(); ++i)
      {
        diff = std::max(diff, std::abs(a[i] - b[i]));
        size = std::max(size, std::abs(b[i]));
      }
    return diff / size;
  }
} // namespace

int
main(int argc, char **argv)
{
  using palpate::MumpsLibrary;
  palpate::Environment env(argc, argv);
  initlog();

  const auto yes = [](const bool b) { return b ? "yes" : "no"; };
  {
    const auto a = MumpsLibrary::acquire(), b = MumpsLibrary::acquire();
    deallog << "two leases at once: private " << yes(a.is_private()) << ", "
            << yes(b.is_private()) << std::endl;
  }
  {
    const auto a = MumpsLibrary::acquire();
    deallog << "a released copy lent again: private " << yes(a.is_private())
            << "; " << MumpsLibrary::description() << std::endl;
  }
  const unsigned int limit = MumpsLibrary::max_private_copies();
  MumpsLibrary::set_max_private_copies(0);
  {
    const auto a = MumpsLibrary::acquire();
    deallog << "private copies switched off: private " << yes(a.is_private())
            << std::endl;
  }

  const Laplacian system(16);
  for (const std::string name : {"MUMPS", "MUMPS single"})
    {
      const double      tolerance = name == "MUMPS" ? 1e-13 : 1e-5;
      const std::string shown     = name == "MUMPS" ? "1e-13" : "1e-5";
      MumpsLibrary::set_max_private_copies(0);
      const std::vector<double> alone =
        solve(*palpate::LinearSolver::create(name, "METIS"), system, 1);
      for (const bool private_copies : {false, true})
        {
          MumpsLibrary::set_max_private_copies(private_copies ? limit : 0);
          const auto          s1 = palpate::LinearSolver::create(name, "METIS");
          const auto          s2 = palpate::LinearSolver::create(name, "METIS");
          std::vector<double> x1, x2;
          std::thread         t1([&] { x1 = solve(*s1, system, 20); });
          std::thread         t2([&] { x2 = solve(*s2, system, 20); });
          t1.join();
          t2.join();
          const double worst = std::max(relative_difference(x1, alone),
                                        relative_difference(x2, alone));
          deallog << name << ", "
                  << (private_copies ? "a copy per solver" : "one shared copy")
                  << ": two threads at once equal one alone to " << shown
                  << ": " << (worst <= tolerance ? "yes" : "NO") << std::endl;
        }
    }
  MumpsLibrary::set_max_private_copies(limit);
}
