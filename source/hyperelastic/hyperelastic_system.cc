// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

// HyperelasticSystem's set-up (step-44's system_setup, in parts): the FE
// space and its DoFs, which are fixed and which the probe moves, the
// equations' numbering, the geometry cached for the assembly, the sparsity
// pattern and the cells' colours; and the system's sizes, scales and DoF
// layout as its users ask for them.

#include <palpate/base/exceptions.h>
#include <palpate/hyperelastic/hyperelastic_system_impl.h>
#include <palpate/mesh/mesh.h>

#include <deal.II/fe/fe_simplex_p.h>
#include <deal.II/fe/fe_values.h>
#include <deal.II/grid/tria.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <set>

namespace palpate
{
  using namespace dealii;

  namespace
  {
    std::unique_ptr<FESystem<3>>
    make_fe(const unsigned int degree, const bool mixed)
    {
      if (mixed)
        return std::make_unique<FESystem<3>>(FE_SimplexP<3>(degree),
                                             3,
                                             FE_SimplexP<3>(1),
                                             1);
      return std::make_unique<FESystem<3>>(FE_SimplexP<3>(degree), 3);
    }
  } // namespace



  HyperelasticSystem::Impl::Impl(const Mesh                      &mesh,
                                 const NodeSelection             &nodes,
                                 const Parameters::AllParameters &p)
    : mesh(mesh)
    , nodes(nodes)
    , material(Material::create(p.material_model))
    , formulation(material->formulation())
    , mixed(formulation.pressure != Formulation::Pressure::none)
    , taylor_hood(mixed && formulation.displacement_degree == 2)
    , kappa_inverse(formulation.pressure == Formulation::Pressure::penalty ?
                      1.0 / formulation.bulk_modulus :
                      0.0)
    , stabilize(mixed && !taylor_hood && formulation.stabilization)
    , alpha(formulation.stabilization_factor)
    , degree(formulation.degree(p.discretization.polynomial_degree))
    , fe(make_fe(degree, mixed))
    , mapping(FE_SimplexP<3>(1))
    , quadrature(p.discretization.quadrature_order > 0 ?
                   p.discretization.quadrature_order :
                   // Exact for St.Venant-Kirchhoff; the penalty's pressure
                   // mass matrix needs the 4-point rule on P1.
                   (degree == 1 ? (kappa_inverse > 0 ? 2 : 1) : 3))
    , dof_handler(mesh.triangulation())
    , n_threads(p.nonlinear_solver.assembly_threads)
  {
    distribute_dofs();
    const unsigned int n_cells = mesh.n_cells();
    L                          = mesh.diameter();
    const double h_mean        = std::cbrt(mesh.volume() / n_cells);

    std::vector<unsigned int> tip_dofs;
    const std::vector<bool>   dof_fixed = find_fixed_and_active_dofs(tip_dofs);
    const bool                has_active =
      nodes.active_vertex != NodeSelection::no_active_node;
    const bool sphere = has_active && nodes.sphere_tip;
    if (sphere)
      find_contact_candidates(p, dof_fixed);
    const unsigned int n_eq =
      number_equations(p, dof_fixed, tip_dofs, sphere, has_active);
    const double mu = material->shear_modulus();
    cache_geometry(mu);
    build_sparsity(n_eq);

    // --- Scales: the constraint rows by a typical diagonal stiffness E h,
    // the pressure unknowns by mu/h, so that every row is a force (N) and
    // every unknown a length (m).
    beta = material->youngs_modulus() * h_mean;
    if (mixed)
      pressure_scale = mu / h_mean;

    color_cells();
    if (n_threads > 1)
      arena = std::make_unique<tbb::task_arena>(n_threads);
    u_work.resize(dof_handler.n_dofs());
  }



  void
  HyperelasticSystem::Impl::distribute_dofs()
  {
    dof_handler.distribute_dofs(*fe);
    n_nodes_per_cell = fe->base_element(0).n_dofs_per_cell();
    n_pressure       = mixed ? fe->base_element(1).n_dofs_per_cell() : 0;
    n_q              = quadrature.size();
    dofs_per_cell    = fe->n_dofs_per_cell();
    local_dof.resize(3 * n_nodes_per_cell);
    for (unsigned int k = 0; k < n_nodes_per_cell; ++k)
      for (unsigned int c = 0; c < 3; ++c)
        local_dof[3 * k + c] = fe->component_to_system_index(c, k);
    for (unsigned int m = 0; m < n_pressure; ++m)
      local_pdof.push_back(fe->component_to_system_index(3, m));
  }



  // A DoF on a vertex belongs to that node; a DoF on an edge (P2) is fixed
  // when both of the edge's end nodes are. Pressure DoFs are never fixed.
  std::vector<bool>
  HyperelasticSystem::Impl::find_fixed_and_active_dofs(
    std::vector<unsigned int> &tip_dofs)
  {
    const unsigned int n_dofs = dof_handler.n_dofs();
    const bool         has_active =
      nodes.active_vertex != NodeSelection::no_active_node;
    std::vector<unsigned int> vertex_mask(mesh.n_vertices(),
                                          0); // bit c: component c fixed
    for (const unsigned int v : nodes.fixed_vertices)
      vertex_mask[v] = 7;
    for (const auto &[v, c] : nodes.fixed_components)
      vertex_mask[v] |= 1u << c;
    std::vector<bool> dof_fixed(n_dofs, false);
    active.fill(static_cast<unsigned int>(-1));
    // A rigid tip: its other nodes' DoFs, in the order of tip_vertices.
    std::vector<int> tip_index(mesh.n_vertices(), -1);
    for (unsigned int t = 0; t < nodes.tip_vertices.size(); ++t)
      tip_index[nodes.tip_vertices[t]] = t;
    tip_dofs.assign(3 * nodes.tip_vertices.size(), 0);
    dof_position.resize(n_dofs);
    dof_component.resize(n_dofs);
    std::vector<types::global_dof_index> dofs(dofs_per_cell);
    const unsigned int first_line = fe->get_first_line_index();
    const unsigned int first_quad = fe->get_first_quad_index(0);
    for (const auto &cell : dof_handler.active_cell_iterators())
      {
        cell->get_dof_indices(dofs);
        for (unsigned int i = 0; i < dofs_per_cell; ++i)
          {
            const unsigned int component =
              fe->system_to_component_index(i).first;
            dof_component[dofs[i]] = component;
            if (i < first_line)
              {
                const unsigned int v =
                  cell->vertex_index(i / fe->n_dofs_per_vertex());
                dof_position[dofs[i]] = mesh.vertices()[v];
                if (component < 3)
                  {
                    if (vertex_mask[v] & (1u << component))
                      dof_fixed[dofs[i]] = true;
                    if (has_active && v == nodes.active_vertex)
                      active[component] = dofs[i];
                    if (has_active && tip_index[v] >= 0)
                      tip_dofs[3 * tip_index[v] + component] = dofs[i];
                  }
              }
            else if (i < first_quad)
              {
                const auto line =
                  cell->line((i - first_line) / fe->n_dofs_per_line());
                const auto c          = line->center();
                dof_position[dofs[i]] = {{c[0], c[1], c[2]}};
                if (component < 3 &&
                    (vertex_mask[line->vertex_index(0)] & (1u << component)) &&
                    (vertex_mask[line->vertex_index(1)] & (1u << component)))
                  dof_fixed[dofs[i]] = true;
              }
          }
      }
    for (unsigned int d = 0; d < n_dofs; ++d)
      if (dof_fixed[d])
        fixed.push_back(d);
    fixed_value.assign(n_dofs, 0.0);
    return dof_fixed;
  }



  unsigned int
  HyperelasticSystem::Impl::number_equations(
    const Parameters::AllParameters &p,
    const std::vector<bool>         &dof_fixed,
    const std::vector<unsigned int> &tip_dofs,
    const bool                       sphere,
    const bool                       has_active)
  {
    const unsigned int n_dofs = dof_handler.n_dofs();
    // --- Equations: free DoFs first (in DoF order), then multipliers: the
    // active node's three, then the fixed DoFs' if they use multipliers.
    const bool eliminate =
      p.boundary_conditions.fixed_nodes.treatment == "elimination";
    eq_of_dof.assign(n_dofs, -1);
    for (unsigned int d = 0; d < n_dofs; ++d)
      if (!(eliminate && dof_fixed[d]))
        eq_of_dof[d] = n_free++;
    if (sphere)
      n_active_multipliers = n_contact;
    else if (has_active)
      {
        multiplier_dof.assign(active.begin(), active.end());
        multiplier_dof.insert(multiplier_dof.end(),
                              tip_dofs.begin(),
                              tip_dofs.end());
        n_active_multipliers    = multiplier_dof.size();
        n_probe_dof_multipliers = multiplier_dof.size();
      }
    if (!eliminate)
      multiplier_dof.insert(multiplier_dof.end(), fixed.begin(), fixed.end());
    for (auto &c : contact)
      for (unsigned int a = 0; a < 3; ++a)
        c.eq[a] = eq_of_dof[c.dof[a]];
    return n_free + n_contact + multiplier_dof.size();
  }



  void
  HyperelasticSystem::Impl::cache_geometry(const double mu)
  {
    const unsigned int                   n_cells = mesh.n_cells();
    std::vector<types::global_dof_index> dofs(dofs_per_cell);
    // --- Geometry, cached once: shape gradients, JxW, DoF indices; the
    // pressure shape values (the same on every cell of an affine simplex
    // mesh) and, for the stabilisation, gradients and cell sizes.
    FEValues<3>                  fe_values(mapping,
                          fe->base_element(0),
                          quadrature,
                          update_gradients | update_values | update_JxW_values);
    std::unique_ptr<FEValues<3>> pressure_fe_values;
    if (mixed)
      pressure_fe_values =
        std::make_unique<FEValues<3>>(mapping,
                                      fe->base_element(1),
                                      quadrature,
                                      update_values | update_gradients);
    cell_dofs.resize(n_cells * dofs_per_cell);
    cell_eqs.resize(n_cells * dofs_per_cell);
    gradients.resize(std::size_t(n_cells) * n_q * n_nodes_per_cell * 3);
    JxW.resize(n_cells * n_q);
    if (stabilize)
      {
        pressure_gradients.resize(std::size_t(n_cells) * n_pressure * 3);
        stabilization_tau.resize(n_cells);
      }
    for (const auto &cell : dof_handler.active_cell_iterators())
      {
        const unsigned int c = cell->active_cell_index();
        // FEValues of the scalar elements: they need the geometry only.
        const typename Triangulation<3>::cell_iterator tria_cell(cell);
        fe_values.reinit(tria_cell);
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
                  gradients[((std::size_t(c) * n_q + q) * n_nodes_per_cell +
                             k) *
                              3 +
                            d] = g[d];
              }
          }
        if (mixed)
          {
            pressure_fe_values->reinit(tria_cell);
            if (pressure_values.empty())
              for (unsigned int q = 0; q < n_q; ++q)
                for (unsigned int m = 0; m < n_pressure; ++m)
                  pressure_values.push_back(
                    pressure_fe_values->shape_value(m, q));
            if (stabilize)
              {
                // P1 pressure: gradients are constant on the cell. h is the
                // edge of the regular tetrahedron of the cell's volume.
                for (unsigned int m = 0; m < n_pressure; ++m)
                  for (unsigned int d = 0; d < 3; ++d)
                    pressure_gradients[(std::size_t(c) * n_pressure + m) * 3 +
                                       d] =
                      pressure_fe_values->shape_grad(m, 0)[d];
                const double h =
                  std::cbrt(6 * std::sqrt(2.0) * cell->measure());
                stabilization_tau[c] = alpha * h * h / mu;
              }
          }
      }
  }



  void
  HyperelasticSystem::Impl::build_sparsity(const unsigned int n_eq)
  {
    const unsigned int n_cells = mesh.n_cells();
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
        rows[e].push_back(n_free + n_contact + m);
        rows[n_free + n_contact + m].push_back(e);
      }
    // A contact multiplier couples with its node's three displacements,
    // and has a diagonal entry (its row while the node is not in
    // contact). The node's own 3 x 3 block is there from its cells.
    for (unsigned int k = 0; k < n_contact; ++k)
      {
        rows[n_free + k].push_back(n_free + k);
        for (const int e : contact[k].eq)
          if (e >= 0)
            {
              rows[e].push_back(n_free + k);
              rows[n_free + k].push_back(e);
            }
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
    matrix_position.assign(std::size_t(n_cells) * dofs_per_cell * dofs_per_cell,
                           -1);
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
        position_lambda_u.push_back(
          pattern.position(n_free + n_contact + m, e));
        position_u_lambda.push_back(
          pattern.position(e, n_free + n_contact + m));
      }
    for (unsigned int k = 0; k < n_contact; ++k)
      {
        auto &c       = contact[k];
        c.position_ll = pattern.position(n_free + k, n_free + k);
        // -1: an eliminated (fixed) component, which has no equation.
        for (unsigned int a = 0; a < 3; ++a)
          {
            c.position_lu[a] =
              c.eq[a] >= 0 ? pattern.position(n_free + k, c.eq[a]) : -1;
            c.position_ul[a] =
              c.eq[a] >= 0 ? pattern.position(c.eq[a], n_free + k) : -1;
            for (unsigned int b = 0; b < 3; ++b)
              c.position_uu[3 * a + b] = c.eq[a] >= 0 && c.eq[b] >= 0 ?
                                           pattern.position(c.eq[a], c.eq[b]) :
                                           -1;
          }
      }
  }



  void
  HyperelasticSystem::Impl::color_cells()
  {
    const unsigned int n_cells = mesh.n_cells();
    // --- Cell colours: no two cells of a colour share a node, so threads
    // can add into the global vectors without locks. (Vertices are taken
    // from the DoF cells, indexed as the assembly indexes them.)
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
  }



  void
  HyperelasticSystem::Impl::expand(const std::vector<double> &x,
                                   std::vector<double>       &u) const
  {
    u.resize(eq_of_dof.size());
    for (unsigned int d = 0; d < eq_of_dof.size(); ++d)
      u[d] = eq_of_dof[d] >= 0 ? x[eq_of_dof[d]] : fixed_value[d];
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



  bool
  HyperelasticSystem::has_pressure() const
  {
    return impl->mixed;
  }



  bool
  HyperelasticSystem::has_active_node() const
  {
    return impl->n_active_multipliers > 0;
  }



  unsigned int
  HyperelasticSystem::n_equations() const
  {
    return impl->pattern.n_rows;
  }



  unsigned int
  HyperelasticSystem::n_multipliers() const
  {
    return impl->n_contact + impl->multiplier_dof.size();
  }



  unsigned int
  HyperelasticSystem::n_active_multipliers() const
  {
    return impl->n_active_multipliers;
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



  bool
  HyperelasticSystem::has_contact() const
  {
    return impl->sphere_radius > 0;
  }



  double
  HyperelasticSystem::sphere_radius() const
  {
    return impl->sphere_radius;
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
    const Impl &s = *impl;
    std::string d;
    if (!s.mixed)
      d = "P" + std::to_string(s.degree) + " tetrahedra";
    else
      d = std::string(s.taylor_hood ? "Taylor-Hood P2-P1" : "P1-P1") +
          " tetrahedra, " +
          (s.kappa_inverse > 0 ? "nearly incompressible (penalty)" :
                                 "exactly incompressible") +
          (s.stabilize ? ", Brezzi-Pitkaranta stabilised" : "");
    return d + ", " + std::to_string(s.n_q) + " quadrature point" +
           (s.n_q > 1 ? "s" : "") + " per cell";
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
} // namespace palpate
