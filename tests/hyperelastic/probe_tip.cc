// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

// A rigid probe tip (Boundary conditions / Active node / Tip radius): the
// surface nodes within the radius of the active node move with the probe,
// and the force is the sum of their multipliers. Checked against the exact
// solution of a bar: a beam 10 x 1 x 1 cm, clamped at x = 0, nu = 0, with
// a tip of 8 mm at the centre of its free end that holds the whole end face
// (9 nodes), pulled 1 micrometre along x. With nu = 0 the displacement is
// linear in x, which linear tetrahedra represent exactly, so the force is
// E A u / L up to the geometric nonlinearity (relative 1.5 u/L = 1.5e-5).
// A point probe at the same node pulls the face's centre only: a smaller
// force.

#include <palpate/hyperelastic/hyperelastic_system.h>
#include <palpate/hyperelastic/state_solver.h>
#include <palpate/mesh/mesh.h>
#include <palpate/mesh/node_selection.h>

#include <cmath>

#include "../tests.h"

int
main(int argc, char **argv)
{
  palpate::Environment env(argc, argv);
  initlog();

  palpate::Scene scene = shipped_scene("beam.prm");
  auto          &p     = scene.parameters;
  p.mesh.beam_width    = 0.01;
  p.mesh.beam_height   = 0.01;
  p.material_model.set("St.Venant-Kirchhoff", "Poisson's ratio", 0.0);
  p.boundary_conditions.active_node.point = {{0.1, 0, 0}};
  const palpate::Mesh mesh                = palpate::Mesh::create(scene);
  const double        E = p.material_model.get_double("St.Venant-Kirchhoff",
                                               "Young's modulus"),
               A = 1e-4, L = 0.1, u = 1e-6;
  const double exact = E * A * u / L;

  for (const double radius : {0.008, 0.0})
    {
      p.boundary_conditions.active_node.tip_radius = radius;
      p.boundary_conditions.active_node.tip =
        radius > 0 ? "glued nodes" : "point";
      const palpate::NodeSelection nodes =
        palpate::NodeSelection::create(scene, mesh);
      palpate::StateSolver solver(mesh, nodes, p);
      const palpate::State s = solver.solve(solver.rest_state(), {{u, 0, 0}});
      deallog << (radius > 0 ? "tip of 8 mm: " : "point probe: ")
              << 1 + nodes.tip_vertices.size() << " nodes, "
              << solver.system().n_multipliers() << " multipliers, "
              << (s.converged ? "converged" : "FAILED") << std::endl;
      const double relative = (-s.force[0] - exact) / exact;
      if (radius > 0)
        deallog << "  force along x = E A u / L = "
                << palpate::Utilities::to_string(exact, 4)
                << " N to relative 1e-4: "
                << (std::abs(relative) < 1e-4 ? "yes" : "NO") << "; across: "
                << (std::abs(s.force[1]) + std::abs(s.force[2]) < 1e-8 * exact ?
                      "0" :
                      "NOT 0")
                << std::endl;
      else
        deallog << "  force along x / E A u / L = "
                << palpate::Utilities::to_string(-s.force[0] / exact, 3)
                << " (less than the whole face)" << std::endl;
    }
}
