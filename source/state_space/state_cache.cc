// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

#include <palpate/hyperelastic/contact_patch.h>
#include <palpate/hyperelastic/state.h>
#include <palpate/state_space/state_cache.h>

#include <algorithm>

namespace palpate
{
  /**
   * One grid point as the real-time side sees it, behind a sequence lock:
   * the writer makes the sequence odd, writes, and makes it even again; a
   * reader that sees an odd or changed sequence discards what it read. All
   * fields are atomics (relaxed inside the lock), so there is no data race
   * in the C++ sense either.
   */
  struct StateCache::Entry
  {
    std::atomic<std::uint32_t> sequence{0};
    std::atomic<std::uint64_t> generation{0};
    std::atomic<std::uint8_t>  status{0};
    std::atomic<double>        force[3]     = {};
    std::atomic<double>        stiffness[9] = {};
    std::atomic<bool>          has_stiffness{false};
    /** The cross derivatives (Hermite), behind their own sequence lock. */
    std::atomic<std::uint32_t> cross_sequence{0};
    std::atomic<double>        cross[12] = {};
    /** Whether the whole state is held (written under the mutex). */
    std::atomic<bool> held{false};
    /** Whether it was dropped for the budget (written under the mutex). */
    std::atomic<bool> dropped{false};
    /** Its contact patch (written under the mutex, read by the real-time
     * side between begin_patch_reads() and end_patch_reads()). */
    std::atomic<const HeldPatch *> patch{nullptr};
  };

  /** A contact patch as the cache holds it: with the generation it was
   * computed for. Freed only when no real-time read can hold it. */
  struct StateCache::HeldPatch
  {
    std::shared_ptr<const ContactPatch> patch;
    std::uint64_t                       generation;
  };

  static_assert(std::atomic<double>::is_always_lock_free &&
                  std::atomic<std::uint64_t>::is_always_lock_free,
                "the real-time reads need lock-free atomics");



  namespace
  {
    /** A state's bytes, its contact patch's included: a patch's dense
     * compliance outweighs the solution many times (doc/benchmarks/
     * contact-patch.md), so a budget of solutions alone would not bound
     * the cache. */
    std::size_t
    size_of(const State &s)
    {
      return sizeof(State) + s.solution.size() * sizeof(double) +
             s.multipliers.size() * sizeof(double) +
             (s.contact_patch ? s.contact_patch->memory() : 0);
    }
    /**
     * What the real-time side reads of a point, written behind its
     * sequence lock (the caller holds the cache's mutex, so there is one
     * writer): odd sequence, the fields, even sequence.
     */
    template <typename Entry>
    void
    write_entry(Entry                       &e,
                const Utilities::Point3     &force,
                const std::array<double, 9> *stiffness,
                const PointStatus            status,
                const std::uint64_t          generation)
    {
      const std::uint32_t s = e.sequence.load(std::memory_order_relaxed);
      e.sequence.store(s + 1, std::memory_order_relaxed);
      std::atomic_thread_fence(std::memory_order_release);
      for (unsigned int d = 0; d < 3; ++d)
        e.force[d].store(force[d], std::memory_order_relaxed);
      if (stiffness != nullptr)
        for (unsigned int d = 0; d < 9; ++d)
          e.stiffness[d].store((*stiffness)[d], std::memory_order_relaxed);
      e.has_stiffness.store(stiffness != nullptr, std::memory_order_relaxed);
      e.status.store(static_cast<std::uint8_t>(status),
                     std::memory_order_relaxed);
      e.generation.store(generation, std::memory_order_relaxed);
      e.sequence.store(s + 2, std::memory_order_release);
    }

    /** Make a point available with @p force unless it already is in this
     * generation: rewriting the same value would only make a concurrent
     * real-time read miss it. */
    template <typename Entry>
    void
    make_available(Entry                       &e,
                   const Utilities::Point3     &force,
                   const std::array<double, 9> *stiffness,
                   const std::uint64_t          generation)
    {
      if (e.generation.load(std::memory_order_relaxed) == generation &&
          e.status.load(std::memory_order_relaxed) ==
            static_cast<std::uint8_t>(PointStatus::available) &&
          (stiffness == nullptr ||
           e.has_stiffness.load(std::memory_order_relaxed)))
        return;
      write_entry(e, force, stiffness, PointStatus::available, generation);
    }

    /**
     * The real-time read of a point behind its sequence lock: its force
     * and, if @p stiffness is given, its stiffness; false if the point is
     * not available in @p generation_read or a write raced with the read.
     */
    template <typename Entry>
    bool
    read_entry(const Entry           &e,
               const std::uint64_t    generation_read,
               Utilities::Point3     &force,
               std::array<double, 9> *stiffness,
               bool                  *has_stiffness) noexcept
    {
      const std::uint32_t s1 = e.sequence.load(std::memory_order_acquire);
      if (s1 & 1)
        return false;
      const auto status     = e.status.load(std::memory_order_relaxed);
      const auto generation = e.generation.load(std::memory_order_relaxed);
      Utilities::Point3     f;
      std::array<double, 9> k;
      bool                  has = false;
      for (unsigned int d = 0; d < 3; ++d)
        f[d] = e.force[d].load(std::memory_order_relaxed);
      if (stiffness != nullptr)
        {
          has = e.has_stiffness.load(std::memory_order_relaxed);
          for (unsigned int d = 0; d < 9; ++d)
            k[d] = e.stiffness[d].load(std::memory_order_relaxed);
        }
      std::atomic_thread_fence(std::memory_order_acquire);
      if (e.sequence.load(std::memory_order_relaxed) != s1 ||
          generation != generation_read ||
          status != static_cast<std::uint8_t>(PointStatus::available))
        return false;
      force = f;
      if (stiffness != nullptr)
        {
          *stiffness     = k;
          *has_stiffness = has;
        }
      return true;
    }
  } // namespace



  StateCache::StateCache(const StateGrid &grid, const std::size_t memory_budget)
    : grid(grid)
    , entries(new Entry[grid.size()])
    , current_generation(1)
    , states(grid.size())
    , is_wanted(grid.size(), 0)
    , reasons(grid.size(), SolveStatus::max_iterations)
    , budget(memory_budget)
    , remote_patch(grid.size(), 0)
  {}



  StateCache::~StateCache()
  {
    for (unsigned int p = 0; p < grid.size(); ++p)
      delete entries[p].patch.load();
    for (const auto &r : retired)
      delete r.first;
  }



  void
  StateCache::retire_patch(const unsigned int point)
  {
    // The caller holds the mutex. The reader that may still use the old
    // patch is at most the read section in progress now: it is freed once that
    // section ended (or none is in progress).
    const HeldPatch *old = entries[point].patch.exchange(nullptr);
    if (old)
      retired.emplace_back(old, reader_sections.load());
  }



  void
  StateCache::reclaim_patches()
  {
    const bool          reading  = reader_active.load();
    const std::uint64_t sections = reader_sections.load();
    auto                end =
      std::remove_if(retired.begin(), retired.end(), [&](const auto &r) {
        if (reading && sections <= r.second)
          return false;
        delete r.first;
        return true;
      });
    retired.erase(end, retired.end());
  }



  void
  StateCache::begin_patch_reads() const noexcept
  {
    reader_active.store(true);
  }



  void
  StateCache::end_patch_reads() const noexcept
  {
    reader_sections.fetch_add(1);
    reader_active.store(false);
  }



  const ContactPatch *
  StateCache::read_patch(const unsigned int  point,
                         const std::uint64_t generation) const noexcept
  {
    const HeldPatch *held = entries[point].patch.load();
    return held && held->generation == generation ? held->patch.get() : nullptr;
  }



  std::shared_ptr<const ContactPatch>
  StateCache::patch(const unsigned int point) const
  {
    // Under the lock no writer retires the entry's patch, so the held one
    // is alive while its pointer is copied.
    std::lock_guard<std::mutex> lock(mutex);
    const HeldPatch            *held = entries[point].patch.load();
    return held && held->generation ==
                     current_generation.load(std::memory_order_acquire) ?
             held->patch :
             nullptr;
  }



  std::uint64_t
  StateCache::generation() const noexcept
  {
    return current_generation.load(std::memory_order_acquire);
  }



  void
  StateCache::invalidate()
  {
    std::lock_guard<std::mutex> lock(mutex);
    current_generation.fetch_add(1, std::memory_order_acq_rel);
    for (unsigned int p = 0; p < states.size(); ++p)
      {
        retire_patch(p);
        states[p].reset();
        entries[p].held.store(false, std::memory_order_relaxed);
        entries[p].dropped.store(false, std::memory_order_relaxed);
      }
    bytes = 0;
    held  = 0;
    std::fill(remote_patch.begin(), remote_patch.end(), 0);
    remote_bytes = 0;
    for (const unsigned int p : wanted)
      is_wanted[p] = 0;
    wanted.clear();
    reclaim_patches();
  }



  void
  StateCache::publish_force(const unsigned int                  point,
                            const Utilities::Point3            &force,
                            const std::uint64_t                 generation,
                            const std::array<double, 9>        *stiffness,
                            std::shared_ptr<const ContactPatch> patch)
  {
    std::lock_guard<std::mutex> lock(mutex);
    if (generation != current_generation.load(std::memory_order_acquire))
      return;
    if (patch)
      {
        // The patch first: a real-time read that finds the point
        // available finds its patch too.
        retire_patch(point);
        remote_bytes -= remote_patch[point];
        remote_patch[point] = patch->memory();
        remote_bytes += remote_patch[point];
        entries[point].patch.store(new HeldPatch{std::move(patch), generation});
      }
    reclaim_patches();
    make_available(entries[point], force, stiffness, generation);
    if (stiffness != nullptr)
      update_cross_around(point);

    // Over budget: let go of the patches farthest from the focus (cells
    // with those corners render trilinearly until they come again).
    if (bytes + remote_bytes > budget)
      {
        std::vector<std::pair<double, unsigned int>> by_distance;
        for (unsigned int p = 0; p < remote_patch.size(); ++p)
          if (remote_patch[p] > 0 && p != point)
            by_distance.emplace_back(Utilities::distance(grid.position(p),
                                                         focus),
                                     p);
        std::sort(by_distance.begin(), by_distance.end());
        while (bytes + remote_bytes > 0.9 * budget && !by_distance.empty())
          {
            const unsigned int p = by_distance.back().second;
            by_distance.pop_back();
            retire_patch(p);
            remote_bytes -= remote_patch[p];
            remote_patch[p] = 0;
          }
      }
  }



  std::vector<unsigned int>
  StateCache::take_wanted()
  {
    std::lock_guard<std::mutex> lock(mutex);
    std::vector<unsigned int>   taken;
    taken.swap(wanted);
    for (const unsigned int p : taken)
      is_wanted[p] = 0;
    return taken;
  }



  void
  StateCache::publish(const unsigned int           point,
                      std::shared_ptr<const State> state,
                      const std::uint64_t          generation)
  {
    std::lock_guard<std::mutex> lock(mutex);
    if (generation != current_generation.load(std::memory_order_acquire))
      return; // computed for parameters that no longer hold
    Entry &e = entries[point];
    // The patch first: a real-time read that finds the point available
    // finds its patch too.
    if (state->contact_patch)
      {
        retire_patch(point);
        // Counted with the state held here from now on.
        remote_bytes -= remote_patch[point];
        remote_patch[point] = 0;
        e.patch.store(new HeldPatch{state->contact_patch, generation});
      }
    reclaim_patches();
    // A point that is already available (a state recomputed because its
    // whole state had been dropped, or fetched from an MPI server whose
    // force arrived first) keeps its force.
    make_available(e,
                   state->force,
                   state->has_stiffness ? &state->stiffness : nullptr,
                   generation);
    if (state->has_stiffness)
      update_cross_around(point);

    if (!states[point])
      ++held;
    else
      bytes -= size_of(*states[point]);
    bytes += size_of(*state);
    states[point] = std::move(state);
    e.held.store(true, std::memory_order_release);
    e.dropped.store(false, std::memory_order_relaxed);

    // Over budget: drop the states farthest from the focus (their forces
    // stay available to the real-time side), down to 90 % of the budget so
    // that the sort is paid once per batch, not once per state.
    if (bytes > budget && held > 1)
      {
        std::vector<std::pair<double, unsigned int>> by_distance;
        by_distance.reserve(held);
        for (unsigned int p = 0; p < states.size(); ++p)
          if (states[p] && p != point)
            by_distance.emplace_back(Utilities::distance(grid.position(p),
                                                         focus),
                                     p);
        std::sort(by_distance.begin(), by_distance.end());
        while (bytes > 0.9 * budget && !by_distance.empty())
          {
            const unsigned int p = by_distance.back().second;
            by_distance.pop_back();
            bytes -= size_of(*states[p]);
            // The patch goes with its state (the budget counts it): the
            // point's force stays, and cells with this corner render
            // trilinearly until it is published again.
            retire_patch(p);
            states[p].reset();
            entries[p].held.store(false, std::memory_order_release);
            entries[p].dropped.store(true, std::memory_order_relaxed);
            --held;
            ++evicted;
          }
      }
  }



  void
  StateCache::publish_failure(const unsigned int  point,
                              const std::uint64_t generation,
                              const SolveStatus   reason)
  {
    std::lock_guard<std::mutex> lock(mutex);
    if (generation != current_generation.load(std::memory_order_acquire))
      return;
    reasons[point] = reason;
    write_entry(
      entries[point], {{0, 0, 0}}, nullptr, PointStatus::failed, generation);
  }



  SolveStatus
  StateCache::failure_reason(const unsigned int point) const
  {
    std::lock_guard<std::mutex> lock(mutex);
    return reasons[point];
  }



  void
  StateCache::update_cross(const unsigned int point)
  {
    const std::uint64_t generation =
      current_generation.load(std::memory_order_relaxed);
    const GridIndex g = grid.index(point);
    // Whether the point at offset d has a stiffness (the caller holds the
    // mutex: the only writer, so relaxed loads are consistent), and its
    // stiffness.
    const auto has = [&](const GridIndex &d) {
      const GridIndex q = {{g[0] + d[0], g[1] + d[1], g[2] + d[2]}};
      if (!grid.contains(q))
        return false;
      const Entry &e = entries[grid.linear(q)];
      return e.generation.load(std::memory_order_relaxed) == generation &&
             e.status.load(std::memory_order_relaxed) ==
               static_cast<std::uint8_t>(PointStatus::available) &&
             e.has_stiffness.load(std::memory_order_relaxed);
    };
    const auto K =
      [&](const GridIndex &d, const unsigned int i, const unsigned int j) {
        const GridIndex q = {{g[0] + d[0], g[1] + d[1], g[2] + d[2]}};
        return entries[grid.linear(q)].stiffness[3 * i + j].load(
          std::memory_order_relaxed);
      };
    const GridIndex here = {{0, 0, 0}};
    if (!has(here))
      return;
    const double           h = grid.spacing();
    std::array<double, 12> cross;
    for (unsigned int i = 0; i < 3; ++i)
      {
        // d2f_i/(da db) for (a, b) = (x, y), (x, z), (y, z).
        unsigned int slot = 0;
        for (unsigned int a = 0; a < 3; ++a)
          for (unsigned int b = a + 1; b < 3; ++b, ++slot)
            {
              double       sum = 0;
              unsigned int n   = 0;
              for (const auto &[along, of] :
                   {std::pair<unsigned int, unsigned int>(b, a), {a, b}})
                {
                  GridIndex up = {{0, 0, 0}}, down = {{0, 0, 0}};
                  up[along]           = 1;
                  down[along]         = -1;
                  const bool has_up   = has(up);
                  const bool has_down = has(down);
                  // d/d(along) of df_i/d(of) = -K_i,of.
                  if (has_up && has_down)
                    sum += (K(down, i, of) - K(up, i, of)) / (2 * h);
                  else if (has_up)
                    sum += (K(here, i, of) - K(up, i, of)) / h;
                  else if (has_down)
                    sum += (K(down, i, of) - K(here, i, of)) / h;
                  n += has_up || has_down;
                }
              cross[4 * i + slot] = n > 0 ? sum / n : 0;
            }
        // d3f_i/dxdydz.
        double       sum = 0;
        unsigned int n   = 0;
        for (unsigned int a = 0; a < 3; ++a)
          {
            const unsigned int e1 = (a + 1) % 3, e2 = (a + 2) % 3;
            double             mixed = 0;
            bool               all   = true;
            for (const int s1 : {-1, 1})
              for (const int s2 : {-1, 1})
                {
                  GridIndex d = {{0, 0, 0}};
                  d[e1]       = s1;
                  d[e2]       = s2;
                  all         = all && has(d);
                  if (all)
                    mixed += s1 * s2 * K(d, i, a);
                }
            if (all)
              {
                sum += -mixed / (4 * h * h);
                ++n;
              }
          }
        cross[4 * i + 3] = n > 0 ? sum / n : 0;
      }
    Entry              &e = entries[point];
    const std::uint32_t s = e.cross_sequence.load(std::memory_order_relaxed);
    e.cross_sequence.store(s + 1, std::memory_order_relaxed);
    std::atomic_thread_fence(std::memory_order_release);
    for (unsigned int k = 0; k < 12; ++k)
      e.cross[k].store(cross[k], std::memory_order_relaxed);
    e.cross_sequence.store(s + 2, std::memory_order_release);
  }



  void
  StateCache::update_cross_around(const unsigned int point)
  {
    for (const unsigned int q : grid.neighbourhood(point))
      update_cross(q);
  }



  bool
  StateCache::read_cross_derivatives(
    const unsigned int      point,
    std::array<double, 12> &cross) const noexcept
  {
    const Entry &e = entries[point];
    for (unsigned int attempt = 0; attempt < 4; ++attempt)
      {
        const std::uint32_t s1 =
          e.cross_sequence.load(std::memory_order_acquire);
        if (s1 & 1)
          continue;
        for (unsigned int k = 0; k < 12; ++k)
          cross[k] = e.cross[k].load(std::memory_order_relaxed);
        std::atomic_thread_fence(std::memory_order_acquire);
        if (e.cross_sequence.load(std::memory_order_relaxed) == s1)
          return true;
      }
    return false;
  }



  PointStatus
  StateCache::status(const unsigned int point) const noexcept
  {
    const Entry &e = entries[point];
    for (unsigned int attempt = 0; attempt < 16; ++attempt)
      {
        const std::uint32_t s1 = e.sequence.load(std::memory_order_acquire);
        if (s1 & 1)
          continue;
        const auto status     = e.status.load(std::memory_order_relaxed);
        const auto generation = e.generation.load(std::memory_order_relaxed);
        std::atomic_thread_fence(std::memory_order_acquire);
        if (e.sequence.load(std::memory_order_relaxed) != s1)
          continue;
        return generation ==
                   current_generation.load(std::memory_order_acquire) ?
                 static_cast<PointStatus>(status) :
                 PointStatus::missing;
      }
    // A writer is slow (preempted mid-write): writers hold the mutex for
    // the whole write, so under it the entry is consistent.
    std::lock_guard<std::mutex> lock(mutex);
    return e.generation.load(std::memory_order_relaxed) ==
               current_generation.load(std::memory_order_relaxed) ?
             static_cast<PointStatus>(
               e.status.load(std::memory_order_relaxed)) :
             PointStatus::missing;
  }



  bool
  StateCache::read_force(const unsigned int  point,
                         const std::uint64_t generation_read,
                         Utilities::Point3  &force) const noexcept
  {
    return read_entry(entries[point], generation_read, force, nullptr, nullptr);
  }



  bool
  StateCache::read_force_and_stiffness(const unsigned int     point,
                                       const std::uint64_t    generation_read,
                                       Utilities::Point3     &force,
                                       std::array<double, 9> &stiffness,
                                       bool &has_stiffness) const noexcept
  {
    return read_entry(
      entries[point], generation_read, force, &stiffness, &has_stiffness);
  }



  std::shared_ptr<const State>
  StateCache::state(const unsigned int point) const
  {
    std::lock_guard<std::mutex> lock(mutex);
    if (!states[point] && !is_wanted[point])
      {
        const Entry &e = entries[point];
        if (e.generation.load(std::memory_order_relaxed) ==
              current_generation.load(std::memory_order_relaxed) &&
            e.status.load(std::memory_order_relaxed) ==
              static_cast<std::uint8_t>(PointStatus::available))
          {
            is_wanted[point] = 1;
            wanted.push_back(point);
          }
      }
    return states[point];
  }



  bool
  StateCache::has_state(const unsigned int point) const
  {
    return entries[point].held.load(std::memory_order_acquire);
  }



  bool
  StateCache::dropped(const unsigned int point) const
  {
    return entries[point].dropped.load(std::memory_order_relaxed);
  }



  void
  StateCache::mark_dropped(const unsigned int point)
  {
    std::lock_guard<std::mutex> lock(mutex);
    if (!states[point])
      entries[point].dropped.store(true, std::memory_order_relaxed);
  }



  void
  StateCache::set_focus(const Utilities::Point3 &hip)
  {
    std::lock_guard<std::mutex> lock(mutex);
    focus = hip;
  }



  std::pair<unsigned int, unsigned int>
  StateCache::counts() const
  {
    unsigned int available = 0, failed = 0;
    for (unsigned int p = 0; p < grid.size(); ++p)
      {
        const PointStatus s = status(p);
        available += s == PointStatus::available;
        failed += s == PointStatus::failed;
      }
    return {available, failed};
  }



  std::pair<unsigned int, std::size_t>
  StateCache::memory() const
  {
    std::lock_guard<std::mutex> lock(mutex);
    return {held, bytes};
  }



  unsigned int
  StateCache::n_evicted() const
  {
    std::lock_guard<std::mutex> lock(mutex);
    return evicted;
  }
} // namespace palpate
