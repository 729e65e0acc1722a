// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

// A solution of HyperelasticSystem as the rest of palpate sees it: the
// unknowns as a State (displacements, pressures, multipliers, the probe's
// force) and back, the strain energy and deformed volume it has, and the
// VTU file that shows it.

#include <palpate/hyperelastic/hyperelastic_system_impl.h>
#include <palpate/mesh/mesh.h>

#include <deal.II/fe/fe_simplex_p.h>
#include <deal.II/lac/vector.h>
#include <deal.II/numerics/data_out.h>

#include <fstream>
#include <sstream>
#include <stdexcept>

namespace palpate
{
  using namespace dealii;



  void
  HyperelasticSystem::to_state(const std::vector<double> &x, State &state) const
  {
    const Impl &s = *impl;
    s.expand(x, state.solution);
    if (s.mixed)
      for (unsigned int d = 0; d < state.solution.size(); ++d)
        if (s.dof_component[d] == 3)
          state.solution[d] *= s.pressure_scale;
    state.multipliers.resize(n_multipliers());
    for (unsigned int m = 0; m < n_multipliers(); ++m)
      state.multipliers[m] = s.beta * x[s.n_free + m];
    state.force = probe_force(x, state.active_displacement);
  }



  std::vector<double>
  HyperelasticSystem::from_state(const State &state) const
  {
    const Impl         &s = *impl;
    std::vector<double> x(n_equations(), 0.0);
    for (unsigned int d = 0; d < s.eq_of_dof.size(); ++d)
      if (s.eq_of_dof[d] >= 0)
        x[s.eq_of_dof[d]] = s.dof_component[d] == 3 ?
                              state.solution[d] / s.pressure_scale :
                              state.solution[d];
    for (unsigned int m = 0; m < n_multipliers(); ++m)
      x[s.n_free + m] = state.multipliers[m] / s.beta;
    return x;
  }



  double
  HyperelasticSystem::deformed_volume(const std::vector<double> &solution) const
  {
    const Impl &s      = *impl;
    double      volume = 0;
    for (unsigned int c = 0; c < s.mesh.n_cells(); ++c)
      for (unsigned int q = 0; q < s.n_q; ++q)
        volume += s.JxW[c * s.n_q + q] *
                  determinant(s.deformation_gradient(solution, c, q));
    return volume;
  }



  double
  HyperelasticSystem::strain_energy(const std::vector<double> &solution) const
  {
    const Impl  &s      = *impl;
    double       energy = 0;
    Tensor<2, 3> P;
    for (unsigned int c = 0; c < s.mesh.n_cells(); ++c)
      for (unsigned int q = 0; q < s.n_q; ++q)
        energy += s.JxW[c * s.n_q + q] *
                  s.material->evaluate(s.deformation_gradient(solution, c, q),
                                       P,
                                       nullptr);
    return energy;
  }



  void
  HyperelasticSystem::write_vtu(const State       &state,
                                const std::string &filename) const
  {
    const Impl &s = *impl;

    // Node-wise fields live on a scalar P1 space over the same mesh,
    // built only when output is written.
    const FE_SimplexP<3> fe_scalar(1);
    DoFHandler<3>        scalar(s.mesh.triangulation());
    scalar.distribute_dofs(fe_scalar);
    Vector<double> node_id(scalar.n_dofs()), fixed(scalar.n_dofs()),
      active(scalar.n_dofs());
    std::vector<bool> vertex_fixed(s.mesh.n_vertices(), false),
      vertex_tip(s.mesh.n_vertices(), false);
    for (const unsigned int v : s.nodes.fixed_vertices)
      vertex_fixed[v] = true;
    for (const unsigned int v : s.nodes.tip_vertices)
      vertex_tip[v] = true;
    for (const auto &cell : scalar.active_cell_iterators())
      for (unsigned int v = 0; v < 4; ++v)
        {
          const auto d = cell->vertex_dof_index(v, 0);
          const auto g = cell->vertex_index(v);
          node_id[d]   = s.mesh.node_id(g);
          fixed[d]     = vertex_fixed[g] ? 1 : 0;
          active[d]    = g == s.nodes.active_vertex || vertex_tip[g] ? 1 : 0;
        }

    // Reactions: the force the body exerts at constrained DoFs (the probe
    // force at the active node, the support forces at fixed nodes).
    Vector<double> displacement(state.solution.begin(), state.solution.end());
    Vector<double> reaction(n_dofs());
    const auto     f = nodal_residual(state.solution);
    for (const unsigned int d : s.fixed)
      reaction[d] = -f[d];
    if (has_contact())
      {
        // The contact forces, where the sphere touches.
        for (const auto &c : contact(state))
          if (c.force > 0)
            for (const unsigned int d : c.dofs)
              reaction[d] = -f[d];
      }
    else
      for (unsigned int m = 0; m < s.n_probe_dof_multipliers; ++m)
        reaction[s.multiplier_dof[m]] = state.multipliers[m];

    // With a pressure field the FE has a fourth, scalar component.
    std::vector<DataComponentInterpretation::DataComponentInterpretation>
      vector_field(3, DataComponentInterpretation::component_is_part_of_vector);
    std::vector<std::string> u_names(3, "displacement"), r_names(3, "reaction");
    if (s.mixed)
      {
        vector_field.push_back(
          DataComponentInterpretation::component_is_scalar);
        u_names.push_back("pressure");
        r_names.push_back("volume_residual");
      }
    DataOut<3> data_out;
    data_out.add_data_vector(s.dof_handler,
                             displacement,
                             u_names,
                             vector_field);
    data_out.add_data_vector(s.dof_handler, reaction, r_names, vector_field);
    data_out.add_data_vector(scalar, node_id, "node_id");
    data_out.add_data_vector(scalar, fixed, "fixed");
    data_out.add_data_vector(scalar, active, "active");
    data_out.build_patches(s.mapping, 1);
    // Into memory first: deal.II asserts on a stream that failed (a full
    // disk), which is an output error to report, not an internal one.
    std::ostringstream vtu;
    data_out.write_vtu(vtu);
    std::ofstream out(filename);
    if (!out)
      throw std::runtime_error("cannot write the file '" + filename + "'");
    out << vtu.str();
    out.flush();
    if (!out)
      throw std::runtime_error("writing the file '" + filename +
                               "' failed (is the disk full?)");
  }
} // namespace palpate
