// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

#include <palpate/base/exceptions.h>
#include <palpate/hyperelastic/hyperelastic_system.h>
#include <palpate/hyperelastic/material.h>
#include <palpate/mesh/mesh.h>
#include <palpate/mesh/node_selection.h>

#include <deal.II/base/quadrature_lib.h>
#include <deal.II/dofs/dof_handler.h>
#include <deal.II/fe/fe_simplex_p.h>
#include <deal.II/fe/fe_system.h>
#include <deal.II/fe/fe_values.h>
#include <deal.II/fe/mapping_fe.h>
#include <deal.II/grid/tria.h>
#include <deal.II/lac/vector.h>
#include <deal.II/numerics/data_out.h>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <fstream>
#include <set>

namespace palpate
{
  using namespace dealii;

  namespace
  {
    /** Largest number of scalar shape functions per cell (P2 tetrahedron). */
    constexpr unsigned int max_nodes = 10;
    /** Largest number of DoFs per cell. */
    constexpr unsigned int max_dofs = 3 * max_nodes;
  } // namespace



  struct HyperelasticSystem::Impl
  {
    Impl(const Mesh                      &mesh,
         const NodeSelection             &nodes,
         const Parameters::AllParameters &p);

    /** Residual and tangent contributions of cell @p c, scattered. */
    template <bool with_matrix, bool to_dofs>
    bool
    assemble_cell(const unsigned int         c,
                  const std::vector<double> &u,
                  double                    *residual,
                  double                    *matrix) const;

    /** Run @p f(c) over all cells, colour by colour, on the arena. */
    template <typename Function>
    bool
    for_all_cells(const Function &f) const;

    /** Full DoF vector of displacements from the unknowns. */
    void
    expand(const std::vector<double> &x, std::vector<double> &u) const;

    const Mesh               &mesh;
    NodeSelection             nodes;
    std::unique_ptr<Material> material;
    const unsigned int        degree;
    FESystem<3>               fe;
    MappingFE<3>              mapping;
    QGaussSimplex<3>          quadrature;
    DoFHandler<3>             dof_handler;
    unsigned int              n_nodes_per_cell, n_q, dofs_per_cell;
    std::vector<unsigned int> local_dof; // [k * 3 + component] -> local DoF
    std::vector<unsigned int> cell_dofs; // [cell * dofs_per_cell + i]
    std::vector<int>          cell_eqs;  // equation of each, or -1
    std::vector<double> gradients; // [((cell * n_q + q) * nodes + k) * 3 + d]
    std::vector<double> JxW;       // [cell * n_q + q]
    std::vector<long>   matrix_position; // [cell * dpc^2 + i * dpc + j]
    std::vector<std::vector<unsigned int>> colors;

    std::vector<int>                eq_of_dof;
    unsigned int                    n_free = 0;
    std::vector<unsigned int>       multiplier_dof;
    std::vector<long>               position_lambda_u, position_u_lambda;
    std::vector<double>             fixed_value;
    std::array<unsigned int, 3>     active;
    std::vector<unsigned int>       fixed;
    std::vector<std::array<int, 3>> vertex_dofs;
    std::vector<Utilities::Point3>  dof_position;
    std::vector<unsigned int>       dof_component;
    SparsityCSR                     pattern;

    double              beta, L;
    bool                gravity;
    std::vector<double> f_ext;

    unsigned int                     n_threads;
    std::unique_ptr<tbb::task_arena> arena;
    mutable std::vector<double>      u_work, f_work;
  };



  HyperelasticSystem::Impl::Impl(const Mesh                      &mesh,
                                 const NodeSelection             &nodes,
                                 const Parameters::AllParameters &p)
    : mesh(mesh)
    , nodes(nodes)
    , material(Material::create(p.material_model))
    , degree(p.discretization.polynomial_degree)
    , fe(FE_SimplexP<3>(degree), 3)
    , mapping(FE_SimplexP<3>(1))
    , quadrature(p.discretization.quadrature_order > 0 ?
                   p.discretization.quadrature_order :
                   (degree == 1 ? 1 : 3))
    , dof_handler(mesh.triangulation())
    , gravity(p.effects.gravity)
    , n_threads(p.nonlinear_solver.assembly_threads)
  {
    dof_handler.distribute_dofs(fe);
    n_nodes_per_cell = fe.base_element(0).n_dofs_per_cell();
    n_q              = quadrature.size();
    dofs_per_cell    = fe.n_dofs_per_cell();
    local_dof.resize(3 * n_nodes_per_cell);
    for (unsigned int k = 0; k < n_nodes_per_cell; ++k)
      for (unsigned int c = 0; c < 3; ++c)
        local_dof[3 * k + c] = fe.component_to_system_index(c, k);

    const unsigned int n_cells = mesh.n_cells();
    const unsigned int n_dofs  = dof_handler.n_dofs();
    L                          = mesh.diameter();

    // --- Which DoFs are fixed, which are the active node's. A DoF on a
    // vertex belongs to that node; a DoF on an edge (P2) is fixed when both
    // of the edge's end nodes are.
    std::vector<bool> vertex_fixed(mesh.n_vertices(), false);
    for (const unsigned int v : nodes.fixed_vertices)
      vertex_fixed[v] = true;
    std::vector<bool> dof_fixed(n_dofs, false);
    vertex_dofs.assign(mesh.n_vertices(), {{-1, -1, -1}});
    dof_position.resize(n_dofs);
    dof_component.resize(n_dofs);
    std::vector<types::global_dof_index> dofs(dofs_per_cell);
    const unsigned int                   first_line = fe.get_first_line_index();
    const unsigned int first_quad = fe.get_first_quad_index(0);
    for (const auto &cell : dof_handler.active_cell_iterators())
      {
        cell->get_dof_indices(dofs);
        for (unsigned int i = 0; i < dofs_per_cell; ++i)
          {
            const unsigned int component =
              fe.system_to_component_index(i).first;
            dof_component[dofs[i]] = component;
            if (i < first_line)
              {
                const unsigned int v =
                  cell->vertex_index(i / fe.n_dofs_per_vertex());
                vertex_dofs[v][component] = dofs[i];
                dof_position[dofs[i]]     = mesh.vertices()[v];
                if (vertex_fixed[v])
                  dof_fixed[dofs[i]] = true;
              }
            else if (i < first_quad)
              {
                const auto line =
                  cell->line((i - first_line) / fe.n_dofs_per_line());
                const auto c          = line->center();
                dof_position[dofs[i]] = {{c[0], c[1], c[2]}};
                if (vertex_fixed[line->vertex_index(0)] &&
                    vertex_fixed[line->vertex_index(1)])
                  dof_fixed[dofs[i]] = true;
              }
          }
      }
    for (unsigned int c = 0; c < 3; ++c)
      active[c] = vertex_dofs[nodes.active_vertex][c];
    for (unsigned int d = 0; d < n_dofs; ++d)
      if (dof_fixed[d])
        fixed.push_back(d);
    fixed_value.assign(n_dofs, 0.0);

    // --- Equations: free DoFs first (in DoF order), then multipliers.
    const bool eliminate =
      p.boundary_conditions.fixed_nodes.treatment == "elimination";
    eq_of_dof.assign(n_dofs, -1);
    for (unsigned int d = 0; d < n_dofs; ++d)
      if (!(eliminate && dof_fixed[d]))
        eq_of_dof[d] = n_free++;
    multiplier_dof.assign(active.begin(), active.end());
    if (!eliminate)
      multiplier_dof.insert(multiplier_dof.end(), fixed.begin(), fixed.end());
    const unsigned int n_eq = n_free + multiplier_dof.size();

    // --- Geometry, cached once: shape gradients, JxW, DoF indices.
    FEValues<3> fe_values(mapping,
                          fe.base_element(0),
                          quadrature,
                          update_gradients | update_values | update_JxW_values);
    cell_dofs.resize(n_cells * dofs_per_cell);
    cell_eqs.resize(n_cells * dofs_per_cell);
    gradients.resize(n_cells * n_q * n_nodes_per_cell * 3);
    JxW.resize(n_cells * n_q);
    if (gravity)
      f_ext.assign(n_dofs, 0.0);
    const auto  &g_accel = p.effects.gravitational_acceleration;
    const double rho     = p.material_model.density;
    for (const auto &cell : dof_handler.active_cell_iterators())
      {
        const unsigned int c = cell->active_cell_index();
        // FEValues of the scalar element: it needs the geometry only.
        fe_values.reinit(typename Triangulation<3>::cell_iterator(cell));
        cell->get_dof_indices(dofs);
        for (unsigned int i = 0; i < dofs_per_cell; ++i)
          {
            cell_dofs[c * dofs_per_cell + i] = dofs[i];
            cell_eqs[c * dofs_per_cell + i]  = eq_of_dof[dofs[i]];
          }
        for (unsigned int q = 0; q < n_q; ++q)
          {
            JxW[c * n_q + q] = fe_values.JxW(q);
            for (unsigned int k = 0; k < n_nodes_per_cell; ++k)
              {
                const auto g = fe_values.shape_grad(k, q);
                for (unsigned int d = 0; d < 3; ++d)
                  gradients[((c * n_q + q) * n_nodes_per_cell + k) * 3 + d] =
                    g[d];
                // Gravity is a dead load: integrate it once, here.
                if (gravity)
                  for (unsigned int comp = 0; comp < 3; ++comp)
                    f_ext[dofs[local_dof[3 * k + comp]]] +=
                      rho * g_accel[comp] * fe_values.shape_value(k, q) *
                      fe_values.JxW(q);
              }
          }
      }

    // --- Sparsity pattern of the equations, and where each local entry
    // goes.
    std::vector<std::vector<unsigned int>> rows(n_eq);
    for (unsigned int c = 0; c < n_cells; ++c)
      for (unsigned int i = 0; i < dofs_per_cell; ++i)
        if (const int ei = cell_eqs[c * dofs_per_cell + i]; ei >= 0)
          for (unsigned int j = 0; j < dofs_per_cell; ++j)
            if (const int ej = cell_eqs[c * dofs_per_cell + j]; ej >= 0)
              rows[ei].push_back(ej);
    for (unsigned int m = 0; m < multiplier_dof.size(); ++m)
      {
        const int e = eq_of_dof[multiplier_dof[m]];
        rows[e].push_back(n_free + m);
        rows[n_free + m].push_back(e);
      }
    pattern.n_rows = n_eq;
    pattern.row_start.assign(1, 0);
    for (auto &r : rows)
      {
        std::sort(r.begin(), r.end());
        r.erase(std::unique(r.begin(), r.end()), r.end());
        pattern.column.insert(pattern.column.end(), r.begin(), r.end());
        pattern.row_start.push_back(pattern.column.size());
      }
    matrix_position.assign(n_cells * dofs_per_cell * dofs_per_cell, -1);
    for (unsigned int c = 0; c < n_cells; ++c)
      for (unsigned int i = 0; i < dofs_per_cell; ++i)
        if (const int ei = cell_eqs[c * dofs_per_cell + i]; ei >= 0)
          for (unsigned int j = 0; j < dofs_per_cell; ++j)
            if (const int ej = cell_eqs[c * dofs_per_cell + j]; ej >= 0)
              matrix_position[(std::size_t(c) * dofs_per_cell + i) *
                                dofs_per_cell +
                              j] = pattern.position(ei, ej);
    for (unsigned int m = 0; m < multiplier_dof.size(); ++m)
      {
        const int e = eq_of_dof[multiplier_dof[m]];
        position_lambda_u.push_back(pattern.position(n_free + m, e));
        position_u_lambda.push_back(pattern.position(e, n_free + m));
      }

    // --- Constraint scale: a typical diagonal stiffness E h, so that the
    // constraint rows are forces like the others.
    const double h = std::cbrt(mesh.volume() / n_cells);
    beta           = material->youngs_modulus() * h;

    // --- Cell colours: no two cells of a colour share a node, so threads
    // can add into the global vectors without locks.
    // (Vertices are taken from the DoF cells themselves, indexed as the
    // assembly indexes them.)
    std::vector<std::array<unsigned int, 4>> cell_vertices(n_cells);
    for (const auto &cell : dof_handler.active_cell_iterators())
      for (unsigned int v = 0; v < 4; ++v)
        cell_vertices[cell->active_cell_index()][v] = cell->vertex_index(v);
    std::vector<std::vector<unsigned int>> cells_of_vertex(mesh.n_vertices());
    for (unsigned int c = 0; c < n_cells; ++c)
      for (const unsigned int v : cell_vertices[c])
        cells_of_vertex[v].push_back(c);
    std::vector<int> color(n_cells, -1);
    for (unsigned int c = 0; c < n_cells; ++c)
      {
        std::set<int> taken;
        for (const unsigned int v : cell_vertices[c])
          for (const unsigned int other : cells_of_vertex[v])
            if (color[other] >= 0)
              taken.insert(color[other]);
        int k = 0;
        while (taken.count(k))
          ++k;
        color[c] = k;
        if (static_cast<unsigned int>(k) >= colors.size())
          colors.resize(k + 1);
        colors[k].push_back(c);
      }
    if (n_threads > 1)
      arena = std::make_unique<tbb::task_arena>(n_threads);
    u_work.resize(n_dofs);
  }



  void
  HyperelasticSystem::Impl::expand(const std::vector<double> &x,
                                   std::vector<double>       &u) const
  {
    u.resize(eq_of_dof.size());
    for (unsigned int d = 0; d < eq_of_dof.size(); ++d)
      u[d] = eq_of_dof[d] >= 0 ? x[eq_of_dof[d]] : fixed_value[d];
  }



  template <bool with_matrix, bool to_dofs>
  bool
  HyperelasticSystem::Impl::assemble_cell(const unsigned int         c,
                                          const std::vector<double> &u,
                                          double                    *residual,
                                          double *matrix) const
  {
    const unsigned int  nk   = n_nodes_per_cell;
    const unsigned int  dpc  = dofs_per_cell;
    const unsigned int *dofs = &cell_dofs[c * dpc];

    double u_local[max_nodes][3];
    for (unsigned int k = 0; k < nk; ++k)
      for (unsigned int a = 0; a < 3; ++a)
        u_local[k][a] = u[dofs[local_dof[3 * k + a]]];

    double r_local[max_dofs] = {};
    double k_local[with_matrix ? max_dofs * max_dofs : 1];
    if constexpr (with_matrix)
      std::fill_n(k_local, dpc * dpc, 0.0);
    Tensor<2, 3> F, P;
    Tensor<4, 3> A;
    for (unsigned int q = 0; q < n_q; ++q)
      {
        const double *g = &gradients[(std::size_t(c) * n_q + q) * nk * 3];
        F               = unit_symmetric_tensor<3>();
        for (unsigned int k = 0; k < nk; ++k)
          for (unsigned int a = 0; a < 3; ++a)
            for (unsigned int b = 0; b < 3; ++b)
              F[a][b] += u_local[k][a] * g[3 * k + b];
        if (!(determinant(F) > 0) || !material->admissible(F))
          return false;
        material->evaluate(F, P, with_matrix ? &A : nullptr);
        const double w = JxW[c * n_q + q];

        for (unsigned int k = 0; k < nk; ++k)
          for (unsigned int a = 0; a < 3; ++a)
            r_local[local_dof[3 * k + a]] +=
              w * (P[a][0] * g[3 * k] + P[a][1] * g[3 * k + 1] +
                   P[a][2] * g[3 * k + 2]);

        if constexpr (with_matrix)
          {
            // K_(ka)(lb) = w sum_JL A_aJbL g_kJ g_lL, in two steps:
            // Ag_k,abL = sum_J A_aJbL g_kJ, then contract with g_l.
            double Ag[max_nodes][3][3][3];
            for (unsigned int k = 0; k < nk; ++k)
              for (unsigned int a = 0; a < 3; ++a)
                for (unsigned int b = 0; b < 3; ++b)
                  for (unsigned int l = 0; l < 3; ++l)
                    Ag[k][a][b][l] = A[a][0][b][l] * g[3 * k] +
                                     A[a][1][b][l] * g[3 * k + 1] +
                                     A[a][2][b][l] * g[3 * k + 2];
            for (unsigned int k = 0; k < nk; ++k)
              for (unsigned int a = 0; a < 3; ++a)
                {
                  double *row = &k_local[local_dof[3 * k + a] * dpc];
                  for (unsigned int l = 0; l < nk; ++l)
                    for (unsigned int b = 0; b < 3; ++b)
                      row[local_dof[3 * l + b]] +=
                        w * (Ag[k][a][b][0] * g[3 * l] +
                             Ag[k][a][b][1] * g[3 * l + 1] +
                             Ag[k][a][b][2] * g[3 * l + 2]);
                }
          }
      }

    // Scatter: into equations (or all DoFs), and into the CSR values.
    for (unsigned int i = 0; i < dpc; ++i)
      {
        if constexpr (to_dofs)
          residual[dofs[i]] += r_local[i];
        else if (const int e = cell_eqs[c * dpc + i]; e >= 0)
          residual[e] += r_local[i];
        if constexpr (with_matrix)
          {
            const long *position =
              &matrix_position[(std::size_t(c) * dpc + i) * dpc];
            for (unsigned int j = 0; j < dpc; ++j)
              if (position[j] >= 0)
                matrix[position[j]] += k_local[i * dpc + j];
          }
      }
    return true;
  }



  template <typename Function>
  bool
  HyperelasticSystem::Impl::for_all_cells(const Function &f) const
  {
    if (!arena)
      {
        for (const auto &color : colors)
          for (const unsigned int c : color)
            if (!f(c))
              return false;
        return true;
      }
    // Enter the arena once; colours run one after the other inside it.
    std::atomic<bool> ok(true);
    arena->execute([&]() {
      for (const auto &color : colors)
        {
          tbb::parallel_for(
            tbb::blocked_range<std::size_t>(0, color.size(), 16),
            [&](const tbb::blocked_range<std::size_t> &range) {
              for (std::size_t i = range.begin(); i < range.end(); ++i)
                if (!f(color[i]))
                  ok = false;
            });
          if (!ok)
            return;
        }
    });
    return ok;
  }



  HyperelasticSystem::HyperelasticSystem(
    const Mesh                      &mesh,
    const NodeSelection             &nodes,
    const Parameters::AllParameters &parameters)
    : impl(std::make_unique<Impl>(mesh, nodes, parameters))
  {}



  HyperelasticSystem::~HyperelasticSystem() = default;



  unsigned int
  HyperelasticSystem::n_dofs() const
  {
    return impl->dof_handler.n_dofs();
  }



  unsigned int
  HyperelasticSystem::n_equations() const
  {
    return impl->pattern.n_rows;
  }



  unsigned int
  HyperelasticSystem::n_multipliers() const
  {
    return impl->multiplier_dof.size();
  }



  const SparsityCSR &
  HyperelasticSystem::sparsity() const
  {
    return impl->pattern;
  }



  const Material &
  HyperelasticSystem::material() const
  {
    return *impl->material;
  }



  double
  HyperelasticSystem::length_scale() const
  {
    return impl->L;
  }



  double
  HyperelasticSystem::constraint_scale() const
  {
    return impl->beta;
  }



  const std::array<unsigned int, 3> &
  HyperelasticSystem::active_dofs() const
  {
    return impl->active;
  }



  const std::vector<unsigned int> &
  HyperelasticSystem::fixed_dofs() const
  {
    return impl->fixed;
  }



  std::string
  HyperelasticSystem::discretization_description() const
  {
    return "P" + std::to_string(impl->degree) + " tetrahedra, " +
           std::to_string(impl->n_q) + " quadrature point" +
           (impl->n_q > 1 ? "s" : "") + " per cell";
  }



  void
  HyperelasticSystem::set_fixed_displacement(
    const std::function<Utilities::Point3(const Utilities::Point3 &)> &f)
  {
    std::fill(impl->fixed_value.begin(), impl->fixed_value.end(), 0.0);
    for (const unsigned int d : impl->fixed)
      impl->fixed_value[d] = f(impl->dof_position[d])[impl->dof_component[d]];
  }



  const std::vector<Utilities::Point3> &
  HyperelasticSystem::dof_positions() const
  {
    return impl->dof_position;
  }



  const std::vector<unsigned int> &
  HyperelasticSystem::dof_components() const
  {
    return impl->dof_component;
  }



  std::vector<double>
  HyperelasticSystem::rest_unknowns() const
  {
    return std::vector<double>(n_equations(), 0.0);
  }



  bool
  HyperelasticSystem::assemble(const std::vector<double> &x,
                               const Utilities::Point3   &target,
                               std::vector<double>       &residual,
                               std::vector<double>       *matrix,
                               double                    *force_scale) const
  {
    const Impl &s = *impl;
    s.expand(x, s.u_work);
    // Internal forces go to all DoFs first (that is where the reactions at
    // eliminated DoFs live), then to the equations.
    s.f_work.assign(n_dofs(), 0.0);
    bool ok;
    if (matrix != nullptr)
      {
        matrix->assign(s.pattern.n_nonzeros(), 0.0);
        ok = s.for_all_cells([&](const unsigned int c) {
          return s.assemble_cell<true, true>(c,
                                             s.u_work,
                                             s.f_work.data(),
                                             matrix->data());
        });
      }
    else
      ok = s.for_all_cells([&](const unsigned int c) {
        return s.assemble_cell<false, true>(c,
                                            s.u_work,
                                            s.f_work.data(),
                                            nullptr);
      });
    if (!ok)
      return false;

    residual.assign(n_equations(), 0.0);
    double f_norm = 0;
    for (unsigned int d = 0; d < s.eq_of_dof.size(); ++d)
      {
        f_norm += s.f_work[d] * s.f_work[d];
        if (s.eq_of_dof[d] >= 0)
          residual[s.eq_of_dof[d]] = s.f_work[d];
      }

    // Dead loads, only when the scene switches gravity on.
    if (s.gravity)
      for (unsigned int d = 0; d < s.eq_of_dof.size(); ++d)
        if (s.eq_of_dof[d] >= 0)
          residual[s.eq_of_dof[d]] -= s.f_ext[d];

    // The constraints: beta B^T x_lambda and beta (B u - g).
    double lambda_norm = 0;
    for (unsigned int m = 0; m < s.multiplier_dof.size(); ++m)
      {
        const unsigned int d      = s.multiplier_dof[m];
        const double       value  = m < 3 ? target[m] : s.fixed_value[d];
        const double       lambda = s.beta * x[s.n_free + m];
        residual[s.eq_of_dof[d]] += lambda;
        residual[s.n_free + m] = s.beta * (s.u_work[d] - value);
        lambda_norm += lambda * lambda;
        if (matrix != nullptr)
          {
            (*matrix)[s.position_lambda_u[m]] = s.beta;
            (*matrix)[s.position_u_lambda[m]] = s.beta;
          }
      }
    for (const double r : residual)
      if (!std::isfinite(r))
        return false;
    if (force_scale != nullptr)
      *force_scale =
        std::max({std::sqrt(f_norm),
                  std::sqrt(lambda_norm),
                  1e-12 * s.material->youngs_modulus() * s.L * s.L});
    return true;
  }



  double
  HyperelasticSystem::force_residual_norm(
    const std::vector<double> &residual) const
  {
    double sum = 0;
    for (unsigned int e = 0; e < impl->n_free; ++e)
      sum += residual[e] * residual[e];
    return std::sqrt(sum);
  }



  double
  HyperelasticSystem::constraint_violation(
    const std::vector<double> &residual) const
  {
    double worst = 0;
    for (unsigned int e = impl->n_free; e < residual.size(); ++e)
      worst = std::max(worst, std::abs(residual[e]) / impl->beta);
    return worst;
  }



  double
  HyperelasticSystem::max_displacement(const std::vector<double> &dx) const
  {
    double worst = 0;
    for (unsigned int e = 0; e < impl->n_free; ++e)
      worst = std::max(worst, std::abs(dx[e]));
    return worst;
  }



  void
  HyperelasticSystem::to_state(const std::vector<double> &x, State &state) const
  {
    const Impl &s = *impl;
    s.expand(x, state.solution);
    state.multipliers.resize(s.multiplier_dof.size());
    for (unsigned int m = 0; m < s.multiplier_dof.size(); ++m)
      state.multipliers[m] = s.beta * x[s.n_free + m];
    for (unsigned int c = 0; c < 3; ++c)
      state.force[c] = state.multipliers[c];
  }



  std::vector<double>
  HyperelasticSystem::from_state(const State &state) const
  {
    const Impl         &s = *impl;
    std::vector<double> x(n_equations(), 0.0);
    for (unsigned int d = 0; d < s.eq_of_dof.size(); ++d)
      if (s.eq_of_dof[d] >= 0)
        x[s.eq_of_dof[d]] = state.solution[d];
    for (unsigned int m = 0; m < s.multiplier_dof.size(); ++m)
      x[s.n_free + m] = state.multipliers[m] / s.beta;
    return x;
  }



  std::vector<double>
  HyperelasticSystem::nodal_residual(const std::vector<double> &solution) const
  {
    const Impl         &s = *impl;
    std::vector<double> f(n_dofs(), 0.0);
    s.for_all_cells([&](const unsigned int c) {
      return s.assemble_cell<false, true>(c, solution, f.data(), nullptr);
    });
    if (s.gravity)
      for (unsigned int d = 0; d < f.size(); ++d)
        f[d] -= s.f_ext[d];
    return f;
  }



  double
  HyperelasticSystem::strain_energy(const std::vector<double> &solution) const
  {
    const Impl  &s      = *impl;
    double       energy = 0;
    Tensor<2, 3> F, P;
    for (unsigned int c = 0; c < s.mesh.n_cells(); ++c)
      {
        const unsigned int *dofs = &s.cell_dofs[c * s.dofs_per_cell];
        for (unsigned int q = 0; q < s.n_q; ++q)
          {
            const double *g = &s.gradients[(std::size_t(c) * s.n_q + q) *
                                           s.n_nodes_per_cell * 3];
            F               = unit_symmetric_tensor<3>();
            for (unsigned int k = 0; k < s.n_nodes_per_cell; ++k)
              for (unsigned int a = 0; a < 3; ++a)
                for (unsigned int b = 0; b < 3; ++b)
                  F[a][b] +=
                    solution[dofs[s.local_dof[3 * k + a]]] * g[3 * k + b];
            energy +=
              s.JxW[c * s.n_q + q] * s.material->evaluate(F, P, nullptr);
          }
      }
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
    std::vector<bool> vertex_fixed(s.mesh.n_vertices(), false);
    for (const unsigned int v : s.nodes.fixed_vertices)
      vertex_fixed[v] = true;
    for (const auto &cell : scalar.active_cell_iterators())
      for (unsigned int v = 0; v < 4; ++v)
        {
          const auto d = cell->vertex_dof_index(v, 0);
          const auto g = cell->vertex_index(v);
          node_id[d]   = s.mesh.node_id(g);
          fixed[d]     = vertex_fixed[g] ? 1 : 0;
          active[d]    = g == s.nodes.active_vertex ? 1 : 0;
        }

    // Reactions: the force the body exerts at constrained DoFs (the probe
    // force at the active node, the support forces at fixed nodes).
    Vector<double> displacement(state.solution.begin(), state.solution.end());
    Vector<double> reaction(n_dofs());
    const auto     f = nodal_residual(state.solution);
    for (const unsigned int d : s.fixed)
      reaction[d] = -f[d];
    for (unsigned int c = 0; c < 3; ++c)
      reaction[s.active[c]] = state.force[c];

    std::vector<DataComponentInterpretation::DataComponentInterpretation>
      vector_field(3, DataComponentInterpretation::component_is_part_of_vector);
    DataOut<3> data_out;
    data_out.add_data_vector(s.dof_handler,
                             displacement,
                             std::vector<std::string>(3, "displacement"),
                             vector_field);
    data_out.add_data_vector(s.dof_handler,
                             reaction,
                             std::vector<std::string>(3, "reaction"),
                             vector_field);
    data_out.add_data_vector(scalar, node_id, "node_id");
    data_out.add_data_vector(scalar, fixed, "fixed");
    data_out.add_data_vector(scalar, active, "active");
    data_out.build_patches(s.mapping, 1);
    std::ofstream out(filename);
    if (!out)
      throw std::runtime_error("cannot write the file '" + filename + "'");
    data_out.write_vtu(out);
  }
} // namespace palpate
