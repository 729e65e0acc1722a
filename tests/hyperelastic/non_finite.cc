// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

// Nothing non-finite is ever "converged" (issue 10): the scene reader
// refuses moduli beyond 1e13 Pa, but the solver must hold on its own. On
// the beam (5 mm down at its tip):
// - E = 1e300 Pa (the force scale overflows): a failure point, force 0;
// - a target with NaN or Inf: a failure point, force 0;
// - E = 1e7 Pa, the same push: converged, finite force, and exactly 1e7/1e5
//   times the force at the shipped 1e5 Pa (StVK under displacement control
//   is linear in E), relative difference < 1e-8.

#include <palpate/hyperelastic/state_solver.h>
#include <palpate/mesh/mesh.h>
#include <palpate/mesh/node_selection.h>

#include <cmath>
#include <limits>

#include "../tests.h"

namespace
{
  using palpate::Utilities::Point3;

  void
  report(const std::string &what, const palpate::State &s)
  {
    const bool finite = all_finite(s.force);
    deallog << what << ": " << (s.converged ? "converged" : "failure point")
            << " (" << palpate::to_string(s.status) << "), force "
            << (finite ? "finite" : "NOT FINITE") << std::endl;
  }
} // namespace

int
main(int argc, char **argv)
{
  palpate::Environment env(argc, argv);
  initlog();

  palpate::Scene               scene = shipped_scene("beam.prm");
  const palpate::Mesh          mesh  = palpate::Mesh::create(scene);
  const palpate::NodeSelection nodes =
    palpate::NodeSelection::create(scene, mesh);
  const Point3 push{{0, 0, -0.005}};

  auto p = scene.parameters;
  p.material_model.set("St.Venant-Kirchhoff", "Young's modulus", 1e300);
  {
    palpate::StateSolver solver(mesh, nodes, p);
    report("E = 1e300 Pa", solver.solve(solver.rest_state(), push));
  }
  {
    palpate::StateSolver solver(mesh, nodes, scene.parameters);
    const double         nan = std::numeric_limits<double>::quiet_NaN();
    const double         inf = std::numeric_limits<double>::infinity();
    report("target (0, 0, NaN)",
           solver.solve(solver.rest_state(), {{0, 0, nan}}));
    report("target (Inf, 0, 0)",
           solver.solve(solver.rest_state(), {{inf, 0, 0}}));

    const palpate::State soft = solver.solve(solver.rest_state(), push);
    p.material_model.set("St.Venant-Kirchhoff", "Young's modulus", 1e7);
    palpate::StateSolver stiff_solver(mesh, nodes, p);
    const palpate::State stiff =
      stiff_solver.solve(stiff_solver.rest_state(), push);
    report("E = 1e5 Pa", soft);
    report("E = 1e7 Pa", stiff);
    const double ratio =
      1e7 / scene.parameters.material_model.get_double("St.Venant-Kirchhoff",
                                                       "Young's modulus");
    Point3 scaled = soft.force;
    for (double &f : scaled)
      f *= ratio;
    deallog << "force at 1e7 Pa is " << ratio
            << " x the force at the shipped modulus: "
            << (palpate::Utilities::distance(stiff.force, scaled) <
                    1e-8 * palpate::Utilities::norm(scaled) ?
                  "yes (relative difference < 1e-8)" :
                  "NO")
            << std::endl;
  }
}
