// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

// Uniaxial tension and compression of an incompressible Mooney-Rivlin
// block with free lateral faces (symmetry planes x = 0, y = -W/2, z = -H/2
// hold one component each; the face x = L is moved by (lambda - 1) L).
// The nominal stress, the force on the moved face per reference area, must
// match the closed form P = 2 (lambda - lambda^-2) (C10 + C01 / lambda)
// within 0.5 % for stretches 0.7 ... 1.5, and the volume must stay that of
// the block: to solver tolerance for Taylor-Hood, reported for P1-P1.
// The Yeoh plug-in (doc/extending.md's example, one file) the same way:
// P = 2 (lambda - lambda^-2) (C10 + 2 C20 x + 3 C30 x^2), x = I1 - 3,
// I1 = lambda^2 + 2/lambda.

#include <palpate/hyperelastic/hyperelastic_system.h>
#include <palpate/hyperelastic/state_solver.h>

#include <cmath>
#include <utility>
#include <vector>

#include "../tests.h"

int
main(int argc, char **argv)
{
  palpate::Environment env(argc, argv);
  initlog();

  const double C10 = 2148, C01 = 429.6; // the liver's, Pa
  const double L = 0.02, W = 0.01, H = 0.01;
  const double Y10 = 2577.5, Y20 = 1288.75, Y30 = 100; // Yeoh, Pa
  for (const auto &[model, element] :
       std::vector<std::pair<std::string, std::string>>{
         {"Mooney-Rivlin", "P1-P1"},
         {"Mooney-Rivlin", "Taylor-Hood"},
         {"Yeoh", "P1-P1"}})
    {
      palpate::Scene scene = shipped_scene("paper-mooney-rivlin.prm");
      auto          &p     = scene.parameters;
      p.mesh.source        = "beam";
      p.mesh.beam_length = L, p.mesh.beam_width = W, p.mesh.beam_height = H;
      p.mesh.beam_subdivisions_length = 3, p.mesh.beam_subdivisions_width = 2,
      p.mesh.beam_subdivisions_height = 2;
      p.material_model.set("Mooney-Rivlin", "C10", C10);
      p.material_model.set("Mooney-Rivlin", "C01", C01);
      p.material_model.set("Mooney-Rivlin", "Element", element);
      p.material_model.model_name = model;
      p.material_model.set("Yeoh", "C10", Y10);
      p.material_model.set("Yeoh", "C20", Y20);
      p.material_model.set("Yeoh", "C30", Y30);
      p.material_model.set("Yeoh", "Element", element);
      p.nonlinear_solver.residual_tolerance = 1e-11;
      const palpate::Mesh mesh              = palpate::Mesh::create(scene);

      // Symmetry planes and the moved face, component by component.
      palpate::NodeSelection nodes;
      nodes.active_vertex = palpate::NodeSelection::no_active_node;
      for (unsigned int v = 0; v < mesh.n_vertices(); ++v)
        {
          const auto &x = mesh.vertices()[v];
          if (std::abs(x[0]) < 1e-12 || std::abs(x[0] - L) < 1e-12)
            nodes.fixed_components.emplace_back(v, 0);
          if (std::abs(x[1] + W / 2) < 1e-12)
            nodes.fixed_components.emplace_back(v, 1);
          if (std::abs(x[2] + H / 2) < 1e-12)
            nodes.fixed_components.emplace_back(v, 2);
        }
      palpate::StateSolver solver(mesh, nodes, p);
      auto                &system = solver.system();
      deallog << model << ", " << element << ": "
              << system.discretization_description() << ", "
              << system.n_equations() << " equations" << std::endl;

      bool   all_within          = true;
      double worst_volume_change = 0;
      for (const double direction : {1.0, -1.0})
        {
          palpate::State state = solver.rest_state();
          for (int k = 1; k <= (direction > 0 ? 10 : 6); ++k)
            {
              const double lambda = 1 + direction * 0.05 * k;
              system.set_fixed_displacement([lambda](
                                              const palpate::Utilities::Point3
                                                &X) {
                return palpate::Utilities::Point3{{(lambda - 1) * X[0], 0, 0}};
              });
              state = solver.solve(state, {{0, 0, 0}});
              // Force on the moved face: the internal forces of its x-DoFs.
              const auto f     = system.nodal_residual(state.solution);
              double     force = 0;
              for (const unsigned int d : system.fixed_dofs())
                if (system.dof_components()[d] == 0 &&
                    std::abs(system.dof_positions()[d][0] - L) < 1e-12)
                  force += f[d];
              const double P_fe = force / (W * H);
              const double x    = lambda * lambda + 2 / lambda - 3;
              const double P_exact =
                2 * (lambda - 1 / (lambda * lambda)) *
                (model == "Yeoh" ? Y10 + 2 * Y20 * x + 3 * Y30 * x * x :
                                   C10 + C01 / lambda);
              const double error = std::abs(P_fe - P_exact) / std::abs(P_exact);
              const double volume =
                system.deformed_volume(state.solution) / (L * W * H);
              all_within = all_within && state.converged && error < 0.005;
              worst_volume_change =
                std::max(worst_volume_change, std::abs(volume - 1));
              if (k % 2 == 0)
                deallog << "  stretch " << std::setprecision(3) << lambda
                        << ": P = " << std::setprecision(5) << P_fe
                        << " Pa, closed form " << P_exact
                        << " Pa, within 0.5 %: "
                        << (error < 0.005 ? "yes" : "NO")
                        << std::setprecision(6) << std::endl;
            }
        }
      deallog << "  every stretch within 0.5 %: " << (all_within ? "yes" : "NO")
              << std::endl;
      deallog << "  largest |V/V0 - 1| < 1e-8: "
              << (worst_volume_change < 1e-8 ? "yes" : "NO") << std::endl;
    }
}
