// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

// Cook's membrane, nearly incompressible, in the set-up of de Souza Neto,
// Peric, Dutko, Owen (1996) as computed by OpenGeoSys' large-deformation
// benchmark (F-bar): the trapezoid (0,0)-(48,44)-(48,60)-(0,44) mm,
// clamped on its left edge, a dead shear traction of 6.25 MPa on its
// right edge (100 N per mm of thickness), plane strain, neo-Hookean with
// E = 240.565 MPa and nu = 0.499 (mu = 80.24 MPa, kappa = 40094 MPa): the
// Mooney-Rivlin model with C01 = 0 and a penalised pressure. The vertical
// displacement of the top right corner converges to 6.89 mm.
//
// Plane strain on a slab one element thick: every node's z-component is
// held. The load is applied in 10 equal steps. Taylor-Hood must be within
// 3 % of 6.89 mm on the finest mesh (16 elements per side); the sequence
// is reported for Taylor-Hood and P1-P1.

#include <palpate/hyperelastic/hyperelastic_system.h>
#include <palpate/hyperelastic/state_solver.h>
#include <palpate/mesh/generators.h>

#include <cmath>

#include "../tests.h"

namespace
{
  /** Tip displacement (mm) on an n x n mesh with element pair @p element. */
  double
  tip_displacement(const std::string &element,
                   const unsigned int n,
                   bool              &converged)
  {
    palpate::Scene scene = shipped_scene("paper-mooney-rivlin.prm");
    auto          &p     = scene.parameters;
    const double   E = 240.565e6, nu = 0.499;
    const double   mu = E / (2 * (1 + nu)), kappa = E / (3 * (1 - 2 * nu));
    p.material_model.set("Mooney-Rivlin", "C10", mu / 2);
    p.material_model.set("Mooney-Rivlin", "C01", 0.0);
    p.material_model.set("Mooney-Rivlin", "Incompressibility", "penalty");
    p.material_model.set("Mooney-Rivlin", "Bulk modulus", kappa);
    p.material_model.set("Mooney-Rivlin", "Element", element);
    p.nonlinear_solver.residual_tolerance = 1e-9;

    // The beam generator's block, mapped onto the trapezoid (in mm, then
    // scaled to m); its face x = 0 has boundary id 0, x = 48 id 1.
    p.mesh.beam_length = 48, p.mesh.beam_width = 1, p.mesh.beam_height = 1;
    p.mesh.beam_subdivisions_length = n, p.mesh.beam_subdivisions_width = n,
    p.mesh.beam_subdivisions_height = 1;
    palpate::MeshData data          = palpate::generate_beam(p.mesh);
    for (auto &x : data.nodes)
      {
        const double xi = x[0] / 48, eta = x[1] + 0.5;
        x[1] = 44 * xi + eta * (44 + 16 * xi - 44 * xi);
      }
    const palpate::Mesh mesh(data, 1e-3, "Cook's membrane");

    palpate::NodeSelection nodes;
    nodes.active_vertex = palpate::NodeSelection::no_active_node;
    unsigned int tip    = 0;
    for (unsigned int v = 0; v < mesh.n_vertices(); ++v)
      {
        const auto &x = mesh.vertices()[v];
        if (std::abs(x[0]) < 1e-12)
          nodes.fixed_vertices.push_back(v);
        else
          nodes.fixed_components.emplace_back(v, 2); // plane strain
        if (std::abs(x[0] - 0.048) < 1e-12 && std::abs(x[1] - 0.060) < 1e-12)
          tip = v;
      }

    palpate::StateSolver solver(mesh, nodes, p);
    auto                &system = solver.system();
    system.add_surface_traction(1, {{0, 6.25e6, 0}});
    palpate::State state = solver.rest_state();
    converged            = true;
    for (unsigned int step = 1; step <= 10; ++step)
      {
        system.set_load_factor(step / 10.0);
        state     = solver.solve(state, {{0, 0, 0}});
        converged = converged && state.converged;
      }
    for (unsigned int d = 0; d < system.n_dofs(); ++d)
      if (system.dof_components()[d] == 1 &&
          palpate::Utilities::distance(system.dof_positions()[d],
                                       mesh.vertices()[tip]) < 1e-12)
        return 1000 * state.solution[d];
    return 0;
  }
} // namespace

int
main(int argc, char **argv)
{
  palpate::Environment env(argc, argv);
  initlog();

  const double reference = 6.89; // mm
  for (const auto &[element, sizes] :
       std::vector<std::pair<std::string, std::vector<unsigned int>>>{
         {"Taylor-Hood", {2, 4, 8, 16}}, {"P1-P1", {4, 8, 16}}})
    {
      deallog << element << " (reference " << reference << " mm)" << std::endl;
      double finest = 0;
      for (const unsigned int n : sizes)
        {
          bool converged;
          finest = tip_displacement(element, n, converged);
          deallog << "  " << n << " x " << n << " elements: tip displacement "
                  << std::setprecision(3) << finest << " mm ("
                  << std::setprecision(2) << 100 * (finest / reference - 1)
                  << " %), converged " << converged << std::setprecision(6)
                  << std::endl;
        }
      if (element == "Taylor-Hood")
        deallog << "  finest mesh within 3 % of 6.89 mm: "
                << (std::abs(finest / reference - 1) < 0.03 ? "yes" : "NO")
                << std::endl;
    }
}
