// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

#include <palpate/hyperelastic/hertz.h>
#include <palpate/mesh/generators.h>

#include <cmath>

namespace palpate
{
  double
  hertz_force(const double E,
              const double nu,
              const double R,
              const double depth)
  {
    return 4.0 / 3.0 * E / (1 - nu * nu) * std::sqrt(R) * std::pow(depth, 1.5);
  }



  HertzBlock::HertzBlock(const Parameters::AllParameters &p,
                         const double                     R,
                         const double                     contact_radius,
                         const double                     size,
                         const double                     h,
                         const unsigned int               split)
    : parameters(p)
  {
    parameters.boundary_conditions.active_node.tip        = "sphere";
    parameters.boundary_conditions.active_node.tip_radius = R;
    parameters.boundary_conditions.fixed_nodes.treatment  = "elimination";

    // The same grading along every axis: fine over two contact radii
    // (where the pressure acts and varies), then growing by 1.5.
    const std::vector<double> t =
      graded_coordinates(size, h, 2 * contact_radius, 1.5, split);
    std::vector<double> z(t.size());
    for (unsigned int i = 0; i < t.size(); ++i)
      z[i] = -t[t.size() - 1 - i];
    mesh = std::make_unique<Mesh>(generate_tensor_block(t, t, z),
                                  1.0,
                                  "Hertz block");

    const auto &x = mesh->vertices();
    for (unsigned int v = 0; v < x.size(); ++v)
      {
        if (x[v][2] <= -size * (1 - 1e-12))
          nodes.fixed_vertices.push_back(v);
        else
          {
            if (x[v][0] == 0)
              nodes.fixed_components.emplace_back(v, 0);
            if (x[v][1] == 0)
              nodes.fixed_components.emplace_back(v, 1);
          }
        if (x[v][0] == 0 && x[v][1] == 0 && x[v][2] == 0)
          nodes.active_vertex = v;
      }
    nodes.sphere_tip        = true;
    nodes.active_normal     = {{0, 0, 1}};
    nodes.sphere_center     = {{0, 0, R}};
    nodes.fixed_description = "the bottom face";
    description             = std::to_string(mesh->n_vertices()) + " nodes, " +
                  std::to_string(mesh->n_cells()) +
                  " tetrahedra, finest spacing " +
                  std::to_string(1e3 * h / split) + " mm";
  }
} // namespace palpate
