// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

#ifndef palpate_haptics_interaction_impl_h
#define palpate_haptics_interaction_impl_h

// Not an interface: Interaction's implementation, shared by its source
// files, one job each:
//   interaction.cc             attaching and detaching, the force at each
//                              tick (the real-time path) and what the
//                              haptic side asks of the data
//   interaction_parameters.cc  the parameters changed while it runs
//   interaction_report.cc      what the interaction says of itself: the store,
//                              the events of missing data, the summary
// Users of the interaction include interaction.h, never this header.

#include <palpate/engine/engine.h>
#include <palpate/engine/hip_channel.h>
#include <palpate/haptics/force_interpolation.h>
#include <palpate/haptics/interaction.h>
#include <palpate/haptics/interpolation.h>
#include <palpate/hyperelastic/sphere_trial.h>
#include <palpate/hyperelastic/state.h>
#include <palpate/mesh/mesh.h>
#include <palpate/mesh/node_selection.h>
#include <palpate/scene/scene.h>
#include <palpate/state_space/state_cache.h>
#include <palpate/state_space/state_grid.h>
#include <palpate/state_space/state_store.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <chrono>
#include <cmath>
#include <condition_variable>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

namespace palpate
{
  struct Interaction::Impl
  {
    using Clock = std::chrono::steady_clock;

    explicit Impl(const Scene &s)
      : scene(s)
      , mesh(Mesh::create(scene))
      , nodes(select_nodes(scene, mesh))
      , grid(scene.parameters.state_space.grid_spacing,
             scene.parameters.state_space.extent)
      , cache(grid,
              static_cast<std::size_t>(scene.parameters.engine.memory_budget *
                                       1048576.0))
      , used(new std::atomic<std::uint8_t>[grid.size()])
      , filter(scene.parameters.haptics.force_limit,
               scene.parameters.haptics.max_force_change)
    {
      for (unsigned int p = 0; p < grid.size(); ++p)
        used[p].store(0, std::memory_order_relaxed);
      // The interpolation with the work space its ticks need (a contact
      // patch's: every surface node), so that the haptic thread never
      // allocates.
      interpolation       = Interpolation::create(scene, mesh, grid, cache);
      const double radius = scene.parameters.scheduler.cloud_radius;
      const int    reach =
        std::min<int>(grid.half_width(), std::floor(radius / grid.spacing()));
      for (int i = -reach; i <= reach; ++i)
        for (int j = -reach; j <= reach; ++j)
          for (int k = -reach; k <= reach; ++k)
            if (const GridIndex g{{i, j, k}};
                Utilities::norm(grid.position(g)) <= radius)
              cloud_points.push_back(grid.linear(g));
      check_memory_budget();
      // The store's states go into the cache before the engine starts, so
      // that it computes only what is missing.
      if (!scene.parameters.state_space.store.empty())
        {
          store = std::make_unique<StateStore>(
            scene.parameters.state_space.store,
            StoreFingerprint::of(scene, mesh, nodes));
          loaded = store->load(cache, grid);
        }
      engine =
        PrecomputationEngine::create(scene, mesh, nodes, grid, cache, hip);
    }

    /** Append the cache's new states to the store, every quarter second
     * while attached (a thread of its own, never the real-time one). */
    void
    write_store()
    {
      while (store_running.load())
        {
          append_to_store();
          std::unique_lock<std::mutex> lock(store_mutex);
          store_wake.wait_for(lock, std::chrono::milliseconds(250), [&] {
            return !store_running.load();
          });
        }
    }

    void
    append_to_store()
    {
      std::lock_guard<std::mutex> lock(store_append_mutex);
      try
        {
          store->append(cache, grid);
        }
      catch (const std::exception &e)
        {
          if (store_error.empty())
            store_error = e.what();
          store_write_failed = true;
        }
      // The store's own count: what it wrote and flushed, or after a
      // failed write (the disk full), what it read back.
      stored = store->appended();
    }

    /**
     * That the memory budget holds the initial cloud's whole states: if it
     * cannot, the cache drops states it needs as sources and computes them
     * again, without end.
     */
    void
    check_memory_budget() const
    {
      // At least the displacement of every node and the state's own size
      // (Mooney-Rivlin's pressures and quadratic elements add more).
      const double state_bytes = sizeof(State) + 3. * mesh.n_vertices() * 8;
      const double budget = scene.parameters.engine.memory_budget * 1048576.0;
      const double needed = 1.25 * cloud_points.size() * state_bytes;
      if (needed > budget)
        throw scene.error(
          "Engine/Memory budget",
          "the initial cloud's " + std::to_string(cloud_points.size()) +
            " states of this mesh (" + std::to_string(mesh.n_vertices()) +
            " nodes, at least " + Utilities::to_string(state_bytes / 1024, 3) +
            " KiB each) need at least " +
            Utilities::to_string(needed / 1048576, 3) +
            " MiB with room to move; beyond the budget the cache drops "
            "states it needs again and recomputes them without end",
          "raise Memory budget to " +
            Utilities::to_string(std::ceil(2 * needed / 1048576), 4) +
            " (MiB) or more, or make Scheduler / Cloud radius smaller.");
    }

    /** The grid points of the initial cloud. */
    std::vector<unsigned int>                    cloud_points;
    Scene                                        scene;
    Mesh                                         mesh;
    NodeSelection                                nodes;
    StateGrid                                    grid;
    StateCache                                   cache;
    HipChannel                                   hip;
    std::unique_ptr<PrecomputationEngine>        engine;
    std::unique_ptr<std::atomic<std::uint8_t>[]> used;

    // The state store (State space / Store) and its writer thread.
    std::unique_ptr<StateStore> store;
    StateStore::Loaded          loaded;
    std::thread                 store_writer;
    std::atomic<bool>           store_running{false};
    std::mutex                  store_mutex, store_append_mutex;
    // attach(), detach() and change_parameters() take turns.
    std::mutex                control_mutex;
    std::condition_variable   store_wake;
    std::atomic<unsigned int> stored{0};
    std::string               store_error;
    /** A write to the store failed (a full disk): the run's outputs end
     * with an output error (exit status 6). */
    std::atomic<bool> store_write_failed{false};

    // Real-time state (touched by force() only).
    ForceFilter           filter;
    ForceHold             hold;
    std::array<double, 9> stiffness = {}; // of the last force()
    // State space / Interpolation: force() asks it for each tick's force.
    std::unique_ptr<Interpolation> interpolation;
    MissingCause                   previous_cause = MissingCause::none;
    // Whether the last tick's missing data was held (a held stretch that
    // turns into a fade, when a server's trouble ends before its states
    // came, is a new event: the summary counts fades and holds apart).
    bool              previous_held = false;
    Utilities::Point3 previous_position{{0, 0, 0}}, velocity{{0, 0, 0}};
    Clock::time_point previous_call;
    bool first_call = true, was_complete = false, in_contact = false;
    // Where the HIP was at the last complete cell: how far the contact
    // patches extrapolate while data are missing is measured from here.
    Utilities::Point3 last_complete_position{{0, 0, 0}};
    // Whether track() has seen a finite position (the first has no
    // velocity).
    bool velocity_known = false;

    // Shared with other threads: atomics only.
    std::atomic<bool>         is_attached{false}, complete{false}, reset{false};
    mutable std::atomic<bool> initial_done{false};
    std::atomic<std::uint64_t> corner_reads{0}, corner_hits{0},
      missing_events{0}, missing_nanoseconds{0}, patched_nanoseconds{0},
      non_finite{0};
    // Held force: [0] in failure regions, [1] outside the state space,
    // [2] while a solver server was silent or lost (PrecomputationEngine::
    // degraded()).
    std::atomic<std::uint64_t> held_events[3] = {}, held_nanoseconds[3] = {};
    std::atomic<std::uint8_t>  event_cause{0}, last_cause{0};
    std::atomic<double>        event_stiffness{0};
    std::atomic<double>        largest_force{0}, largest_change{0};
    // The farthest (m) from last_complete_position that the interpolation
    // rendered missing data from the last complete cell (its patches).
    std::atomic<double> patched_farthest{0};
    std::atomic<double> event_position[3] = {};
    std::uint64_t       reported_events   = 0;
    Clock::time_point   attach_time;

    /** Seconds since the last force() call (1 ms at the first). */
    double
    tick() noexcept
    {
      const auto now = Clock::now();
      double     dt  = first_call ?
                         0.001 :
                         std::chrono::duration<double>(now - previous_call).count();
      if (!(dt > 0))
        dt = 1e-6;
      previous_call = now;
      first_call    = false;
      return dt;
    }

    /** The HIP's velocity for the scheduler's look-ahead: first-order low
     * pass of the position differences, time constant 20 ms; both go to
     * the HIP channel. False (and nothing written) for a non-finite
     * position. */
    bool
    track(const Utilities::Point3 &position, const double dt) noexcept
    {
      for (const double x : position)
        if (!std::isfinite(x))
          return false;
      const double alpha = std::min(1.0, dt / 0.02);
      for (unsigned int d = 0; d < 3; ++d)
        {
          const double v =
            velocity_known ? (position[d] - previous_position[d]) / dt : 0.0;
          velocity[d] += alpha * (v - velocity[d]);
        }
      velocity_known = true;
      hip.write(position, velocity);
      previous_position = position;
      return true;
    }

    /** force(), a step: forget the contact, the hold and what the
     * interpolation kept, as attach() asked (a new interaction
     * starts). */
    void
    apply_reset() noexcept
    {
      in_contact     = false;
      was_complete   = false;
      previous_cause = MissingCause::none;
      previous_held  = false;
      hold.reset();
      interpolation->reset();
    }

    /** force(), a step: the force at @p position by the interpolation,
     * and the corners it read (sample.read) counted as read and, once
     * complete, used. */
    ForceSample
    sample_at(const Utilities::Point3 &position) noexcept
    {
      const ForceSample sample = interpolation->force(position);
      if (sample.hits > 0 || sample.complete)
        {
          corner_reads.fetch_add(__builtin_popcount(sample.read),
                                 std::memory_order_relaxed);
          corner_hits.fetch_add(sample.hits, std::memory_order_relaxed);
        }
      if (sample.complete)
        for (unsigned int c = 0; c < 8; ++c)
          if ((sample.read >> c) & 1)
            used[sample.corners[c]].store(1, std::memory_order_relaxed);
      return sample;
    }

    /** force(), a step: a tick with data missing for @p cause counted,
     * held or not (@p held), over @p dt s, its force rendered from the
     * last complete cell's contact patches or not (@p patched); a change
     * of cause or hold is a new event, reported with the (finite or not)
     * @p position. */
    void
    count_missing(const MissingCause       cause,
                  const bool               held,
                  const bool               patched,
                  const Utilities::Point3 &position,
                  const double             dt,
                  const bool               finite) noexcept
    {
      const unsigned int slot = cause == MissingCause::failure_region ? 0 :
                                cause == MissingCause::outside        ? 1 :
                                                                        2;
      if (cause != previous_cause || held != previous_held)
        {
          for (unsigned int d = 0; d < 3; ++d)
            event_position[d].store(finite ? position[d] : 0.0,
                                    std::memory_order_relaxed);
          event_cause.store(static_cast<std::uint8_t>(cause) |
                              (held ? 0x10 : 0) | (hold.valid() ? 0 : 0x20) |
                              (patched ? 0x40 : 0),
                            std::memory_order_relaxed);
          event_stiffness.store(hold.held_stiffness(),
                                std::memory_order_relaxed);
          if (held)
            held_events[slot].fetch_add(1, std::memory_order_release);
          else
            missing_events.fetch_add(1, std::memory_order_release);
        }
      const auto nanoseconds = static_cast<std::uint64_t>(dt * 1e9);
      if (held)
        held_nanoseconds[slot].fetch_add(nanoseconds,
                                         std::memory_order_relaxed);
      else
        missing_nanoseconds.fetch_add(nanoseconds, std::memory_order_relaxed);
      if (patched && !held)
        patched_nanoseconds.fetch_add(nanoseconds, std::memory_order_relaxed);
    }

    /** force(), a step: the interpolation answered missing data at
     * @p position with @p force from the last complete cell: keep the
     * farthest from where the data were last complete. Off the surface
     * the patches answer zero, which extrapolates nothing. */
    void
    note_extrapolation(const Utilities::Point3 &position,
                       const Utilities::Point3 &force) noexcept
    {
      if (!(Utilities::norm(force) > 0))
        return;
      const double d = Utilities::distance(position, last_complete_position);
      if (d > patched_farthest.load(std::memory_order_relaxed))
        patched_farthest.store(d, std::memory_order_relaxed);
    }

    /** force(), a step: @p target (rendered or faded, @p render) through
     * the filter, with the largest force and change it made. */
    Utilities::Point3
    filtered(const Utilities::Point3 &target, const bool render) noexcept
    {
      bool                    rejected;
      const Utilities::Point3 f = filter.next(target, render, rejected);
      if (rejected)
        non_finite.fetch_add(1, std::memory_order_relaxed);
      if (filter.change() > largest_change.load(std::memory_order_relaxed))
        largest_change.store(filter.change(), std::memory_order_relaxed);
      const double magnitude = Utilities::norm(f);
      if (magnitude > largest_force.load(std::memory_order_relaxed))
        largest_force.store(magnitude, std::memory_order_relaxed);
      return f;
    }
  };
} // namespace palpate

#endif
