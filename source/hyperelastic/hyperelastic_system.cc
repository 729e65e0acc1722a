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
#include <map>
#include <set>
#include <sstream>

namespace palpate
{
  using namespace dealii;

  namespace
  {
    /** Largest number of scalar shape functions per cell (P2 tetrahedron). */
    constexpr unsigned int max_nodes = 10;
    /** Pressure shape functions per cell (P1). */
    constexpr unsigned int max_pressure = 4;
    /** Largest number of DoFs per cell. */
    constexpr unsigned int max_dofs = 3 * max_nodes + max_pressure;

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



  struct HyperelasticSystem::Impl
  {
    Impl(const Mesh                      &mesh,
         const NodeSelection             &nodes,
         const Parameters::AllParameters &p);

    // The constructor's steps (step-44's system_setup, in parts).
    /** The DoFs, and where each cell's displacement and pressure DoFs are
     * among its local ones. */
    void
    distribute_dofs();
    /** Which DoFs are fixed, which are the active node's (and a rigid
     * tip's other nodes', into @p tip_dofs); returns the fixed mask. */
    std::vector<bool>
    find_fixed_and_active_dofs(std::vector<unsigned int> &tip_dofs);
    /** Tip = sphere: the surface nodes that may touch it. */
    void
    find_contact_candidates(const Parameters::AllParameters &p,
                            const std::vector<bool>         &dof_fixed);
    /** The equations' numbering; returns how many. */
    unsigned int
    number_equations(const Parameters::AllParameters &p,
                     const std::vector<bool>         &dof_fixed,
                     const std::vector<unsigned int> &tip_dofs,
                     const bool                       sphere,
                     const bool                       has_active);
    /** Shape gradients, JxW and DoF indices per cell, cached once. */
    void
    cache_geometry(const double mu);
    /** The sparsity pattern and where each local entry goes. */
    void
    build_sparsity(const unsigned int n_eq);
    /** Cell colours for lock-free threaded assembly. */
    void
    color_cells();

    /** Residual and tangent contributions of cell @p c, scattered. */
    template <bool with_matrix, bool to_dofs>
    bool
    assemble_cell(const unsigned int         c,
                  const std::vector<double> &u,
                  double                    *residual,
                  double                    *matrix) const;

    /** F = I + grad u at quadrature point @p q of cell @p c. */
    Tensor<2, 3>
    deformation_gradient(const std::vector<double> &u,
                         const unsigned int         c,
                         const unsigned int         q) const
    {
      const unsigned int *dofs = &cell_dofs[c * dofs_per_cell];
      const double       *g =
        &gradients[(std::size_t(c) * n_q + q) * n_nodes_per_cell * 3];
      Tensor<2, 3> F = unit_symmetric_tensor<3>();
      for (unsigned int k = 0; k < n_nodes_per_cell; ++k)
        for (unsigned int a = 0; a < 3; ++a)
          for (unsigned int b = 0; b < 3; ++b)
            F[a][b] += u[dofs[local_dof[3 * k + a]]] * g[3 * k + b];
      return F;
    }

    /** Run @p f(c) over all cells, colour by colour, on the arena. */
    template <typename Function>
    bool
    for_all_cells(const Function &f) const;

    /** Full DoF vector (displacements, scaled pressures) from the unknowns. */
    void
    expand(const std::vector<double> &x, std::vector<double> &u) const;

    /** Subtract the dead loads (gravity, tractions) from @p f at all DoFs
     * for which @p keep(d) holds. */
    template <typename Keep>
    void
    subtract_dead_loads(double *f, const Keep &keep) const;

    /**
     * The contact of the sphere with candidate @p k at unknowns @p x and
     * HIP displacement @p target: the unit normal n from the sphere's
     * centre to the node's current position, the distance rho to the
     * centre, the gap g = rho - R (m), and the contact force's magnitude
     * lambda_hat = beta max(0, x_lambda - g) (N), which is positive exactly
     * when the node is in the active set.
     */
    struct Contact
    {
      Utilities::Point3 n;
      double            rho, gap, x_lambda, lambda_hat;
    };
    Contact
    contact_at(const unsigned int         k,
               const std::vector<double> &u,
               const std::vector<double> &x,
               const Utilities::Point3   &target) const;

    const Mesh                  &mesh;
    NodeSelection                nodes;
    std::unique_ptr<Material>    material;
    const Formulation            formulation;
    const bool                   mixed; // pressure field present
    const bool                   taylor_hood;
    const double                 kappa_inverse; // 0: exact incompressibility
    const bool                   stabilize;     // Brezzi-Pitkaranta (P1-P1)
    const double                 alpha;
    const unsigned int           degree;
    std::unique_ptr<FESystem<3>> fe;
    MappingFE<3>                 mapping;
    QGaussSimplex<3>             quadrature;
    DoFHandler<3>                dof_handler;
    unsigned int              n_nodes_per_cell, n_pressure, n_q, dofs_per_cell;
    std::vector<unsigned int> local_dof;  // [k * 3 + component] -> local DoF
    std::vector<unsigned int> local_pdof; // [m] -> local pressure DoF
    std::vector<unsigned int> cell_dofs;  // [cell * dofs_per_cell + i]
    std::vector<int>          cell_eqs;   // equation of each, or -1
    std::vector<double> gradients; // [((cell * n_q + q) * nodes + k) * 3 + d]
    std::vector<double> JxW;       // [cell * n_q + q]
    std::vector<double> pressure_values;    // [q * n_pressure + m]
    std::vector<double> pressure_gradients; // [(cell * n_pressure + m) * 3 + d]
    std::vector<double> stabilization_tau;  // [cell]: alpha h^2 / mu
    std::vector<long>   matrix_position;    // [cell * dpc^2 + i * dpc + j]
    std::vector<std::vector<unsigned int>> colors;

    std::vector<int> eq_of_dof;
    unsigned int     n_free = 0, n_active_multipliers = 0;
    // The first entries of multiplier_dof that hold a probe DoF at the HIP
    // (a point probe's or glued tip's; none for a sphere, whose
    // multipliers are contact rows), the rest hold fixed DoFs.
    unsigned int n_probe_dof_multipliers = 0;
    // Tip = sphere: one multiplier per surface node that the sphere may
    // touch (the contact candidates), equations n_free ... n_free +
    // n_contact - 1, before those of multiplier_dof.
    struct ContactNode
    {
      std::array<unsigned int, 3> dof;         // x, y, z DoFs of the node
      std::array<int, 3>          eq;          // their equations
      Utilities::Point3           position;    // reference position (m)
      std::array<long, 3>         position_lu; // CSR entries (lambda, u_a)
      std::array<long, 3>         position_ul; // (u_a, lambda)
      std::array<long, 9>         position_uu; // (u_a, u_b)
      long                        position_ll; // (lambda, lambda)
    };
    std::vector<ContactNode> contact;
    // With a sphere, the surface triangles as their vertices' x, y, z DoFs
    // and reference positions: where the deformed surface is, to tell a
    // sphere that touches it from one that went through it.
    std::vector<std::array<std::array<unsigned int, 3>, 3>> surface_dofs;
    std::vector<std::array<Utilities::Point3, 3>>           surface_rest;
    unsigned int                                            n_contact     = 0;
    double                                                  sphere_radius = 0;
    Utilities::Point3              sphere_rest_center = {{0, 0, 0}};
    std::vector<unsigned int>      multiplier_dof;
    std::vector<long>              position_lambda_u, position_u_lambda;
    std::vector<double>            fixed_value;
    std::array<unsigned int, 3>    active;
    std::vector<unsigned int>      fixed;
    std::vector<Utilities::Point3> dof_position;
    std::vector<unsigned int>      dof_component;
    SparsityCSR                    pattern;

    double              beta, L, pressure_scale = 1;
    std::vector<double> f_body, f_surface;
    double              load_factor = 1;

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
    const bool sphere = has_active && p.boundary_conditions.active_node.tip ==
                                        Parameters::ActiveNode::Tip::sphere;
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



  void
  HyperelasticSystem::Impl::find_contact_candidates(
    const Parameters::AllParameters &p,
    const std::vector<bool>         &dof_fixed)
  {
    // --- Tip = sphere: the contact candidates are the free surface nodes,
    // the vertices and (P2) the midpoints of the surface triangles' edges.
    // All of them, not only those near the probe's rest position: the
    // probe may go anywhere (palpate solve --to, the live view), a
    // candidate that is not touched costs one trivial row, and the
    // residual's loop over them is nothing next to the cells'.
    std::vector<types::global_dof_index> dofs(dofs_per_cell);
    const unsigned int first_line = fe->get_first_line_index();
    const unsigned int first_quad = fe->get_first_quad_index(0);
    sphere_radius      = p.boundary_conditions.active_node.tip_radius;
    sphere_rest_center = nodes.sphere_center;
    std::set<std::pair<unsigned int, unsigned int>> surface_edges;
    for (const auto &face : mesh.surface_faces())
      for (unsigned int i = 0; i < 3; ++i)
        surface_edges.insert(
          std::minmax(face.vertices[i], face.vertices[(i + 1) % 3]));
    // Node key: vertex v -> v, edge -> n_vertices + line index.
    std::map<unsigned int, std::array<unsigned int, 3>> node_dofs;
    std::map<unsigned int, Utilities::Point3>           node_position;
    for (const auto &cell : dof_handler.active_cell_iterators())
      {
        cell->get_dof_indices(dofs);
        for (unsigned int i = 0; i < first_quad && i < dofs_per_cell; ++i)
          {
            const unsigned int component =
              fe->system_to_component_index(i).first;
            if (component >= 3)
              continue;
            unsigned int key;
            if (i < first_line)
              {
                key = cell->vertex_index(i / fe->n_dofs_per_vertex());
                if (!mesh.on_surface()[key])
                  continue;
              }
            else
              {
                const auto line =
                  cell->line((i - first_line) / fe->n_dofs_per_line());
                if (!surface_edges.count(std::minmax(line->vertex_index(0),
                                                     line->vertex_index(1))))
                  continue;
                key = mesh.n_vertices() + line->index();
              }
            node_dofs[key][component] = dofs[i];
            node_position[key]        = dof_position[dofs[i]];
          }
      }
    for (const auto &face : mesh.surface_faces())
      {
        std::array<std::array<unsigned int, 3>, 3> d;
        std::array<Utilities::Point3, 3>           X;
        for (unsigned int i = 0; i < 3; ++i)
          {
            d[i] = node_dofs.at(face.vertices[i]);
            X[i] = node_position.at(face.vertices[i]);
          }
        surface_dofs.push_back(d);
        surface_rest.push_back(X);
      }
    // A node with some components fixed (a symmetry plane) slides on
    // its plane and may touch; one fixed entirely cannot move.
    for (const auto &[key, d] : node_dofs)
      if (!dof_fixed[d[0]] || !dof_fixed[d[1]] || !dof_fixed[d[2]])
        {
          ContactNode c;
          c.dof      = d;
          c.position = node_position[key];
          contact.push_back(c);
        }
    n_contact = contact.size();
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



  HyperelasticSystem::Impl::Contact
  HyperelasticSystem::Impl::contact_at(const unsigned int         k,
                                       const std::vector<double> &u,
                                       const std::vector<double> &x,
                                       const Utilities::Point3   &target) const
  {
    const ContactNode &c = contact[k];
    Contact            r;
    for (unsigned int a = 0; a < 3; ++a)
      r.n[a] = c.position[a] + u[c.dof[a]] - sphere_rest_center[a] - target[a];
    r.rho = Utilities::norm(r.n);
    for (unsigned int a = 0; a < 3; ++a)
      r.n[a] /= r.rho;
    r.gap        = r.rho - sphere_radius;
    r.x_lambda   = x[n_free + k];
    r.lambda_hat = beta * std::max(0.0, r.x_lambda - r.gap);
    return r;
  }



  template <typename Keep>
  void
  HyperelasticSystem::Impl::subtract_dead_loads(double     *f,
                                                const Keep &keep) const
  {
    for (unsigned int d = 0; d < f_body.size(); ++d)
      if (keep(d))
        f[d] -= f_body[d];
    if (!f_surface.empty())
      for (unsigned int d = 0; d < f_surface.size(); ++d)
        if (keep(d))
          f[d] -= load_factor * f_surface[d];
  }



  // One function on purpose (about 150 lines): the assembly's kernel, run
  // for every cell at every Newton iteration. It reads top-down as the weak
  // form (kinematics, stress, residual, tangent, scatter), and its loops
  // share the quadrature point's F, S and C and the cell's local arrays;
  // split, they would pass between the pieces on the hottest path of the
  // solver (doc/benchmarks/newton.md times it).
  template <bool with_matrix, bool to_dofs>
  bool
  HyperelasticSystem::Impl::assemble_cell(const unsigned int         c,
                                          const std::vector<double> &u,
                                          double                    *residual,
                                          double *matrix) const
  {
    const unsigned int  nk   = n_nodes_per_cell;
    const unsigned int  np   = n_pressure;
    const unsigned int  dpc  = dofs_per_cell;
    const unsigned int *dofs = &cell_dofs[c * dpc];

    double u_local[max_nodes][3];
    for (unsigned int k = 0; k < nk; ++k)
      for (unsigned int a = 0; a < 3; ++a)
        u_local[k][a] = u[dofs[local_dof[3 * k + a]]];
    double p_local[max_pressure];
    for (unsigned int m = 0; m < np; ++m)
      p_local[m] = u[dofs[local_pdof[m]]]; // scaled: p = pressure_scale p_local

    double r_local[max_dofs] = {};
    double k_local[with_matrix ? max_dofs * max_dofs : 1];
    if constexpr (with_matrix)
      std::fill_n(k_local, dpc * dpc, 0.0);
    const double s = pressure_scale;
    Tensor<2, 3> F, P, dJ;
    Tensor<4, 3> A, d2J;
    double       J;
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

        // The pressure: P = P_iso - p dJ/dF, A = A_iso - p d2J/dF2, and the
        // pressure rows s int N_m (-(J - 1) - p/kappa) (+ stabilisation).
        const double *N = mixed ? &pressure_values[q * np] : nullptr;
        if (mixed)
          {
            volume_derivatives(F, J, dJ, with_matrix ? &d2J : nullptr);
            double p_tilde = 0;
            for (unsigned int m = 0; m < np; ++m)
              p_tilde += p_local[m] * N[m];
            const double pressure = s * p_tilde;
            P -= pressure * dJ;
            if constexpr (with_matrix)
              A -= pressure * d2J;
            const double volumetric = -(J - 1) - kappa_inverse * pressure;
            for (unsigned int m = 0; m < np; ++m)
              r_local[local_pdof[m]] += s * w * volumetric * N[m];
          }

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
            if (mixed)
              {
                // K_u,p = K_p,u = -s w N_m (dJ/dF)_aJ g_kJ;
                // K_p,p = -s^2 w N_m N_n / kappa.
                for (unsigned int k = 0; k < nk; ++k)
                  for (unsigned int a = 0; a < 3; ++a)
                    {
                      const double dJg = dJ[a][0] * g[3 * k] +
                                         dJ[a][1] * g[3 * k + 1] +
                                         dJ[a][2] * g[3 * k + 2];
                      const unsigned int i = local_dof[3 * k + a];
                      for (unsigned int m = 0; m < np; ++m)
                        {
                          const double v = -s * w * N[m] * dJg;
                          k_local[i * dpc + local_pdof[m]] += v;
                          k_local[local_pdof[m] * dpc + i] += v;
                        }
                    }
                if (kappa_inverse > 0)
                  for (unsigned int m = 0; m < np; ++m)
                    for (unsigned int n = 0; n < np; ++n)
                      k_local[local_pdof[m] * dpc + local_pdof[n]] -=
                        s * s * w * kappa_inverse * N[m] * N[n];
              }
          }
      }

    // Brezzi-Pitkaranta: - tau int grad p . grad q over the cell (the
    // gradients are constant, so the integral is the volume).
    if (stabilize)
      {
        const double *G      = &pressure_gradients[std::size_t(c) * np * 3];
        double        volume = 0;
        for (unsigned int q = 0; q < n_q; ++q)
          volume += JxW[c * n_q + q];
        double grad_p[3] = {0, 0, 0};
        for (unsigned int m = 0; m < np; ++m)
          for (unsigned int d = 0; d < 3; ++d)
            grad_p[d] += s * p_local[m] * G[3 * m + d];
        const double t = stabilization_tau[c] * volume;
        for (unsigned int m = 0; m < np; ++m)
          {
            r_local[local_pdof[m]] -=
              s * t *
              (grad_p[0] * G[3 * m] + grad_p[1] * G[3 * m + 1] +
               grad_p[2] * G[3 * m + 2]);
            if constexpr (with_matrix)
              for (unsigned int n = 0; n < np; ++n)
                k_local[local_pdof[m] * dpc + local_pdof[n]] -=
                  s * s * t *
                  (G[3 * m] * G[3 * n] + G[3 * m + 1] * G[3 * n + 1] +
                   G[3 * m + 2] * G[3 * n + 2]);
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



  Utilities::Point3
  HyperelasticSystem::sphere_center(const Utilities::Point3 &target) const
  {
    const auto &c = impl->sphere_rest_center;
    return {{c[0] + target[0], c[1] + target[1], c[2] + target[2]}};
  }



  double
  HyperelasticSystem::sphere_center_distance(
    const std::vector<double> &x,
    const Utilities::Point3   &target) const
  {
    using namespace Utilities;
    const Impl &s = *impl;
    if (!has_contact())
      return std::numeric_limits<double>::infinity();
    s.expand(x, s.u_work);
    const Point3 c       = sphere_center(target);
    double       nearest = std::numeric_limits<double>::infinity();
    // Inside or outside by the parity of the crossings of a ray from the
    // centre (Moller and Trumbore's ray-triangle test), in a direction no
    // mesh is likely to line up with.
    const Point3 ray       = {{0.5377, 0.3107, 0.7836}};
    unsigned int crossings = 0;
    for (unsigned int f = 0; f < s.surface_dofs.size(); ++f)
      {
        std::array<Point3, 3> X;
        for (unsigned int i = 0; i < 3; ++i)
          for (unsigned int a = 0; a < 3; ++a)
            X[i][a] =
              s.surface_rest[f][i][a] + s.u_work[s.surface_dofs[f][i][a]];
        nearest =
          std::min(nearest,
                   distance(c, closest_on_triangle(c, X[0], X[1], X[2])));
        const Point3 e1 = minus(X[1], X[0]), e2 = minus(X[2], X[0]);
        const Point3 h   = cross(ray, e2);
        const double det = dot(e1, h);
        if (std::abs(det) < 1e-300)
          continue;
        const Point3 t0 = minus(c, X[0]);
        const double u  = dot(t0, h) / det;
        if (u < 0 || u > 1)
          continue;
        const Point3 q = cross(t0, e1);
        const double v = dot(ray, q) / det;
        if (v < 0 || u + v > 1)
          continue;
        if (dot(e2, q) / det > 0)
          ++crossings;
      }
    return crossings % 2 == 1 ? -nearest : nearest;
  }



  std::vector<HyperelasticSystem::ContactPoint>
  HyperelasticSystem::contact(const State &state) const
  {
    const Impl               &s = *impl;
    const std::vector<double> x = from_state(state);
    std::vector<ContactPoint> points(s.n_contact);
    for (unsigned int k = 0; k < s.n_contact; ++k)
      {
        const Impl::Contact c =
          s.contact_at(k, state.solution, x, state.active_displacement);
        points[k] = {s.contact[k].dof, c.gap, c.lambda_hat};
      }
    return points;
  }



  Utilities::Point3
  HyperelasticSystem::probe_force(const std::vector<double> &x,
                                  const Utilities::Point3   &target) const
  {
    const Impl       &s     = *impl;
    Utilities::Point3 force = {{0, 0, 0}};
    if (!has_contact())
      {
        // The sum over the tip's nodes (one for a point probe).
        for (unsigned int m = 0; m < s.n_probe_dof_multipliers; ++m)
          force[m % 3] += s.beta * x[s.n_free + m];
        return force;
      }
    s.expand(x, s.u_work);
    for (unsigned int k = 0; k < s.n_contact; ++k)
      {
        const Impl::Contact c = s.contact_at(k, s.u_work, x, target);
        for (unsigned int a = 0; a < 3; ++a)
          force[a] -= c.lambda_hat * c.n[a];
      }
    return force;
  }



  void
  HyperelasticSystem::probe_load(const std::vector<double> &x,
                                 const Utilities::Point3   &target,
                                 const unsigned int         j,
                                 std::vector<double>       &rhs) const
  {
    const Impl &s = *impl;
    rhs.assign(n_equations(), 0.0);
    if (!has_contact())
      {
        // R_lambda = beta (u - target) at the probe's rows of component j.
        for (unsigned int m = j; m < s.n_probe_dof_multipliers; m += 3)
          rhs[s.n_free + m] = s.beta;
        return;
      }
    // The contact terms depend on x_k - c only, so d/dc = -d/du_k of the
    // active nodes' terms (assemble()): -dR_u/dc_j = (beta + lambda/rho)
    // n n_j - lambda/rho e_j, and -dR_lambda/dc_j = -beta n_j.
    s.expand(x, s.u_work);
    for (unsigned int k = 0; k < s.n_contact; ++k)
      {
        const Impl::Contact c = s.contact_at(k, s.u_work, x, target);
        if (!(c.lambda_hat > 0))
          continue;
        const double curvature = c.lambda_hat / c.rho;
        for (unsigned int a = 0; a < 3; ++a)
          if (const int e = s.contact[k].eq[a]; e >= 0)
            rhs[e] = (s.beta + curvature) * c.n[a] * c.n[j] -
                     (a == j ? curvature : 0.0);
        rhs[s.n_free + k] = -s.beta * c.n[j];
      }
  }



  Utilities::Point3
  HyperelasticSystem::probe_force_change(const std::vector<double> &x,
                                         const Utilities::Point3   &target,
                                         const std::vector<double> &dx,
                                         const unsigned int         j) const
  {
    const Impl       &s  = *impl;
    Utilities::Point3 df = {{0, 0, 0}};
    if (!has_contact())
      {
        for (unsigned int m = 0; m < s.n_probe_dof_multipliers; ++m)
          df[m % 3] += s.beta * dx[s.n_free + m];
        return df;
      }
    // f = -sum lambda n with lambda = beta (x_lambda - g), g = rho - R:
    // with dr = du_k - e_j (the node relative to the centre),
    // dg = n . dr, dn = (dr - n (n . dr)) / rho.
    s.expand(x, s.u_work);
    for (unsigned int k = 0; k < s.n_contact; ++k)
      {
        const Impl::Contact c = s.contact_at(k, s.u_work, x, target);
        if (!(c.lambda_hat > 0))
          continue;
        Utilities::Point3 dr;
        for (unsigned int a = 0; a < 3; ++a)
          {
            const int e = s.contact[k].eq[a];
            dr[a]       = (e >= 0 ? dx[e] : 0.0) - (a == j ? 1.0 : 0.0);
          }
        const double dg      = Utilities::dot(c.n, dr);
        const double dlambda = s.beta * (dx[s.n_free + k] - dg);
        for (unsigned int a = 0; a < 3; ++a)
          df[a] -=
            dlambda * c.n[a] + c.lambda_hat * (dr[a] - c.n[a] * dg) / c.rho;
      }
    return df;
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



  void
  HyperelasticSystem::add_surface_traction(const unsigned int       boundary_id,
                                           const Utilities::Point3 &traction)
  {
    Impl &s = *impl;
    if (s.f_surface.empty())
      s.f_surface.assign(n_dofs(), 0.0);
    const QGaussSimplex<2>               face_quadrature(s.degree + 1);
    FEFaceValues<3>                      fe_face(s.mapping,
                            s.fe->base_element(0),
                            face_quadrature,
                            update_values | update_JxW_values);
    std::vector<types::global_dof_index> dofs(s.dofs_per_cell);
    for (const auto &cell : s.dof_handler.active_cell_iterators())
      for (const unsigned int f : cell->face_indices())
        if (cell->face(f)->at_boundary() &&
            cell->face(f)->boundary_id() == boundary_id)
          {
            fe_face.reinit(typename Triangulation<3>::cell_iterator(cell), f);
            cell->get_dof_indices(dofs);
            for (unsigned int q = 0; q < face_quadrature.size(); ++q)
              for (unsigned int k = 0; k < s.n_nodes_per_cell; ++k)
                for (unsigned int c = 0; c < 3; ++c)
                  s.f_surface[dofs[s.local_dof[3 * k + c]]] +=
                    traction[c] * fe_face.shape_value(k, q) * fe_face.JxW(q);
          }
  }



  void
  HyperelasticSystem::add_body_force(const Utilities::Point3 &b)
  {
    // A dead load: integrated once, here, not at every residual.
    Impl &s = *impl;
    if (s.f_body.empty())
      s.f_body.assign(n_dofs(), 0.0);
    FEValues<3>                          fe_values(s.mapping,
                          s.fe->base_element(0),
                          s.quadrature,
                          update_values | update_JxW_values);
    std::vector<types::global_dof_index> dofs(s.dofs_per_cell);
    for (const auto &cell : s.dof_handler.active_cell_iterators())
      {
        fe_values.reinit(typename Triangulation<3>::cell_iterator(cell));
        cell->get_dof_indices(dofs);
        for (unsigned int q = 0; q < s.quadrature.size(); ++q)
          for (unsigned int k = 0; k < s.n_nodes_per_cell; ++k)
            for (unsigned int c = 0; c < 3; ++c)
              s.f_body[dofs[s.local_dof[3 * k + c]]] +=
                b[c] * fe_values.shape_value(k, q) * fe_values.JxW(q);
      }
  }



  void
  HyperelasticSystem::set_load_factor(const double factor)
  {
    impl->load_factor = factor;
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
                               double                    *force_scale,
                               const bool contact_in_matrix) const
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
    double f_norm = 0; // internal forces only, not the pressure rows
    for (unsigned int d = 0; d < s.eq_of_dof.size(); ++d)
      {
        if (s.dof_component[d] < 3)
          f_norm += s.f_work[d] * s.f_work[d];
        if (s.eq_of_dof[d] >= 0)
          residual[s.eq_of_dof[d]] = s.f_work[d];
      }

    // Dead loads, only when there are any (gravity switched on, tractions
    // added): no work at all otherwise.
    if (!s.f_body.empty() || !s.f_surface.empty())
      {
        for (unsigned int d = 0; d < s.eq_of_dof.size(); ++d)
          s.f_work[d] = 0;
        s.subtract_dead_loads(s.f_work.data(), [&](const unsigned int d) {
          return s.eq_of_dof[d] >= 0;
        });
        for (unsigned int d = 0; d < s.eq_of_dof.size(); ++d)
          if (s.eq_of_dof[d] >= 0)
            residual[s.eq_of_dof[d]] += s.f_work[d];
      }

    // The constraints: beta B^T x_lambda and beta (B u - g).
    double lambda_norm = 0;
    for (unsigned int m = 0; m < s.multiplier_dof.size(); ++m)
      {
        const unsigned int d = s.multiplier_dof[m];
        const double       value =
          m < s.n_probe_dof_multipliers ? target[m % 3] : s.fixed_value[d];
        const unsigned int e      = s.n_free + s.n_contact + m;
        const double       lambda = s.beta * x[e];
        residual[s.eq_of_dof[d]] += lambda;
        residual[e] = s.beta * (s.u_work[d] - value);
        lambda_norm += lambda * lambda;
        if (matrix != nullptr)
          {
            (*matrix)[s.position_lambda_u[m]] = s.beta;
            (*matrix)[s.position_u_lambda[m]] = s.beta;
          }
      }
    // The sphere's contact, as an augmented Lagrangian (Alart and
    // Curnier's semi-smooth form): with the gap g = |x_k - c| - R of
    // candidate k, its multiplier x_lambda (scaled like the others, a
    // length) and lambda_hat = beta max(0, x_lambda - g), the node gets the
    // contact force lambda_hat n along the normal n from the centre c, and
    // the multiplier's row is
    //   -beta (x_lambda - max(0, x_lambda - g)),
    // i.e. -beta g while in contact (x_lambda > g: the node lies on the
    // sphere) and -beta x_lambda otherwise (no force). At a solution this
    // is exactly the complementarity g >= 0, lambda >= 0, g lambda = 0;
    // the residual is continuous, and its Jacobian (taken on either side
    // of the kink) is symmetric, so the symmetric LDL^T factorisation
    // serves: the augmentation beta n n^T stiffens the node's block, and
    // -lambda_hat (I - n n^T)/rho is the sphere's curvature.
    for (unsigned int k = 0; k < s.n_contact; ++k)
      {
        const auto         &node = s.contact[k];
        const Impl::Contact c    = s.contact_at(k, s.u_work, x, target);
        if (!(c.rho > 1e-9 * s.sphere_radius))
          return false; // a node at the centre: far beyond any contact
        const unsigned int e = s.n_free + k;
        lambda_norm += c.lambda_hat * c.lambda_hat;
        if (c.lambda_hat > 0)
          {
            for (unsigned int a = 0; a < 3; ++a)
              if (node.eq[a] >= 0)
                residual[node.eq[a]] -= c.lambda_hat * c.n[a];
            residual[e] = -s.beta * c.gap;
            if (matrix != nullptr && !contact_in_matrix)
              (*matrix)[node.position_ll] = -s.beta;
            else if (matrix != nullptr)
              {
                (*matrix)[node.position_ll] = 0;
                const double curvature      = c.lambda_hat / c.rho;
                for (unsigned int a = 0; a < 3; ++a)
                  if (node.eq[a] >= 0)
                    {
                      (*matrix)[node.position_lu[a]] = -s.beta * c.n[a];
                      (*matrix)[node.position_ul[a]] = -s.beta * c.n[a];
                      for (unsigned int b = 0; b < 3; ++b)
                        if (node.eq[b] >= 0)
                          (*matrix)[node.position_uu[3 * a + b]] +=
                            (s.beta + curvature) * c.n[a] * c.n[b] -
                            (a == b ? curvature : 0.0);
                    }
              }
          }
        else
          {
            residual[e] = -s.beta * c.x_lambda;
            if (matrix != nullptr)
              {
                (*matrix)[node.position_ll] = -s.beta;
                for (unsigned int a = 0; a < 3; ++a)
                  if (node.eq[a] >= 0)
                    {
                      (*matrix)[node.position_lu[a]] = 0;
                      (*matrix)[node.position_ul[a]] = 0;
                    }
              }
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



  void
  HyperelasticSystem::contact_rows(const std::vector<double> &x,
                                   const Utilities::Point3   &target,
                                   std::vector<ContactRow>   &rows) const
  {
    const Impl &s = *impl;
    s.expand(x, s.u_work);
    rows.resize(s.n_contact);
    for (unsigned int k = 0; k < s.n_contact; ++k)
      {
        const Impl::Contact c = s.contact_at(k, s.u_work, x, target);
        rows[k]               = {
                        s.contact[k].eq, s.n_free + k, c.n, c.rho, c.gap, c.lambda_hat};
      }
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



  std::vector<double>
  HyperelasticSystem::nodal_residual(const std::vector<double> &solution) const
  {
    const Impl &s = *impl;
    // The kernel works with scaled pressures.
    std::vector<double> u = solution;
    if (s.mixed)
      for (unsigned int d = 0; d < u.size(); ++d)
        if (s.dof_component[d] == 3)
          u[d] /= s.pressure_scale;
    std::vector<double> f(n_dofs(), 0.0);
    s.for_all_cells([&](const unsigned int c) {
      return s.assemble_cell<false, true>(c, u, f.data(), nullptr);
    });
    s.subtract_dead_loads(f.data(), [](const unsigned int) { return true; });
    return f;
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
