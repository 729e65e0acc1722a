// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

#ifndef palpate_hyperelastic_hyperelastic_system_impl_h
#define palpate_hyperelastic_hyperelastic_system_impl_h

// Not an interface: HyperelasticSystem's implementation, shared by its
// source files, one job each:
//   hyperelastic_system.cc           the FE space, the DoFs and their
//                                    equations, the cached geometry, the
//                                    sparsity and the cells' colours; the
//                                    system's sizes and scales
//   hyperelastic_system_contact.cc   the sphere probe: its contact
//                                    candidates, their gaps and forces, the
//                                    probe's force and its derivatives
//   hyperelastic_system_assembly.cc  the residual and the tangent: the cell
//                                    kernel, the threaded loop over cells,
//                                    the dead loads, the constraint and
//                                    contact rows
//   hyperelastic_system_output.cc    a solution as a State and back, its
//                                    energy and volume, the VTU file
// Users of the system include hyperelastic_system.h, never this header.

#include <palpate/hyperelastic/hyperelastic_system.h>
#include <palpate/hyperelastic/material.h>
#include <palpate/mesh/node_selection.h>

#include <deal.II/base/quadrature_lib.h>
#include <deal.II/base/tensor.h>
#include <deal.II/dofs/dof_handler.h>
#include <deal.II/fe/fe_system.h>
#include <deal.II/fe/mapping_fe.h>

#include <tbb/task_arena.h>

#include <array>
#include <memory>
#include <vector>

namespace palpate
{
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
    dealii::Tensor<2, 3>
    deformation_gradient(const std::vector<double> &u,
                         const unsigned int         c,
                         const unsigned int         q) const
    {
      const unsigned int *dofs = &cell_dofs[c * dofs_per_cell];
      const double       *g =
        &gradients[(std::size_t(c) * n_q + q) * n_nodes_per_cell * 3];
      dealii::Tensor<2, 3> F = dealii::unit_symmetric_tensor<3>();
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

    // assemble()'s steps (hyperelastic_system_assembly.cc), on u_work.
    /** Every cell's internal forces into f_work (all DoFs), and the
     * tangent into @p matrix if given; false if a cell's are not finite. */
    bool
    assemble_cells(std::vector<double> *matrix) const;
    /** The internal forces from f_work to their equations in @p residual,
     * less the dead loads; returns the internal forces' norm. */
    double
    gather_forces(std::vector<double> &residual) const;
    /** The rows of the multipliers that hold fixed and probe DoFs (at
     * @p target), into @p residual and @p matrix; returns the squared
     * norm of their forces. */
    double
    add_constraint_rows(const std::vector<double> &x,
                        const Utilities::Point3   &target,
                        std::vector<double>       &residual,
                        std::vector<double>       *matrix) const;
    /** The sphere's contact rows of every candidate, into @p residual and
     * (all of them, or with @p contact_in_matrix false only the
     * multipliers' diagonal) @p matrix; their squared forces are added to
     * @p lambda_norm. False for a node at the sphere's centre. */
    bool
    add_contact_rows(const std::vector<double> &x,
                     const Utilities::Point3   &target,
                     std::vector<double>       &residual,
                     std::vector<double>       *matrix,
                     const bool                 contact_in_matrix,
                     double                    &lambda_norm) const;

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

    const Mesh               &mesh;
    NodeSelection             nodes;
    std::unique_ptr<Material> material;
    const Formulation         formulation;
    const bool                mixed; // pressure field present
    const bool                taylor_hood;
    const double              kappa_inverse; // 0: exact incompressibility
    const bool                stabilize;     // Brezzi-Pitkaranta (P1-P1)
    const double              alpha;
    const unsigned int        degree;
    std::unique_ptr<dealii::FESystem<3>> fe;
    dealii::MappingFE<3>                 mapping;
    dealii::QGaussSimplex<3>             quadrature;
    dealii::DoFHandler<3>                dof_handler;
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
} // namespace palpate

#endif
