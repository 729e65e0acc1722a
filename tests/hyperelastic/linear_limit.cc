// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

// The small-displacement limit is linear elasticity. An independent linear
// elastic solve on the same mesh, written the textbook way with deal.II
// (FEValues, symmetric gradients, AffineConstraints, UMFPACK; as in
// step-8), gives the reaction at the active node for a prescribed
// displacement delta. The non-linear force must agree to first order in
// delta: the relative difference shrinks tenfold per decade of delta.

#include <palpate/hyperelastic/hyperelastic_system.h>
#include <palpate/hyperelastic/material.h>
#include <palpate/hyperelastic/state_solver.h>

#include <deal.II/base/quadrature_lib.h>
#include <deal.II/dofs/dof_handler.h>
#include <deal.II/dofs/dof_tools.h>
#include <deal.II/fe/fe_simplex_p.h>
#include <deal.II/fe/fe_system.h>
#include <deal.II/fe/fe_values.h>
#include <deal.II/fe/mapping_fe.h>
#include <deal.II/lac/affine_constraints.h>
#include <deal.II/lac/dynamic_sparsity_pattern.h>
#include <deal.II/lac/sparse_direct.h>
#include <deal.II/lac/sparse_matrix.h>
#include <deal.II/lac/vector.h>

#include <cmath>

#include "../tests.h"

using namespace dealii;

namespace
{
  /** The force the body exerts on the active node in linear elasticity,
   * per metre of prescribed displacement along @p direction. */
  Tensor<1, 3>
  linear_force(const Body         &body,
               const double        lambda,
               const double        mu,
               const Tensor<1, 3> &direction)
  {
    const FESystem<3>      fe(FE_SimplexP<3>(1), 3);
    const MappingFE<3>     mapping(FE_SimplexP<3>(1));
    const QGaussSimplex<3> quadrature(1);
    DoFHandler<3>          dof_handler(body.mesh.triangulation());
    dof_handler.distribute_dofs(fe);

    // Constraints: fixed nodes zero, the active node at `direction`.
    std::vector<bool> fixed(body.mesh.n_vertices(), false);
    for (const unsigned int v : body.nodes.fixed_vertices)
      fixed[v] = true;
    AffineConstraints<double>            constraints;
    std::vector<types::global_dof_index> active(3);
    for (const auto &cell : dof_handler.active_cell_iterators())
      for (unsigned int v = 0; v < 4; ++v)
        for (unsigned int c = 0; c < 3; ++c)
          {
            const auto dof = cell->vertex_dof_index(v, c);
            if (fixed[cell->vertex_index(v)] &&
                !constraints.is_constrained(dof))
              constraints.add_line(dof);
            if (cell->vertex_index(v) == body.nodes.active_vertex)
              active[c] = dof;
          }
    for (unsigned int c = 0; c < 3; ++c)
      if (!constraints.is_constrained(active[c]))
        {
          constraints.add_line(active[c]);
          constraints.set_inhomogeneity(active[c], direction[c]);
        }
    constraints.close();

    DynamicSparsityPattern dsp(dof_handler.n_dofs());
    DoFTools::make_sparsity_pattern(dof_handler, dsp);
    SparsityPattern pattern;
    pattern.copy_from(dsp);
    SparseMatrix<double> K(pattern), K_free(pattern);
    Vector<double>       rhs(dof_handler.n_dofs()), u(dof_handler.n_dofs());

    const FEValuesExtractors::Vector     displacement(0);
    FEValues<3>                          fe_values(mapping,
                          fe,
                          quadrature,
                          update_gradients | update_JxW_values);
    const unsigned int                   n = fe.n_dofs_per_cell();
    FullMatrix<double>                   local(n, n);
    Vector<double>                       local_rhs(n);
    std::vector<types::global_dof_index> dofs(n);
    for (const auto &cell : dof_handler.active_cell_iterators())
      {
        fe_values.reinit(cell);
        local = 0;
        for (unsigned int q = 0; q < quadrature.size(); ++q)
          for (unsigned int i = 0; i < n; ++i)
            for (unsigned int j = 0; j < n; ++j)
              local(i, j) +=
                (lambda * fe_values[displacement].divergence(i, q) *
                   fe_values[displacement].divergence(j, q) +
                 2 * mu *
                   scalar_product(
                     fe_values[displacement].symmetric_gradient(i, q),
                     fe_values[displacement].symmetric_gradient(j, q))) *
                fe_values.JxW(q);
        cell->get_dof_indices(dofs);
        local_rhs = 0;
        constraints.distribute_local_to_global(local, local_rhs, dofs, K, rhs);
        K_free.add(dofs, local);
      }
    SparseDirectUMFPACK direct;
    direct.initialize(K);
    direct.vmult(u, rhs);
    constraints.distribute(u);

    // Reaction: (K u) at the active node is the force the probe applies.
    Vector<double> Ku(dof_handler.n_dofs());
    K_free.vmult(Ku, u);
    Tensor<1, 3> force;
    for (unsigned int c = 0; c < 3; ++c)
      force[c] = -Ku[active[c]];
    return force;
  }
} // namespace

int
main(int argc, char **argv)
{
  palpate::Environment env(argc, argv);
  initlog();

  for (const std::string material : {"St.Venant-Kirchhoff", "Neo-Hookean"})
    {
      palpate::Scene scene                       = shipped_scene("beam.prm");
      scene.parameters.material_model.model_name = material;
      scene.parameters.nonlinear_solver.residual_tolerance = 1e-12;
      const Body           body(scene);
      palpate::StateSolver solver(body.mesh, body.nodes, scene.parameters);
      const auto          &m = solver.system().material();
      const double         lambda =
        material == "Neo-Hookean" ?
                  dynamic_cast<const palpate::NeoHookean &>(m).lambda :
                  dynamic_cast<const palpate::StVenantKirchhoff &>(m).lambda;
      const double mu = m.shear_modulus();

      const Tensor<1, 3> direction({0.3, -0.2, -1.0});
      const Tensor<1, 3> stiffness = linear_force(body, lambda, mu, direction);
      deallog << material << ": linear stiffness of the free end along ("
              << direction << ") = " << stiffness << " N/m" << std::endl;

      double previous    = 0;
      bool   first_order = true;
      for (const double delta : {1e-3, 1e-4, 1e-5})
        {
          const palpate::Utilities::Point3 target = {
            {delta * direction[0], delta * direction[1], delta * direction[2]}};
          const palpate::State state =
            solver.solve(solver.rest_state(), target);
          Tensor<1, 3> difference;
          for (unsigned int c = 0; c < 3; ++c)
            difference[c] = state.force[c] - delta * stiffness[c];
          const double relative =
            difference.norm() / (delta * stiffness.norm());
          deallog << "  delta = " << delta
                  << " m: relative difference to linear "
                  << std::setprecision(2) << relative << std::setprecision(6);
          if (previous > 0)
            {
              deallog << ", ratio to the previous " << std::setprecision(3)
                      << previous / relative << std::setprecision(6);
              first_order =
                first_order && std::abs(previous / relative - 10) < 1.5;
            }
          deallog << std::endl;
          previous = relative;
        }
      deallog << "  first order in delta (every ratio within 10 +- 1.5): "
              << (first_order ? "yes" : "NO") << std::endl;
    }
}
