// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

// Every sparse direct solver gives the same state: the liver pushed 1.5 cm
// with MUMPS (symmetric LDL^T, METIS and AMD orderings; and in single
// precision as GMRES's preconditioner), UMFPACK, KLU and Trilinos Amesos
// (MUMPS and KLU); forces agree to 1e-9 relative and Newton takes the
// same number of iterations (single precision too, although its Newton
// steps are GMRES's to 1e-4 of the residual).

#include <palpate/hyperelastic/state_solver.h>

#include "../tests.h"

int
main(int argc, char **argv)
{
  palpate::Environment env(argc, argv);
  initlog();

  palpate::State reference;
  for (const auto &[solver_name, ordering] : every_linear_solver())
    {
      palpate::Scene scene                    = shipped_scene("paper-stvk.prm");
      scene.parameters.linear_solver.solver   = solver_name;
      scene.parameters.linear_solver.ordering = ordering;
      scene.parameters.nonlinear_solver.residual_tolerance = 1e-10;
      const Body           body(scene);
      palpate::StateSolver solver(body.mesh, body.nodes, scene.parameters);
      const palpate::State state =
        solver.solve(solver.rest_state(), {{0.005, 0.005, -0.015}});
      if (reference.solution.empty())
        reference = state;
      const double difference =
        palpate::Utilities::distance(state.force, reference.force) /
        palpate::Utilities::norm(reference.force);
      deallog << solver.linear_solver_name() << ": " << state.newton_iterations
              << " Newton iterations, force ("
              << palpate::Utilities::to_string(state.force, 6)
              << ") N, same as the first to 1e-9: "
              << (difference < 1e-9 ? "yes" : "NO") << std::endl;
    }
}
