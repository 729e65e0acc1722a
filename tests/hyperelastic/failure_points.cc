// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

// Hard cases stay numerically stable: pushes far beyond what the mesh can
// follow, in one increment or staged, pulls, and a NaN target. Each ends as
// a converged state or as a failure point with a reason; never an
// exception, never a NaN or infinite force, and a failure point's force is
// zero (it must not be rendered). The same solver then still computes an
// ordinary state correctly.

#include <palpate/hyperelastic/state_solver.h>

#include <cmath>
#include <limits>

#include "../tests.h"

namespace
{
  bool
  finite(const palpate::State &s)
  {
    for (const double f : s.force)
      if (!std::isfinite(f))
        return false;
    for (const double u : s.solution)
      if (!std::isfinite(u))
        return false;
    return true;
  }

  void
  report(const std::string &what, const palpate::State &s)
  {
    deallog << what << ": "
            << (s.converged ?
                  "converged" :
                  "failure point (" + palpate::to_string(s.status) + ")")
            << ", finite: " << (finite(s) ? "yes" : "NO")
            << ", failure force zero: "
            << (s.converged || palpate::Utilities::norm(s.force) == 0 ? "yes" :
                                                                        "NO")
            << std::endl;
  }
} // namespace

int
main(int argc, char **argv)
{
  palpate::Environment env(argc, argv);
  initlog();

  for (const std::string material : {"St.Venant-Kirchhoff", "Neo-Hookean"})
    {
      palpate::Scene scene        = shipped_scene("paper-stvk.prm");
      auto          &p            = scene.parameters;
      p.material_model.model_name = material;
      const Body           body(scene);
      palpate::StateSolver solver(body.mesh, body.nodes, p);
      const palpate::State rest = solver.rest_state();
      deallog << material << std::endl;

      p.nonlinear_solver.max_increment_length = 0; // no staging
      solver.settings()                       = p.nonlinear_solver;
      report("  10 cm push in one increment",
             solver.solve(rest, {{0, 0, -0.1}}));
      report("  10 cm push sideways in one increment",
             solver.solve(rest, {{0.1, 0, 0}}));

      p.nonlinear_solver.max_increment_length = 0.01; // 1 cm increments
      p.nonlinear_solver.max_cutbacks         = 2;
      solver.settings()                       = p.nonlinear_solver;
      report("  8 cm push, 1 cm increments, 2 cutbacks",
             solver.solve(rest, {{0, 0, -0.08}}));
      report("  15 cm pull, 1 cm increments, 2 cutbacks",
             solver.solve(rest, {{0, 0, 0.15}}));

      const double nan = std::numeric_limits<double>::quiet_NaN();
      report("  NaN target", solver.solve(rest, {{nan, 0, 0}}));

      const palpate::State ordinary = solver.solve(rest, {{0, 0, -0.01}});
      report("  afterwards, 1 cm push", ordinary);
      deallog << "    force ("
              << palpate::Utilities::to_string(ordinary.force, 4) << ") N"
              << std::endl;
    }
}
