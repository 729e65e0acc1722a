// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

// Newton's method converges quadratically: a moderate step of the liver's
// active node (1 cm, one increment) with the residual history printed.
// And the state does not
// depend on the path: reaching the same target directly and via a detour
// gives the same displacement field and force within solver tolerance.
//
// "Quadratic" is judged where it is defined: on the last iteration whose
// residual is still above the round-off floor (1e-11 relative), starting
// below 1e-2; there log r_k+1 / log r_k >= 1.8.

#include <palpate/hyperelastic/hyperelastic_system.h>
#include <palpate/hyperelastic/state_solver.h>

#include <cmath>

#include "../tests.h"

int
main(int argc, char **argv)
{
  palpate::Environment env(argc, argv);
  initlog(3);

  for (const std::string material : {"St.Venant-Kirchhoff", "Neo-Hookean"})
    {
      palpate::Scene scene = shipped_scene("paper-stvk.prm");
      auto          &p     = scene.parameters;
      // Quadratic convergence is a property of the exact Newton step: no
      // GMRES with a kept factorisation here.
      p.nonlinear_solver.set_reuse(false);
      p.material_model.model_name           = material;
      p.nonlinear_solver.residual_tolerance = 1e-13;
      const Body           body(scene);
      palpate::StateSolver solver(body.mesh, body.nodes, p);

      const palpate::State state =
        solver.solve(solver.rest_state(), {{0.005, 0, -0.0085}});
      deallog << material
              << ", 1 cm in one increment: residual after each iteration"
              << std::endl;
      double rate     = 0;
      double previous = 0;
      for (unsigned int k = 0; k < state.history.size(); ++k)
        {
          const double r = state.history[k].residual_after;
          deallog << "  " << k + 1 << ": " << r << " (step "
                  << state.history[k].step_length << ")" << std::endl;
          if (previous < 1e-2 && r > 1e-11)
            rate = std::log(r) / std::log(previous);
          previous = r;
        }
      deallog << "  converged " << state.converged
              << ", quadratic near the solution: "
              << (rate >= 1.8 ? "yes" : "NO") << std::endl;
    }

  // Path independence.
  palpate::Scene scene = shipped_scene("paper-stvk.prm");
  scene.parameters.nonlinear_solver.residual_tolerance = 1e-11;
  const Body           body(scene);
  palpate::StateSolver solver(body.mesh, body.nodes, scene.parameters);
  const palpate::Utilities::Point3 target = {{0.01, -0.005, -0.02}};
  const palpate::State direct = solver.solve(solver.rest_state(), target);
  const palpate::State detour_start =
    solver.solve(solver.rest_state(), {{0.02, 0.01, 0}});
  const palpate::State detour     = solver.solve(detour_start, target);
  double               difference = 0, size = 0;
  for (unsigned int d = 0; d < direct.solution.size(); ++d)
    {
      difference =
        std::max(difference, std::abs(direct.solution[d] - detour.solution[d]));
      size = std::max(size, std::abs(direct.solution[d]));
    }
  deallog << "path independence: direct (" << direct.increments
          << " increments) and via "
          << "(0.02, 0.01, 0) m ("
          << detour_start.increments + detour.increments
          << " increments), both converged: "
          << (direct.converged && detour.converged) << std::endl;
  deallog << "  displacement difference / max u < 1e-8: "
          << (difference / size < 1e-8 ? "yes" : "NO")
          << ", force difference / |force| < 1e-8: "
          << (palpate::Utilities::distance(direct.force, detour.force) /
                    palpate::Utilities::norm(direct.force) <
                  1e-8 ?
                "yes" :
                "NO")
          << std::endl;
}
