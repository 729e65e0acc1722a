// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

#ifndef palpate_hyperelastic_patch_contact_h
#define palpate_hyperelastic_patch_contact_h

#include <palpate/base/utilities.h>

#include <array>
#include <cstdint>
#include <vector>

namespace palpate
{
  struct ContactPatch;

  /**
   * The haptic loop's side of State space / Interpolation = contact patch:
   * the sphere's frictionless contact solved, at every tick, against the
   * contact patches (ContactPatch) of the corners of the HIP's cell, for
   * the sphere where the HIP is.
   *
   * Each corner's patch gives a force F_k(x): the contact of the sphere at
   * x with the patch's linear model of the tissue around its state, the
   * resultant -sum lambda_i nu_i. F_k is exactly zero while the sphere is
   * off the corner's free surface, grows as the sphere's geometry and the
   * tissue's compliance say from the moment it touches, and is the state's
   * own force at the corner. The rendered force is their blend (blend()):
   * the state's force at every grid point, continuous everywhere, zero
   * where no corner's surface is touched. The corners blended are the 4
   * of the HIP's tetrahedron in its cell (simplex_weights()).
   *
   * The model is non-linear in the directions of the forces (they follow
   * the sphere's normals at the moved nodes), so each tick takes one step
   * of a fixed-point iteration from the patch's last solution: with the
   * normals nu at the nodes' current positions, the contact problem for
   * the nodes' gaps with every force taken off along them and for W along
   * them (nu_i^T H_ij nu_j on the nodes in contact), then the nodes moved
   * by the new forces. That step converges wherever the model's own
   * equilibrium is stable, at the rate of its slowest sliding mode
   * (direction_tolerance says why W must follow the normals). The sphere
   * moves microns per tick, so the iteration follows the hand and
   * converges where it rests. The contact problem is solved by the
   * primal-dual active-set method, warm started from the last tick; its
   * Cholesky factors are kept while the set of nodes in contact and their
   * normals stay, so that a tick of a hand at rest costs triangular
   * solves, the gaps and the nodes' move. At most max_iterations
   * active-set iterations per tick: a problem not settled by then gives
   * the iterate's non-negative forces, and the next tick goes on from it.
   *
   * Where a state's model is itself unstable (a sphere pressed so deep
   * that the surface could slide round it: 1 of the liver's 153 states
   * around the 10 mm stroke, 5 of the blob's 134, all 10-20 mm deep), the
   * iteration leaves the state's equilibrium for a neighbouring one of the
   * model when the HIP rests there for tens of ticks.
   *
   * All work space is allocated by the constructor: force() and blend()
   * never allocate. Not thread-safe: one per haptic thread.
   */
  class PatchContact
  {
  public:
    /** For patches of up to @p max_nodes nodes, of which at most
     * @p max_active are in contact at once. */
    PatchContact(const unsigned int max_nodes, const unsigned int max_active);

    /** The force on the sphere (N) with the HIP at @p x against @p patch
     * alone, after one more step of its fixed-point iteration;
     * @p stiffness (if not null) gets the normal forces' part of -dF/dx
     * there (N/m, row-major; symmetric, positive semi-definite). Returns
     * whether the contact problem settled. */
    bool
    force(const ContactPatch      &patch,
          const Utilities::Point3 &x,
          Utilities::Point3       &force,
          std::array<double, 9>   *stiffness = nullptr) noexcept;

    /**
     * The rendered force at @p x from the forces F_k(x) of the @p corners'
     * patches (weight 0: not solved), @p stiffness likewise from theirs (as
     * force()). Returns whether every problem settled.
     *
     * Each corner's model is a linearisation about its state, poor in two
     * ways that the blend corrects.
     *
     * The tissue stiffens as it is pressed: a linear model under-predicts
     * the force at the states around it (the rest tangent at a corner on
     * the surface gives 71 % of the force 10 mm deeper on the blob), and
     * the shortfall grows along the cell. Each patch knows its model's
     * force m_k(x_j) at the grid points around it (tabulate_neighbours()),
     * so at x_j the ratio r_kj = |F_j| / m_k(x_j) to the state's force F_j
     * there is known; the corner's force is scaled by those ratios
     * interpolated geometrically with the weights of the other corners,
     *
     *   F_k(x) <- F_k(x) prod_{j != k} r_kj^{w_j},
     *
     * each r_kj clamped to [2/3, 3/2] and taken as 1 where F_j or m_k(x_j)
     * is below force_floor (no contact to compare).
     *
     * A corner pressed deeper than the contact at x has a free surface
     * x - H f_s (the state's forces taken off with the tangent compliance)
     * not at the tissue's rest surface but nearer the sphere
     * (doc/benchmarks/contact-patch.md measures it), so its model touches
     * early at a shallow HIP; a corner pressed less, or not at all, has a
     * free surface near the rest surface and the contact's geometry exact.
     * The blend therefore weights each corner by @p weights w_k
     * (simplex_weights(); a corner of weight 0 is not solved) times a
     * confidence c_k = 1 / (1 + (d_k / tau)^2), d_k = max(0, |F_k| -
     * |F_k(x)|) / (|F_k| + force_floor), with F_k the state's force and
     * F_k(x) the corrected one, and normalises:
     *
     *   F(x) = sum_k w_k c_k F_k(x) / sum_k w_k c_k.
     *
     * At a grid point w is 1 for its corner and 0 for the others (the
     * state's force, uncorrected); weights, ratios and c_k are continuous,
     * so F is continuous; it is zero where every F_k is.
     */
    bool
    blend(const std::array<const ContactPatch *, 8> &corners,
          const std::array<double, 8>               &weights,
          const Utilities::Point3                   &x,
          Utilities::Point3                         &force,
          std::array<double, 9> *stiffness = nullptr) noexcept;

    /** Drop every warm start: the next call on any patch starts from its
     * state. */
    void
    forget() noexcept;

    /** What the last blend() (or force()) did: the tick's work, for the
     * benchmark to tell which ticks are slow and why. */
    struct Work
    {
      /** Corners solved, and of them those without a warm start. */
      unsigned int corners = 0, new_corners = 0;
      /** Active-set iterations and factorisations of W's active block,
       * summed over the corners. */
      unsigned int iterations = 0, factorizations = 0;
      /** The most nodes in contact, and the largest patch, of a corner. */
      unsigned int largest_active = 0, largest_patch = 0;
    };

    /** The work of the last blend() or force() call. */
    const Work &
    last_work() const noexcept
    {
      return work;
    }

    /** The most active-set iterations one call may take. */
    static constexpr unsigned int max_iterations = 12;

    /** tau of the blend's confidence: a corner whose force at the HIP is
     * 60 % of its state's keeps half its weight, at 20 % a fifth
     * (doc/benchmarks/contact-patch.md: 0.2-0.4 alike on the liver, 0.4
     * best on the beam). */
    static constexpr double confidence_scale = 0.4;

    /**
     * How far (in any component) the sphere's normal at a node in contact
     * may turn before the factors of W on the active set are made again
     * along the new normals.
     *
     * Each step solves the contact problem with the forces along the
     * normals at the nodes' current positions, from their gaps with the
     * forces taken off, and W along those same normals: the Picard
     * iteration on the directions, which converges where the model's
     * equilibrium is stable. W along the state's normals instead, kept
     * while the active set stays, leaves the nodes' sliding round the
     * sphere unbalanced, and that step diverges where the sphere presses
     * deep (doc/benchmarks/contact-patch.md measures both).
     */
    static constexpr double direction_tolerance = 1e-8;

    /** The range a corner's stiffening ratio r_kj is clamped to (blend()):
     * a model far from its state, or on another branch, corrects no more
     * than by half. */
    static constexpr double largest_ratio = 1.5;

    /** Forces below this (N) are compared by their difference, not their
     * ratio: the force a hand tells apart from none, the floor of the
     * benchmark's error measure. */
    static constexpr double force_floor = 0.05;

  private:
    /** A patch's warm start: its last forces and active set, and the LU
     * factors of W on that set. */
    struct Slot
    {
      const ContactPatch *patch = nullptr;
      std::uint64_t       id    = 0;
      std::uint64_t       used  = 0;
      std::vector<double> lambda;
      // The nodes' positions under those forces (3 per node).
      std::vector<double> y;
      // The sphere's normals at the nodes of the active set when it was
      // factorised (3 per node): the directions its W is along.
      std::vector<double> direction;
      // H's 3 x 3 blocks between the nodes it has seen in contact, side by
      // side (block_capacity^2 blocks of 9): block_pos[i] is node i's row
      // and column (-1: none), block_nodes the nodes in them.
      std::vector<float>        block;
      std::vector<unsigned int> block_nodes;
      std::vector<int>          block_pos;
      unsigned int              n_block = 0;
      std::vector<char>         active;
      // The active set the factors are of (valid if factored).
      std::vector<unsigned int> index;
      std::vector<double>       LU;
      std::vector<unsigned int> pivot;
      unsigned int              n_active = 0;
      bool                      factored = false;
      // Whether LU holds a Cholesky factor (else LU with pivot).
      bool cholesky = false;
    };

    /** blend(), for corner @p c: prod_{j != c} r_cj^{w_j}, its model's
     * stiffening ratios at the other corners of weight w_j (1 where its
     * patch has no table). */
    static double
    stiffening_ratio(const std::array<const ContactPatch *, 8> &corners,
                     const std::array<double, 8>               &weights,
                     const unsigned int                         c) noexcept;

    /** force() without resetting the work counted (blend() sums its
     * corners'). */
    bool
    corner_force(const ContactPatch      &patch,
                 const Utilities::Point3 &x,
                 Utilities::Point3       &force,
                 std::array<double, 9>   *stiffness) noexcept;

    /** The slot of @p patch (its warm start), or the least recently used
     * one, reset. */
    Slot &
    slot_of(const ContactPatch &patch) noexcept;

    /** W on the @p m nodes of s.index along the sphere's normals at them
     * (stored in s.direction), nu_a^T H_ab nu_b, into s.LU. */
    void
    assemble_active_block(const ContactPatch &patch,
                          Slot               &s,
                          const unsigned int  m) noexcept;

    /** Whether H's blocks on the @p m nodes of s.index are in s.block
     * (added if not; false if more than block_capacity). */
    bool
    keep_blocks(const ContactPatch &patch,
                Slot               &s,
                const unsigned int  m) noexcept;

    /** Empty s.block. */
    static void
    forget_blocks(Slot &s) noexcept;

    /** Node @p i's gap along its direction in @p s with every force taken
     * off: its gap less its move from x_free. */
    double
    free_gap(const ContactPatch &patch,
             const Slot         &s,
             const unsigned int  i) const noexcept;

    /** Solve W_AA x = b in place with the factors of @p s. */
    void
    solve_active(const Slot &s, double *b) const noexcept;

    /** Factorise W on the active set of @p s (into s.index, s.LU); false
     * if it is singular or larger than the work space. */
    bool
    factorize_active(const ContactPatch &patch, Slot &s) noexcept;

    /** force(), a step: the gaps q of @p patch's nodes (their positions in
     * @p s) to the sphere at the HIP @p x, the directions u to them (not
     * yet normalised) and the @p n_loaded nodes that carry a force; true
     * if any gap is closed. */
    bool
    measure_gaps(const ContactPatch      &patch,
                 const Utilities::Point3 &x,
                 const Slot              &s,
                 unsigned int            &n_loaded) noexcept;

    /** force(), a step: the contact problem W lambda + q >= 0 solved by
     * the primal-dual active set, warm-started from @p s; true if the set
     * settled within max_iterations. */
    bool
    solve_contact(const ContactPatch &patch,
                  Slot               &s,
                  const unsigned int  n_loaded) noexcept;

    /** force(), a step: the nodes' forces summed into @p force, and the
     * nodes of @p s moved by them for the next tick (y = x_free + H f). */
    void
    apply_forces(const ContactPatch &patch,
                 Slot               &s,
                 Utilities::Point3  &force) noexcept;

    /** force(), a step: the normal forces' growth as the gaps close,
     * U_A^T W_AA^-1 U_A on the settled active set of @p s, added to
     * @p stiffness. */
    void
    add_stiffness(const Slot &s, std::array<double, 9> &stiffness) noexcept;

    unsigned int                       max_nodes, max_active;
    std::vector<Slot>                  slots;
    std::uint64_t                      clock = 0;
    Work                               work;
    std::vector<double>                q, gap, w, rhs, rho;
    std::vector<std::array<double, 3>> u;
    std::vector<unsigned int>          loaded;
    // The nodes that left the active set in this step (solve_contact()).
    std::vector<char> left;
    // The most nodes whose blocks of H a slot keeps side by side.
    unsigned int block_capacity;
  };

  /**
   * The magnitude of @p patch's model force at each of the 14 grid points
   * around its state, @p spacing apart, that share a tetrahedron of the
   * grid with it (steps all up or all down; -1 at the other 12), and at
   * its own, into patch.neighbour_force (with patch.spacing): the model
   * solved by
   * following the sphere from the state to each in steps of at most
   * 0.25 mm, as a hand would move it (a model met far from its state can
   * settle on another branch: nodes on the far side of the sphere), then
   * until it settles. What PatchContact::blend() corrects each corner's
   * model by. Allocates; for the solver that makes the patch.
   */
  void
  tabulate_neighbours(ContactPatch &patch, const double spacing);
} // namespace palpate

#endif
