// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

#ifndef palpate_state_space_state_cache_h
#define palpate_state_space_state_cache_h

#include <palpate/base/utilities.h>
#include <palpate/hyperelastic/state.h>
#include <palpate/state_space/state_grid.h>

#include <array>
#include <atomic>
#include <cstdint>
#include <memory>
#include <mutex>
#include <vector>

namespace palpate
{
  struct ContactPatch;
  struct State;

  /** What the cache knows about a grid point. */
  enum class PointStatus : std::uint8_t
  {
    /** Not computed (or computed for parameters that changed since). */
    missing = 0,
    /** Computed: its force can be interpolated. */
    available = 1,
    /** A failure point: no equilibrium was found; never interpolated. */
    failed = 2
  };

  /**
   * The computed states of the state grid.
   *
   * Two kinds of readers, two mechanisms:
   * - The real-time side reads only forces, through read_force(): a
   *   sequence lock per grid point, so it never waits, never allocates and
   *   never sees a half-written force; a read that races with a write
   *   reports the point as missing for that tick.
   * - The engine (sources of new computations) and the shape interpolator
   *   read whole states, through state(), under a mutex.
   *
   * Whole states are kept within a memory budget: when it is exceeded, the
   * states farthest from the focus (the HIP) are dropped; their forces stay.
   *
   * invalidate() starts a new generation: every point is missing again, and
   * results that arrive for an older generation are discarded, so no stale
   * state is ever interpolated after the parameters change.
   */
  class StateCache
  {
  public:
    /** A cache for @p grid holding at most @p memory_budget bytes of states. */
    StateCache(const StateGrid &grid, const std::size_t memory_budget);

    ~StateCache();

    /** The current generation (starts at 1). */
    std::uint64_t
    generation() const noexcept;

    /** Start a new generation: every point missing, all states dropped. */
    void
    invalidate();

    /**
     * Store a converged state for @p point, computed for @p generation; it
     * is discarded if the generation has changed since.
     */
    void
    publish(const unsigned int           point,
            std::shared_ptr<const State> state,
            const std::uint64_t          generation);

    /**
     * Make @p point available with force @p force (N) only, for
     * @p generation: its whole state is held elsewhere (a solver server of
     * the MPI engine) and travels here only when state() asks for it. Its
     * contact @p patch, if given, is held here for the haptic loop and
     * counts in the memory budget; beyond it, the patches farthest from
     * the focus are let go of (their forces stay).
     */
    void
    publish_force(const unsigned int                  point,
                  const Utilities::Point3            &force,
                  const std::uint64_t                 generation,
                  const std::array<double, 9>        *stiffness = nullptr,
                  std::shared_ptr<const ContactPatch> patch     = nullptr);

    /**
     * The available points whose whole state was asked for by state() but
     * is not held here, since the last call (each once). An engine that
     * holds states elsewhere fetches them and publish()es them (lazy state
     * transfer); the caller of state() asks again later.
     */
    std::vector<unsigned int>
    take_wanted();

    /** Record @p point as a failure point (for @p generation), and why no
     * equilibrium was found there. */
    void
    publish_failure(const unsigned int  point,
                    const std::uint64_t generation,
                    const SolveStatus   reason = SolveStatus::max_iterations);

    /** Why the failure point @p point failed (for the state store). */
    SolveStatus
    failure_reason(const unsigned int point) const;

    /** What is known about @p point in the current generation. Lock-free
     * unless a writer is preempted mid-write; not for the real-time side. */
    PointStatus
    status(const unsigned int point) const noexcept;

    /** The whole state at @p point, or null if missing, failed or not held
     * here (an available point that is not held is remembered as wanted,
     * see take_wanted()). */
    std::shared_ptr<const State>
    state(const unsigned int point) const;

    /** Whether the whole state at @p point is held (usable as a source).
     * Lock-free; state() may still return null if it was dropped since. */
    bool
    has_state(const unsigned int point) const;

    /** The point states are kept near when the budget is tight (m). */
    void
    set_focus(const Utilities::Point3 &hip);

    /**
     * Real-time read of the force at @p point (N): true and @p force set if
     * the point is available in generation @p generation (read once per
     * interpolation with generation(), so that the corners of one cell never
     * mix generations), false otherwise. Never blocks, never allocates.
     */
    bool
    read_force(const unsigned int  point,
               const std::uint64_t generation,
               Utilities::Point3  &force) const noexcept;

    /**
     * Real-time read of the force and the active-node stiffness at
     * @p point, as read_force(); @p has_stiffness says whether the state
     * came with its stiffness (@p stiffness is valid only then).
     */
    bool
    read_force_and_stiffness(const unsigned int     point,
                             const std::uint64_t    generation,
                             Utilities::Point3     &force,
                             std::array<double, 9> &stiffness,
                             bool &has_stiffness) const noexcept;

    /**
     * The cross derivatives of the force at @p point, for tricubic Hermite
     * interpolation: d2f_i/dxdy, d2f_i/dxdz, d2f_i/dydz (N/m^2) and
     * d3f_i/dxdydz (N/m^3) as cross[4 i + m], estimated from the
     * neighbours' stiffnesses (see update_cross()). The writer keeps them
     * current as neighbours arrive, behind a sequence lock of their own (so
     * that updating them never hides the point's force); a read that races
     * with an update is retried a few times. Real-time safe. False if no
     * consistent read was had.
     */
    bool
    read_cross_derivatives(const unsigned int      point,
                           std::array<double, 12> &cross) const noexcept;

    /**
     * Real-time reads of contact patches (State space / Interpolation =
     * contact patch): between begin_patch_reads() and end_patch_reads(),
     * read_patch() gives the patch of @p point if it is available in
     * @p generation (else null), and the patch stays valid until
     * end_patch_reads() even if the point is republished or the cache
     * invalidated meanwhile: a patch the cache lets go of is freed by a
     * later writer once no read section can hold it (read-copy-update).
     * One reading thread at a time. Never block, never allocate.
     */
    void
    begin_patch_reads() const noexcept;
    const ContactPatch *
    read_patch(const unsigned int  point,
               const std::uint64_t generation) const noexcept;
    void
    end_patch_reads() const noexcept;

    /** The contact patch the cache holds for @p point in this generation
     * (a state's or an MPI result's), or null. Not real-time: takes the
     * lock. */
    std::shared_ptr<const ContactPatch>
    patch(const unsigned int point) const;

    /** Number of available and of failed points in this generation. */
    std::pair<unsigned int, unsigned int>
    counts() const;

    /** Number of whole states held, and their size in bytes. */
    std::pair<unsigned int, std::size_t>
    memory() const;

    /** Number of states dropped to respect the budget. */
    unsigned int
    n_evicted() const;

    /** Whether the whole state at @p point was dropped to respect the
     * budget (and not published again since): an engine that held it only
     * here cannot give it back. */
    bool
    dropped(const unsigned int point) const;

    /** Record that the whole state at @p point, held elsewhere (an MPI
     * server), was dropped there: unless it is held here, dropped(). */
    void
    mark_dropped(const unsigned int point);

  private:
    struct Entry;
    struct HeldPatch;

    /** Let go of the patch of @p point (mutex held): freed by
     * reclaim_patches() once no read section can hold it. */
    void
    retire_patch(const unsigned int point);

    /** Free the patches let go of that no read section can hold (mutex
     * held). */
    void
    reclaim_patches();

    /**
     * Recompute the cross derivatives of @p point (if it is available with
     * a stiffness) from its neighbours' stiffnesses in the current
     * generation: mixed second derivatives d/db (df/da) = -dK_ia/db by
     * central differences along b (one-sided where one neighbour is
     * missing, zero where both are), averaged with d/da (df/db); the third
     * by mixed central differences of -K_ia over the four diagonal
     * neighbours in the other two axes, averaged over a (zero where none
     * is complete). Each value depends on the point and what is known
     * around it only, so every cell that shares a corner sees the same
     * value: the interpolant stays C1. Called by the writer (mutex held).
     */
    void
    update_cross(const unsigned int point);

    /** update_cross() for @p point and its 26 neighbours. */
    void
    update_cross_around(const unsigned int point);

    const StateGrid                          &grid;
    std::unique_ptr<Entry[]>                  entries;
    std::atomic<std::uint64_t>                current_generation;
    mutable std::mutex                        mutex;
    std::vector<std::shared_ptr<const State>> states;
    // Available points asked for by state() but not held (mutable: asking
    // is a read), and whether each is already in the list.
    mutable std::vector<unsigned int> wanted;
    mutable std::vector<std::uint8_t> is_wanted;
    std::vector<SolveStatus>          reasons; // of failure points
    std::size_t                       bytes = 0, budget;
    // Patches of points whose state is held elsewhere (publish_force()):
    // each one's bytes, and their sum.
    std::vector<std::size_t> remote_patch;
    std::size_t              remote_bytes = 0;
    unsigned int             held = 0, evicted = 0;
    Utilities::Point3        focus = {{0, 0, 0}};
    // Patches let go of, with the read sections ended when they were.
    std::vector<std::pair<const HeldPatch *, std::uint64_t>> retired;
    mutable std::atomic<bool>          reader_active{false};
    mutable std::atomic<std::uint64_t> reader_sections{0};
  };
} // namespace palpate

#endif
