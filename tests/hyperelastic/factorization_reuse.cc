// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

// Nonlinear solver / Reuse factorization: Newton steps solved by GMRES,
// preconditioned with a kept factorisation, give the same states as a
// factorisation at every step. On the liver (StVK), 12 states along two
// grid lines of 5 mm steps, each from the previous one as an engine worker
// computes them: the forces agree to 1e-6 relative and the displacement
// fields to 1e-6 of their size, and fewer factorisations are made.

#include <palpate/hyperelastic/state_solver.h>

#include <cmath>

#include "../tests.h"

int
main(int argc, char **argv)
{
  using palpate::Utilities::Point3;
  palpate::Environment env(argc, argv);
  initlog();

  const Body           body(shipped_scene("paper-stvk.prm"));
  const auto          &p = body.scene.parameters;
  palpate::StateSolver direct(body.mesh, body.nodes, p),
    reuse(body.mesh, body.nodes, p);
  direct.settings().reuse_factorization = false;
  reuse.settings().reuse_factorization  = true;

  std::vector<Point3> path;
  for (int k = 1; k <= 6; ++k)
    path.push_back({{-0.005 * k, 0, 0}});
  for (int k = 1; k <= 6; ++k)
    path.push_back({{-0.03, 0, -0.005 * k}});

  palpate::State from_direct     = direct.rest_state(),
                 from_reuse      = reuse.rest_state();
  unsigned int factorizations[2] = {0, 0}, gmres_steps = 0;
  double       force_difference = 0, field_difference = 0;
  bool         all_converged = true;
  for (const Point3 &x : path)
    {
      palpate::State a = direct.solve(from_direct, x);
      palpate::State b = reuse.solve(from_reuse, x);
      all_converged    = all_converged && a.converged && b.converged;
      for (const auto &h : a.history)
        factorizations[0] += h.factorized;
      for (const auto &h : b.history)
        {
          factorizations[1] += h.factorized;
          gmres_steps += !h.factorized;
        }
      force_difference =
        std::max(force_difference,
                 palpate::Utilities::distance(a.force, b.force) /
                   palpate::Utilities::norm(a.force));
      double diff = 0, size = 0;
      for (unsigned int i = 0; i < a.solution.size(); ++i)
        {
          diff = std::max(diff, std::abs(a.solution[i] - b.solution[i]));
          size = std::max(size, std::abs(a.solution[i]));
        }
      field_difference = std::max(field_difference, diff / size);
      from_direct      = std::move(a);
      from_reuse       = std::move(b);
    }
  deallog << path.size()
          << " states, all converged: " << (all_converged ? "yes" : "NO")
          << std::endl;
  deallog << "forces agree to 1e-6: "
          << (force_difference < 1e-6 ? "yes" : "NO")
          << ", displacement fields to 1e-6: "
          << (field_difference < 1e-6 ? "yes" : "NO") << std::endl;
  deallog << "fewer factorisations with reuse: "
          << (factorizations[1] < factorizations[0] ? "yes" : "NO")
          << ", some steps solved by GMRES: "
          << (gmres_steps > 0 ? "yes" : "NO") << ", force at the end ("
          << palpate::Utilities::to_string(from_direct.force, 4) << ") N"
          << std::endl;
}
