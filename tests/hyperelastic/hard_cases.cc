// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

// Hard cases stay numerically stable (issue 10): each converges to the
// right answer or fails gracefully - flagged as a failure point, with a
// zero (safe) force, never NaN, never a crash. On the shipped blob
// (default.prm, 25 cm, St.Venant-Kirchhoff E = 15465 Pa) and beam:
// 1. E from 10 Pa to 1e7 Pa: StVK under displacement control is linear in
//    E, so the forces scale exactly (relative difference < 1e-8);
// 2. nu = 0.49, 0.499, 0.4999 (StVK, P1: volumetric locking raises the
//    force) and the exactly incompressible Mooney-Rivlin limit;
// 3. extreme Mooney-Rivlin constants: C01/C10 = 0, 1, 100 (same shear
//    modulus), and C10 = 0;
// 4. pushes and pulls to 40 % of the body's length (10 cm) in 4 directions,
//    with StVK, neo-Hookean and Mooney-Rivlin;
// 5. a sliver (50:1) next to the active node, and an active node at the
//    tip of a thin beam (5 mm thick, pushed 4 cm sideways).

#include <palpate/hyperelastic/state_solver.h>
#include <palpate/mesh/generators.h>
#include <palpate/mesh/mesh.h>
#include <palpate/mesh/node_selection.h>

#include <cmath>

#include "../tests.h"

namespace
{
  using palpate::Utilities::Point3;

  unsigned int n_cases = 0, n_unsafe = 0;

  /** Solve from rest to @p target and report; the state. */
  palpate::State
  run(const std::string    &what,
      const palpate::Mesh  &mesh,
      const palpate::Scene &scene,
      const Point3         &target,
      const bool            print_force = true)
  {
    const palpate::NodeSelection nodes =
      palpate::NodeSelection::create(scene, mesh);
    palpate::StateSolver solver(mesh, nodes, scene.parameters);
    const palpate::State s      = solver.solve(solver.rest_state(), target);
    const bool           finite = all_finite(s.force);
    const bool           safe =
      finite && (s.converged || palpate::Utilities::norm(s.force) == 0);
    ++n_cases;
    n_unsafe += !safe;
    deallog << what << ": "
            << (s.converged ?
                  "converged" :
                  "failure point (" + palpate::to_string(s.status) + ")");
    if (print_force && s.converged)
      deallog
        << ", |f| = "
        << palpate::Utilities::to_string(palpate::Utilities::norm(s.force), 4)
        << " N";
    deallog << (safe ? "" : ", UNSAFE FORCE") << std::endl;
    return s;
  }
} // namespace

int
main(int argc, char **argv)
{
  palpate::Environment env(argc, argv);
  initlog();

  const palpate::Scene blob = shipped_scene("default.prm");
  const palpate::Mesh  mesh = palpate::Mesh::create(blob);
  const Point3         push{{0, 0, -0.02}};

  deallog << "--- 1. Young's modulus from 10 Pa to 1e7 Pa, 2 cm push"
          << std::endl;
  {
    const palpate::State reference = run("E = 15465 Pa", mesh, blob, push);
    for (const double E : {10., 1e3, 1e5, 1e7})
      {
        palpate::Scene scene = blob;
        scene.parameters.material_model.set("St.Venant-Kirchhoff",
                                            "Young's modulus",
                                            E);
        const palpate::State s =
          run("E = " + palpate::Utilities::to_string(E, 2) + " Pa",
              mesh,
              scene,
              push,
              false);
        Point3 scaled = reference.force;
        for (double &f : scaled)
          f *= E / 15465;
        deallog << "  force = E/15465 x the reference: "
                << (s.converged &&
                        palpate::Utilities::distance(s.force, scaled) <
                          1e-8 * palpate::Utilities::norm(scaled) ?
                      "yes" :
                      "NO")
                << std::endl;
      }
  }

  deallog << "--- 2. near incompressibility, 2 cm push" << std::endl;
  {
    double f49 = 0;
    for (const double nu : {0.49, 0.499, 0.4999})
      {
        palpate::Scene scene = blob;
        scene.parameters.material_model.set("St.Venant-Kirchhoff",
                                            "Poisson's ratio",
                                            nu);
        const palpate::State s =
          run("StVK nu = " + palpate::Utilities::to_string(nu, 4),
              mesh,
              scene,
              push);
        if (nu == 0.49)
          f49 = palpate::Utilities::norm(s.force);
        else if (s.converged)
          deallog << "  force / force at nu = 0.49: "
                  << palpate::Utilities::to_string(
                       palpate::Utilities::norm(s.force) / f49, 3)
                  << " (locking)" << std::endl;
      }
    palpate::Scene scene = blob;
    auto          &m     = scene.parameters.material_model;
    m.model_name         = "Mooney-Rivlin";
    run("Mooney-Rivlin, exactly incompressible (P1-P1 stabilised)",
        mesh,
        scene,
        push);
  }

  deallog << "--- 3. extreme Mooney-Rivlin constants, 2 cm push" << std::endl;
  for (const auto &[c10, c01] : std::vector<std::pair<double, double>>{
         {2577.5, 0}, {1288.75, 1288.75}, {25.52, 2551.98}, {0, 2577.5}})
    {
      palpate::Scene scene = blob;
      auto          &m     = scene.parameters.material_model;
      m.model_name         = "Mooney-Rivlin";
      m.set("Mooney-Rivlin", "C10", c10);
      m.set("Mooney-Rivlin", "C01", c01);
      run("C10 = " + palpate::Utilities::to_string(c10, 4) +
            " Pa, C01 = " + palpate::Utilities::to_string(c01, 4) + " Pa",
          mesh,
          scene,
          push);
    }

  deallog << "--- 4. pushes and pulls of 10 cm (40 % of the body)" << std::endl;
  for (const std::string model :
       {"St.Venant-Kirchhoff", "Neo-Hookean", "Mooney-Rivlin"})
    for (const Point3 &d : {Point3{{0, 0, -0.1}},
                            Point3{{0, 0, 0.1}},
                            Point3{{0.1, 0, 0}},
                            Point3{{0, -0.1, 0}}})
      {
        palpate::Scene scene                           = blob;
        scene.parameters.material_model.model_name     = model;
        scene.parameters.nonlinear_solver.max_cutbacks = 4;
        run(model + " to (" + palpate::Utilities::to_string(d, 2) + ") m",
            mesh,
            scene,
            d,
            false);
      }

  deallog << "--- 5. a sliver next to the active node, a thin beam"
          << std::endl;
  {
    palpate::Scene beam = shipped_scene("beam.prm");
    auto          &p    = beam.parameters;
    // The active node is the top node at the free end's middle,
    // (0.1, 0, 0.01); the node below it, on the middle layer (0.1, 0, 0),
    // moves up to 0.2 mm below it: the tetrahedra between them are
    // slivers (50:1).
    palpate::MeshData data = palpate::generate_beam(p.mesh);
    for (auto &x : data.nodes)
      if (std::abs(x[0] - 0.1) < 1e-9 && std::abs(x[1]) < 1e-9 &&
          std::abs(x[2]) < 1e-9)
        x[2] = 0.0098;
    const palpate::Mesh sliver(data, 1.0, "beam with a sliver");
    deallog << "  smallest tetrahedron / mean: "
            << palpate::Utilities::to_string(sliver.min_cell_volume() /
                                               (sliver.volume() /
                                                sliver.n_cells()),
                                             2)
            << std::endl;
    run("sliver, 5 mm push", sliver, beam, {{0, 0, -0.005}});
    run("sliver, 2 cm push", sliver, beam, {{0, 0, -0.02}});

    p.mesh.beam_height                      = 0.005;
    p.mesh.beam_width                       = 0.005;
    p.mesh.beam_subdivisions_length         = 20;
    p.mesh.beam_subdivisions_width          = 1;
    p.mesh.beam_subdivisions_height         = 1;
    p.boundary_conditions.active_node.point = {{0.1, 0, 0.0025}};
    const palpate::Mesh thin                = palpate::Mesh::create(beam);
    run("thin beam tip, 4 cm sideways", thin, beam, {{0, 0.04, 0}});
    run("thin beam tip, 4 cm down", thin, beam, {{0, 0, -0.04}});
  }

  deallog << n_cases << " cases: " << n_unsafe
          << " with an unsafe force (NaN, or a failure point with a non-zero "
             "force): must be 0"
          << std::endl;
}
