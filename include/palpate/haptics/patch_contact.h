// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

#ifndef palpate_haptics_patch_contact_h
#define palpate_haptics_patch_contact_h

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
   * of the HIP's tetrahedron in its cell (weights()).
   *
   * The model is non-linear in the directions of the forces (they follow
   * the sphere's normals at the moved nodes), so each tick takes one step
   * of a fixed-point iteration from the patch's last solution: the
   * contact problem on W (the patch's compliance along its state's
   * normals) for the gaps at the nodes' current positions, then the nodes
   * moved by the new forces. The sphere moves microns per tick, so the
   * iteration follows the hand and converges where it rests. The contact
   * problem is solved by the primal-dual active-set method, warm started
   * from the last tick; while the set of nodes in contact stays, its LU
   * factors are kept and a tick costs triangular solves, the gaps and the
   * nodes' move. At most max_iterations active-set iterations per tick: a
   * problem not settled by then gives the iterate's non-negative forces,
   * and the next tick goes on from it.
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
     * Each corner's model is a linearisation about its state, and one
     * direction of it is poor: from a state pressed deeper than the
     * contact at x. Its free surface x - H f_s, the state's forces taken
     * off with the tangent compliance, is not the tissue's rest surface
     * but nearer the sphere (doc/benchmarks/contact-patch.md measures it),
     * so its model touches early at a shallow HIP; a corner pressed
     * less, or not at all, has a free surface near the rest surface and
     * the contact's geometry exact. The blend therefore weights each corner
     * by @p weights w_k (weights(); a corner of weight 0 is not solved)
     * times a confidence
     * c_k = 1 / (1 + (d_k / tau)^2), d_k = max(0, |F_k| - |F_k(x)|) /
     * (|F_k| + force_floor), with F_k the state's force, and normalises:
     *
     *   F(x) = sum_k w_k c_k F_k(x) / sum_k w_k c_k.
     *
     * At a grid point w is 1 for its corner (the state's force); the c_k are
     * continuous and positive, so F is continuous; it is zero where every
     * F_k is.
     */
    bool
    blend(const std::array<const ContactPatch *, 8> &corners,
          const std::array<double, 8>               &weights,
          const Utilities::Point3                   &x,
          Utilities::Point3                         &force,
          std::array<double, 9> *stiffness = nullptr) noexcept;

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

    /**
     * The corners' weights blend() is given for the HIP at local
     * coordinates @p local in its cell: those of the tetrahedron of the
     * cell's Kuhn triangulation that holds it (simplex_weights()), so that
     * a tick solves the contact of 4 corners, not 8. Measured against the
     * trilinear weights of all 8 (doc/benchmarks/contact-patch.md): the
     * same accuracy against direct solves, half the work.
     */
    static std::array<double, 8>
    weights(const std::array<double, 3> &local) noexcept;

    /** The most active-set iterations one call may take. */
    static constexpr unsigned int max_iterations = 12;

    /** tau of the blend's confidence: a corner whose force at the HIP is
     * 60 % of its state's keeps half its weight, at 20 % a fifth
     * (doc/benchmarks/contact-patch.md: 0.2-0.4 alike on the liver, 0.4
     * best on the beam). */
    static constexpr double confidence_scale = 0.4;

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
      std::vector<char>   active;
      // The active set the factors are of (valid if factored).
      std::vector<unsigned int> index;
      std::vector<double>       LU;
      std::vector<unsigned int> pivot;
      unsigned int              n_active = 0;
      bool                      factored = false;
      // Whether LU holds a Cholesky factor (else LU with pivot).
      bool cholesky = false;
    };

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
    std::vector<double>                q, w, rhs, rho;
    std::vector<std::array<double, 3>> u;
    std::vector<unsigned int>          loaded;
  };
} // namespace palpate

#endif
