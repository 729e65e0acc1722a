// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

#ifndef palpate_hyperelastic_hyperelastic_system_h
#define palpate_hyperelastic_hyperelastic_system_h

#include <palpate/base/utilities.h>
#include <palpate/hyperelastic/linear_solver.h>
#include <palpate/hyperelastic/state.h>
#include <palpate/scene/parameters.h>

#include <array>
#include <functional>
#include <memory>
#include <string>
#include <vector>

namespace palpate
{
  class Mesh;
  class Material;
  struct NodeSelection;

  /**
   * The discrete non-linear system of one body: the finite element space
   * (FE_SimplexP of degree 1 or 2, three components; plus a P1 pressure
   * for Mooney-Rivlin), the constraints, and the assembly of the residual
   * and its tangent.
   *
   * With a pressure field (mixed u-p), the energy is
   *
   *   Pi(u, p) = int W_iso(F) - p (J - 1) - p^2 / (2 kappa) dV
   *
   * (1/kappa = 0 for exact incompressibility), so p is the hydrostatic
   * pressure and the pressure rows say int q (J - 1 + p/kappa) dV = 0. For
   * P1-P1, which is not inf-sup stable, the Brezzi-Pitkaranta term
   * - alpha h^2/mu int grad p . grad q is added to the pressure rows. The
   * pressure unknowns are scaled by mu/h so that all rows are forces and
   * all unknowns lengths, as for the multipliers.
   *
   * The unknowns x are the *equations* of the system:
   *
   *   x = [ free displacement (and pressure) DoFs | multipliers ]
   *
   * Fixed nodes are either eliminated (their DoFs are not unknowns) or
   * constrained by multipliers, as the scene says. The active node's three
   * DoFs are always constrained by multipliers. With the constraint rows
   * scaled by a stiffness beta (so that all residual rows are forces), the
   * residual is
   *
   *   R_u = f_int(u) - f_ext + beta B^T x_lambda,   R_lambda = beta (B u - g),
   *
   * and the physical multipliers are lambda = beta x_lambda. At equilibrium
   * lambda = f_ext - f_int at the constrained DoFs: the force the body
   * exerts on whatever holds that DoF — for the active node, on the probe.
   *
   * Total Lagrangian formulation: the reference geometry never changes, so
   * shape-function gradients and JxW are computed once with deal.II's
   * FEValues and cached; every assembly afterwards is arithmetic on cached
   * numbers. The sparsity pattern and the position of every local matrix
   * entry in it are fixed at construction.
   *
   * Not thread-safe: each solver worker owns its own instance. Assembly may
   * itself use several threads (Nonlinear solver / Assembly threads); cells
   * are coloured so that threads never write to the same entry, and the
   * summation order is the same for any thread count, so results are
   * bitwise reproducible.
   */
  class HyperelasticSystem
  {
  public:
    /** Set up the system for the scene's material, discretisation and
     * constraints. */
    HyperelasticSystem(const Mesh                      &mesh,
                       const NodeSelection             &nodes,
                       const Parameters::AllParameters &parameters);

    ~HyperelasticSystem();

    /** Number of DoFs of the finite element space (3 per node for P1). */
    unsigned int
    n_dofs() const;

    /** Number of unknowns/equations of the linear systems. */
    unsigned int
    n_equations() const;

    /** Number of Lagrange multipliers (3 for the active node, plus 3 per
     * fixed DoF triple when fixed nodes use multipliers). */
    unsigned int
    n_multipliers() const;

    /** Number of the probe's multipliers (the first multipliers): 3 per
     * node of a point probe or glued tip, one per contact candidate of a
     * sphere; 0 without an active node. */
    unsigned int
    n_active_multipliers() const;

    /** The fixed sparsity pattern of the tangent. */
    const SparsityCSR &
    sparsity() const;

    /** The material law. */
    const Material &
    material() const;

    /** The body's diameter L (m), used to scale displacement tolerances. */
    double
    length_scale() const;

    /** The scale beta of the constraint rows (N/m). */
    double
    constraint_scale() const;

    /**
     * Whether the body has a pressure field: the Mooney-Rivlin model's
     * incompressibility (exact or penalised) is a mixed u-p formulation.
     * Its pressure DoFs have component 3 in dof_components().
     */
    bool
    has_pressure() const;

    /** Whether the body has an active node (its three multipliers). */
    bool
    has_active_node() const;

    /**
     * Whether the probe is a rigid sphere in frictionless contact with the
     * surface (Tip = sphere). Its multipliers are then one per contact
     * candidate (every free surface node): the contact force on that node
     * (N) while it touches the sphere, zero otherwise.
     */
    bool
    has_contact() const;

    /** With a sphere: its radius (m) and its centre (m) at HIP
     * displacement @p target. */
    double
    sphere_radius() const;
    Utilities::Point3
    sphere_center(const Utilities::Point3 &target) const;

    /**
     * With a sphere: the distance (m) of its centre from the deformed
     * surface at unknowns @p x with the HIP displaced by @p target,
     * negative when the centre is inside the body (infinite without a
     * sphere). A sphere pressed on the surface is about its radius away
     * (less by the sag of the triangles between the nodes it touches,
     * h^2 / 8R for edges h). Much less means it went between the surface
     * nodes: the contact is node to sphere, and a sphere smaller than the
     * triangles can slip past a node it pushes. Its force is then the
     * mesh's, not the tissue's.
     */
    double
    sphere_center_distance(const std::vector<double> &x,
                           const Utilities::Point3   &target) const;

    /** One contact candidate of the sphere in a state. */
    struct ContactPoint
    {
      /** The node's x, y, z DoFs. */
      std::array<unsigned int, 3> dofs;
      /** Its distance from the sphere's surface (m; negative: inside). */
      double gap;
      /** The contact force on it, pushing it away from the centre (N;
       * zero when not in contact, never negative at an equilibrium). */
      double force;
    };

    /** Every contact candidate's gap and contact force in @p state
     * (empty without a sphere). */
    std::vector<ContactPoint>
    contact(const State &state) const;

    /**
     * One contact candidate as the condensed contact solver sees it at
     * some unknowns: where its rows are and how it touches the sphere.
     */
    struct ContactRow
    {
      /** The equations of the node's x, y, z displacements (-1: fixed). */
      std::array<int, 3> eq;
      /** The equation of its multiplier. */
      unsigned int multiplier_eq;
      /** Unit normal from the sphere's centre to the node (deformed). */
      Utilities::Point3 n;
      /** Distance of the node from the centre (m) and from the sphere's
       * surface, rho - R (m; negative: inside). */
      double rho, gap;
      /** The contact force the residual applies, lambda_hat = beta
       * max(0, x_lambda - gap) (N). */
      double lambda_hat;
    };

    /**
     * Every contact candidate's row data at unknowns @p x with the HIP
     * displaced by @p target, into @p rows (resized to the number of
     * candidates; no allocation once it has that size).
     */
    void
    contact_rows(const std::vector<double> &x,
                 const Utilities::Point3   &target,
                 std::vector<ContactRow>   &rows) const;

    /**
     * The force the body exerts on the probe (N) at unknowns @p x with the
     * HIP displaced by @p target: the sum of the probe's multipliers for a
     * point probe or glued tip, the resultant of the contact forces,
     * -sum lambda_k n_k, for a sphere.
     */
    Utilities::Point3
    probe_force(const std::vector<double> &x,
                const Utilities::Point3   &target) const;

    /**
     * The load of moving the probe: -dR/d target_j at unknowns @p x (the
     * right-hand side whose solution with the tangent is dx/d target_j),
     * into @p rhs.
     */
    void
    probe_load(const std::vector<double> &x,
               const Utilities::Point3   &target,
               const unsigned int         j,
               std::vector<double>       &rhs) const;

    /**
     * The change of probe_force() when the unknowns change by @p dx and the
     * HIP by the unit vector e_j: with dx = dx/d target_j this is the
     * column j of d force / d target, i.e. of minus the probe's stiffness.
     */
    Utilities::Point3
    probe_force_change(const std::vector<double> &x,
                       const Utilities::Point3   &target,
                       const std::vector<double> &dx,
                       const unsigned int         j) const;

    /** The DoFs of the active node (x, y, z components). */
    const std::array<unsigned int, 3> &
    active_dofs() const;

    /** All fixed DoFs (sorted). */
    const std::vector<unsigned int> &
    fixed_dofs() const;

    /** The reference position of each DoF's node (m): the vertex, or (P2)
     * the edge midpoint.
     */
    const std::vector<Utilities::Point3> &
    dof_positions() const;

    /** The component of each DoF: 0, 1, 2 for displacements, 3 for the
     * pressure. */
    const std::vector<unsigned int> &
    dof_components() const;

    /** Polynomial degree and number of quadrature points per cell. */
    std::string
    discretization_description() const;

    /**
     * Prescribe a displacement (m) at the fixed nodes, as a function of the
     * reference position. Fixed nodes are held at zero by default; tests
     * use this for the patch test.
     */
    void
    set_fixed_displacement(
      const std::function<Utilities::Point3(const Utilities::Point3 &)> &f);

    /**
     * Add a dead traction @p traction (Pa, per unit reference area) on the
     * boundary faces with @p boundary_id, scaled by the load factor (the
     * Surface traction effect, Cook's membrane).
     */
    void
    add_surface_traction(const unsigned int       boundary_id,
                         const Utilities::Point3 &traction);

    /**
     * Add a dead body force @p b (N/m^3, per unit reference volume), not
     * scaled by the load factor (the Gravity effect: rho g).
     */
    void
    add_body_force(const Utilities::Point3 &b);

    /** The factor that scales the surface tractions (default 1). */
    void
    set_load_factor(const double factor);

    /** Deformed volume of the body at @p solution, int J dV (m^3). */
    double
    deformed_volume(const std::vector<double> &solution) const;

    /** The unknowns of the rest state: all zero. */
    std::vector<double>
    rest_unknowns() const;

    /**
     * Evaluate the residual at unknowns @p x with the active node's
     * displacement @p target (m), and the tangent (into @p matrix, in the
     * order of sparsity()) if @p matrix is not null.
     *
     * Returns false, without a usable result, if some quadrature point is
     * not admissible (det F <= 0, or the material undefined there) or a
     * number is not finite.
     *
     * If @p force_scale is not null, it receives the force scale of the
     * convergence test (N): the largest of the norm of the internal forces
     * at all DoFs (which includes the reactions), the norm of the
     * multipliers, and 1e-12 E L^2.
     *
     * With @p contact_in_matrix false the tangent leaves the sphere's
     * contact out: every contact row is that of a candidate out of
     * contact (-beta on the diagonal, no coupling), whatever the active
     * set. Its factors then stay valid while the contact set moves, and
     * the condensed contact solver handles contact on the candidates'
     * compliance instead. The residual is the same either way.
     */
    bool
    assemble(const std::vector<double> &x,
             const Utilities::Point3   &target,
             std::vector<double>       &residual,
             std::vector<double>       *matrix,
             double                    *force_scale       = nullptr,
             const bool                 contact_in_matrix = true) const;

    /** Euclidean norm of the displacement rows of @p residual (N). */
    double
    force_residual_norm(const std::vector<double> &residual) const;

    /** Largest violation of a constraint, |B u - g| (m), given the
     * residual. */
    double
    constraint_violation(const std::vector<double> &residual) const;

    /** Largest absolute displacement entry of an update @p dx (m). */
    double
    max_displacement(const std::vector<double> &dx) const;

    /** Fill the solution (displacements in m, pressures in Pa),
     * multipliers and force of @p state from @p x. */
    void
    to_state(const std::vector<double> &x, State &state) const;

    /** The unknowns that reproduce @p state. */
    std::vector<double>
    from_state(const State &state) const;

    /**
     * f_int(u) - f_ext at every DoF for a state's displacement (N): zero at
     * free DoFs in equilibrium, minus the reactions at constrained ones.
     */
    std::vector<double>
    nodal_residual(const std::vector<double> &solution) const;

    /** Strain energy of a state's displacement (J). */
    double
    strain_energy(const std::vector<double> &solution) const;

    /**
     * Write a state as VTU for ParaView: displacement (warp by it to see
     * the deformed body), node ids as the mesh file numbers them, fixed and
     * active flags, and the force at the active node as field data.
     */
    void
    write_vtu(const State &state, const std::string &filename) const;

  private:
    struct Impl;
    std::unique_ptr<Impl> impl;
  };
} // namespace palpate

#endif
