// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

// A sphere pressed past what the mesh under it can hold: the failure says
// why. A block 60 x 40 x 30 mm of incompressible Mooney-Rivlin (P1-P1),
// its 5 mm cubes each split into 6 tetrahedra along a diagonal (Kuhn), held
// at its underside, pressed on top by a sphere of 10 mm radius with the
// condensed contact at the study's tolerance (a new user's block, read from
// a Gmsh file as they would):
// - 8 mm deep it converges, with no cause appended;
// - 10 mm deep (one radius, which the checks on reading accept) the nodes
//   under the sphere slide round it, Newton stagnates, and the failure's
//   message says the sphere was sinking between the surface nodes, how far
//   its centre was from the surface in radii, and what to change.

#include <palpate/hyperelastic/state_solver.h>
#include <palpate/mesh/mesh.h>
#include <palpate/mesh/node_selection.h>

#include <array>
#include <cmath>
#include <fstream>
#include <iomanip>
#include <utility>

#include "../tests.h"

namespace
{
  // The block in Gmsh 2.2 (mm): nx x ny x nz cubes of 5 mm, each split into
  // the 6 tetrahedra of the paths from its lowest to its highest corner.
  void
  write_block(const std::string &file)
  {
    const unsigned int nx = 12, ny = 8, nz = 6;
    const double       h = 5;
    const auto tag       = [&](unsigned int i, unsigned int j, unsigned int k) {
      return 1 + i + (nx + 1) * (j + (ny + 1) * k);
    };
    std::ofstream f(file);
    f << "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$Nodes\n"
      << (nx + 1) * (ny + 1) * (nz + 1) << "\n";
    for (unsigned int k = 0; k <= nz; ++k)
      for (unsigned int j = 0; j <= ny; ++j)
        for (unsigned int i = 0; i <= nx; ++i)
          f << tag(i, j, k) << " " << i * h << " " << j * h << " " << k * h
            << "\n";
    f << "$EndNodes\n$Elements\n" << 6 * nx * ny * nz << "\n";
    std::array<unsigned int, 3> axes = {{0, 1, 2}};
    unsigned int                e    = 1;
    for (unsigned int i = 0; i < nx; ++i)
      for (unsigned int j = 0; j < ny; ++j)
        for (unsigned int k = 0; k < nz; ++k)
          {
            std::array<unsigned int, 3> order = axes;
            do
              {
                std::array<unsigned int, 3> c = {{i, j, k}};
                std::array<unsigned int, 4> t;
                t[0] = tag(c[0], c[1], c[2]);
                for (unsigned int s = 0; s < 3; ++s)
                  {
                    ++c[order[s]];
                    t[s + 1] = tag(c[0], c[1], c[2]);
                  }
                // Odd permutations of the axes give a negative volume.
                const bool odd = (order[0] == 0 && order[1] == 2) ||
                                 (order[0] == 1 && order[1] == 0) ||
                                 (order[0] == 2 && order[1] == 1);
                if (odd)
                  std::swap(t[2], t[3]);
                f << e++ << " 4 2 1 1 " << t[0] << " " << t[1] << " " << t[2]
                  << " " << t[3] << "\n";
              }
            while (std::next_permutation(order.begin(), order.end()));
          }
    f << "$EndElements\n";
  }
} // namespace

int
main(int argc, char **argv)
{
  palpate::Environment env(argc, argv);
  initlog();

  write_block("block.msh");
  palpate::Scene scene                    = shipped_scene("beam.prm");
  auto          &p                        = scene.parameters;
  p.mesh.source                           = "file";
  p.mesh.file_name                        = "block.msh";
  p.mesh.scale_factor                     = 0.001;
  auto &fixed                             = p.boundary_conditions.fixed_nodes;
  fixed.selection                         = "half-space";
  fixed.half_space_point                  = {{0, 0, 0.001}};
  fixed.half_space_normal                 = {{0, 0, -1}};
  fixed.surface_nodes_only                = true;
  auto &active                            = p.boundary_conditions.active_node;
  active.selection                        = "nearest surface node";
  active.point                            = {{0.03, 0.02, 0.03}};
  active.tip                              = "sphere";
  active.tip_radius                       = 0.01;
  p.material_model.model_name             = "Mooney-Rivlin";
  p.nonlinear_solver.condensed_contact    = true;
  p.nonlinear_solver.residual_tolerance   = 1e-3;
  p.nonlinear_solver.max_increment_length = 0.002;

  const Body body(scene);
  deallog << "block: " << body.mesh.n_vertices() << " nodes, "
          << body.mesh.n_cells() << " tetrahedra" << std::endl;
  const std::string cause = "sinking between the surface nodes";
  for (const double depth : {0.008, 0.01})
    {
      palpate::StateSolver solver(body.mesh, body.nodes, p);
      const palpate::State s =
        solver.solve(solver.rest_state(), {{0, 0, -depth}});
      deallog << std::lround(1000 * depth) << " mm deep: "
              << (s.converged ? "converged" : palpate::to_string(s.status));
      if (s.converged)
        deallog << ", |f| " << std::fixed << std::setprecision(1)
                << palpate::Utilities::norm(s.force) << std::defaultfloat
                << " N, no cause appended: "
                << (s.message.find(cause) == std::string::npos ? "yes" : "NO");
      else
        {
          const auto names = [&](const std::string &what) {
            return s.message.find(what) != std::string::npos ? "yes" : "NO";
          };
          deallog << "; the message names the cause: " << names(cause)
                  << ", the centre's distance in radii: "
                  << names(" of its radius")
                  << ", a fix: " << names("Use a larger Tip radius");
        }
      deallog << std::endl;
    }
}
