// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

// Two solver workers at once, with every registered linear solver: two
// StateSolvers compute the same liver states (StVK, 1 and 2 cm pushes in
// four directions) in two threads at the same time, three times over, and
// every state equals the one computed alone (1e-12 relative).
//
// It caught Trilinos' Amesos_Mumps running MUMPS without palpate's MUMPS
// lock (a crash in MUMPS's load module). Debian's libopenblas0-serial,
// which gives wrong results when two threads call it, is why palpate
// installs the pthread build and sets one BLAS thread per caller; on this
// small liver the serial build's race did not show up here (measured:
// the test passes with either build), so the test guards the solvers'
// own thread safety, not the choice of BLAS build.

#include <palpate/hyperelastic/state_solver.h>

#include <cmath>
#include <thread>

#include "../tests.h"

int
main(int argc, char **argv)
{
  using palpate::Utilities::Point3;
  palpate::Environment env(argc, argv);
  initlog();

  const std::vector<Point3> targets = {{{0, 0, -0.01}},
                                       {{-0.02, 0, 0}},
                                       {{0, 0.01, 0.01}},
                                       {{0.01, -0.01, 0}}};
  for (const auto &plugin : palpate::LinearSolverRegistry::plugins())
    {
      const std::string &name               = plugin.name;
      palpate::Scene     scene              = shipped_scene("paper-stvk.prm");
      scene.parameters.linear_solver.solver = name;
      const Body           body(scene);
      palpate::StateSolver a(body.mesh, body.nodes, body.scene.parameters),
        b(body.mesh, body.nodes, body.scene.parameters);
      std::vector<palpate::State> alone;
      for (const Point3 &x : targets)
        alone.push_back(a.solve(a.rest_state(), x));

      double worst = 0;
      for (unsigned int round = 0; round < 3; ++round)
        {
          std::vector<palpate::State> first(targets.size()),
            second(targets.size());
          std::thread t1([&] {
            for (unsigned int i = 0; i < targets.size(); ++i)
              first[i] = a.solve(a.rest_state(), targets[i]);
          });
          std::thread t2([&] {
            for (unsigned int i = 0; i < targets.size(); ++i)
              second[i] = b.solve(b.rest_state(), targets[i]);
          });
          t1.join();
          t2.join();
          for (unsigned int i = 0; i < targets.size(); ++i)
            for (const auto *s : {&first[i], &second[i]})
              {
                double diff = 0, size = 0;
                for (unsigned int k = 0; k < s->solution.size(); ++k)
                  {
                    diff =
                      std::max(diff,
                               std::abs(s->solution[k] - alone[i].solution[k]));
                    size = std::max(size, std::abs(alone[i].solution[k]));
                  }
                worst = std::max(worst, diff / size);
                if (s->converged != alone[i].converged)
                  worst = 1;
              }
        }
      unsigned int converged = 0;
      for (const auto &s : alone)
        converged += s.converged;
      deallog << name << ": " << converged << " of " << targets.size()
              << " states converge; two workers at once give the same states "
              << "as one alone: " << (worst <= 1e-12 ? "yes" : "NO")
              << std::endl;
    }
}
