// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

#include <palpate/engine/engine.h>
#include <palpate/engine/hip_channel.h>
#include <palpate/haptics/force_interpolation.h>
#include <palpate/haptics/interaction.h>
#include <palpate/haptics/patch_contact.h>
#include <palpate/hyperelastic/sphere_trial.h>
#include <palpate/hyperelastic/state.h>
#include <palpate/mesh/mesh.h>
#include <palpate/mesh/node_selection.h>
#include <palpate/scene/scene.h>
#include <palpate/state_space/state_cache.h>
#include <palpate/state_space/state_grid.h>
#include <palpate/state_space/state_store.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <condition_variable>
#include <mutex>
#include <ostream>
#include <stdexcept>
#include <thread>

namespace palpate
{
  using Clock = std::chrono::steady_clock;

  struct Interaction::Impl
  {
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
      // Work space for the largest patch there can be (every surface
      // node), so that the haptic thread never allocates.
      if (interpolation == Interpolation::contact_patch)
        patch_contact = std::make_unique<PatchContact>(mesh.n_vertices(), 256);
      const double radius = scene.parameters.scheduler.cloud_radius;
      const int    reach =
        std::min<int>(grid.half_width(), std::floor(radius / grid.spacing()));
      for (int i = -reach; i <= reach; ++i)
        for (int j = -reach; j <= reach; ++j)
          for (int k = -reach; k <= reach; ++k)
            cloud_size +=
              Utilities::norm(grid.position(GridIndex{{i, j, k}})) <= radius;
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
      const double needed = 1.25 * cloud_size * state_bytes;
      if (needed > budget)
        throw scene.error(
          "Engine/Memory budget",
          "the initial cloud's " + std::to_string(cloud_size) +
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

    unsigned int                                 cloud_size = 0;
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
    const Interpolation   interpolation =
      interpolation_from_name(scene.parameters.state_space.interpolation);
    std::unique_ptr<PatchContact> patch_contact;
    // With contact patches, the cache's read section stays open from one
    // complete cell to the next, so that the last complete cell's patches
    // stay alive (the cache frees a patch it lets go of only once no
    // section can hold it) and answer while data are missing.
    bool                                patch_section_open = false;
    bool                                last_patches_valid = false;
    std::array<const ContactPatch *, 8> last_patches       = {};
    Utilities::Point3                   last_origin        = {{0, 0, 0}};
    std::uint64_t                       last_generation    = 0;
    MissingCause                        previous_cause     = MissingCause::none;
    // Whether the last tick's missing data was held (a held stretch that
    // turns into a fade, when a server's trouble ends before its states
    // came, is a new event: the summary counts fades and holds apart).
    bool              previous_held = false;
    Utilities::Point3 previous_position{{0, 0, 0}}, velocity{{0, 0, 0}};
    Clock::time_point previous_call;
    bool first_call = true, was_complete = false, in_contact = false;
    // Whether track() has seen a finite position (the first has no
    // velocity).
    bool velocity_known = false;

    // Shared with other threads: atomics only.
    std::atomic<bool>         is_attached{false}, complete{false}, reset{false};
    mutable std::atomic<bool> initial_done{false};
    std::atomic<std::uint64_t> corner_reads{0}, corner_hits{0},
      missing_events{0}, missing_nanoseconds{0}, non_finite{0};
    // Held force: [0] in failure regions, [1] outside the state space,
    // [2] while a solver server was silent or lost (PrecomputationEngine::
    // degraded()).
    std::atomic<std::uint64_t> held_events[3] = {}, held_nanoseconds[3] = {};
    std::atomic<std::uint8_t>  event_cause{0}, last_cause{0};
    std::atomic<double>        event_stiffness{0};
    std::atomic<double>        largest_force{0}, largest_change{0};
    std::atomic<double>        event_position[3] = {};
    std::uint64_t              reported_events   = 0;
    Clock::time_point          attach_time;

    /**
     * With Interpolation = contact patch: the force of the complete
     * @p sample at @p position from its corners' contact patches, solved
     * for the sphere there (PatchContact), in place of the trilinear one
     * interpolate_force() gave. A corner without a patch leaves the sample
     * trilinear. Real-time safe.
     */
    void
    render_contact_patch(const Utilities::Point3 &position,
                         ForceSample             &sample) noexcept
    {
      const std::uint64_t                 generation = cache.generation();
      std::array<const ContactPatch *, 8> patches;
      // The section of the last complete cell ends here: its patches are
      // not read again.
      if (patch_section_open)
        cache.end_patch_reads();
      cache.begin_patch_reads();
      patch_section_open = true;
      bool all           = true;
      for (unsigned int c = 0; c < 8 && all; ++c)
        all = (patches[c] = cache.read_patch(sample.corners[c], generation));
      last_patches_valid = all;
      if (all)
        {
          patch_contact->blend(patches,
                               trilinear_weights(sample.local),
                               position,
                               sample.force,
                               &sample.stiffness);
          last_patches    = patches;
          last_origin     = grid.position(sample.corners[0]);
          last_generation = generation;
        }
    }

    /**
     * While data are missing, with contact patches: the force at
     * @p position from the last complete cell's patches, the sphere's
     * contact against the surface and compliance last known there
     * (weights of the position clamped to that cell, so that the force is
     * continuous as the HIP leaves it). False, and the section ended, if
     * there are none or the parameters changed since. Real-time safe.
     */
    bool
    render_last_patches(const Utilities::Point3 &position,
                        Utilities::Point3       &force,
                        std::array<double, 9>   &stiffness) noexcept
    {
      if (last_patches_valid && cache.generation() != last_generation)
        {
          cache.end_patch_reads();
          patch_section_open = false;
          last_patches_valid = false;
        }
      if (!last_patches_valid)
        return false;
      std::array<double, 3> local;
      for (unsigned int d = 0; d < 3; ++d)
        local[d] =
          std::clamp((position[d] - last_origin[d]) / grid.spacing(), 0.0, 1.0);
      patch_contact->blend(
        last_patches, trilinear_weights(local), position, force, &stiffness);
      return true;
    }

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

    /** force(), a step: forget the contact, the hold and the patches
     * read, as reset_contact() asked (a new interaction starts). */
    void
    apply_reset() noexcept
    {
      in_contact     = false;
      was_complete   = false;
      previous_cause = MissingCause::none;
      previous_held  = false;
      hold.reset();
      if (patch_section_open)
        cache.end_patch_reads();
      patch_section_open = false;
      last_patches_valid = false;
    }

    /** force(), a step: the force at @p position interpolated from the 8
     * corners (with contact patches, solved against them), and the corners
     * counted as read and used. */
    ForceSample
    sample_at(const Utilities::Point3 &position) noexcept
    {
      ForceSample sample =
        interpolate_force(grid, cache, position, interpolation);
      if (sample.complete && patch_contact)
        render_contact_patch(position, sample);
      if (sample.hits > 0 || sample.complete)
        {
          corner_reads.fetch_add(8, std::memory_order_relaxed);
          corner_hits.fetch_add(sample.hits, std::memory_order_relaxed);
        }
      if (sample.complete)
        for (const unsigned int c : sample.corners)
          used[c].store(1, std::memory_order_relaxed);
      return sample;
    }

    /** force(), a step: a tick with data missing for @p cause counted,
     * held or not (@p held), over @p dt s; a change of cause or hold is a
     * new event, reported with the (finite or not) @p position. */
    void
    count_missing(const MissingCause       cause,
                  const bool               held,
                  const Utilities::Point3 &position,
                  const bool               finite,
                  const double             dt) noexcept
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
                              (held ? 0x10 : 0) | (hold.valid() ? 0 : 0x20),
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



  Interaction::Interaction(const Scene &scene)
    : impl(std::make_unique<Impl>(scene))
  {}



  Interaction::~Interaction()
  {
    detach();
  }



  void
  Interaction::attach()
  {
    Impl                       &s = *impl;
    std::lock_guard<std::mutex> lock(s.control_mutex);
    if (s.is_attached.load())
      return;
    // The HIP channel has one writer, force(): the cloud is computed around
    // where force() last saw the HIP (the rest position before its first
    // call).
    s.initial_done.store(false);
    s.attach_time = Clock::now();
    s.reset.store(
      true, std::memory_order_release); // force() restarts its contact logic
    s.engine->start();
    s.is_attached.store(true);
    if (s.store && !s.store_running.exchange(true))
      s.store_writer = std::thread([&s] { s.write_store(); });
  }



  void
  Interaction::abandon_running()
  {
    impl->engine->abandon_running();
  }



  void
  Interaction::detach()
  {
    Impl                       &s = *impl;
    std::lock_guard<std::mutex> lock(s.control_mutex);
    s.is_attached.store(false);
    s.engine->stop();
    if (s.store_running.exchange(false))
      {
        s.store_wake.notify_all();
        s.store_writer.join();
      }
    if (!s.store)
      return;
    // What the engine finished last. States held elsewhere (MPI servers)
    // are fetched when the store asks for them, a few ms later: append
    // again while that brings more, until every finished point that can be
    // stored is (a state the cache's budget dropped cannot come back); at
    // most 10 s, and half a second without progress ends it (a lost
    // server).
    using Clock           = std::chrono::steady_clock;
    const auto start      = Clock::now();
    auto       progressed = start;
    for (;;)
      {
        const unsigned int before = s.stored.load();
        s.append_to_store();
        const auto now = Clock::now();
        if (s.stored.load() > before)
          progressed = now;
        if (!s.store || s.store->missing(s.cache, s.grid) == 0 ||
            now - progressed > std::chrono::milliseconds(500) ||
            now - start > std::chrono::seconds(10))
          break;
        std::this_thread::sleep_for(std::chrono::milliseconds(20));
      }
  }



  bool
  Interaction::attached() const noexcept
  {
    return impl->is_attached.load(std::memory_order_relaxed);
  }



  Utilities::Point3
  Interaction::force(const Utilities::Point3 &position) noexcept
  {
    Impl &s = *impl;
    if (s.reset.exchange(false, std::memory_order_acq_rel))
      s.apply_reset();
    // The time since the last call, and the HIP's position and velocity
    // for the scheduler; a non-finite position is treated as "outside":
    // no force.
    const double dt     = s.tick();
    const bool   finite = s.track(position, dt);

    // Interpolation from the 8 corners (and, for Hermite, their
    // neighbours' stiffnesses), if all corners are there.
    const bool  attached = s.is_attached.load(std::memory_order_relaxed);
    ForceSample sample;
    if (attached && finite)
      sample = s.sample_at(position);
    const bool complete = sample.complete;
    if (complete)
      {
        s.in_contact = true;
        s.hold.update(position, sample);
      }

    // No force here, while in contact (from the first complete cell after
    // attaching on). Where states will come (not computed yet) the force
    // fades to zero, as in the paper. Where none can come - a failure
    // region, or outside the state space - the hand must not fall through
    // the tissue: the force is held from the last complete cell
    // (ForceHold, passive), until complete data is found again.
    MissingCause cause = !attached ? MissingCause::none :
                         finite    ? sample.cause() :
                                     MissingCause::outside;
    // Beyond a failure region the grid is not computed either (no
    // converged neighbour to start from): a held force stays held there.
    if (cause == MissingCause::not_computed &&
        (s.previous_cause == MissingCause::failure_region ||
         s.previous_cause == MissingCause::outside))
      cause = s.previous_cause;
    Utilities::Point3 target = sample.force;
    bool              render = complete;
    s.stiffness = complete ? sample.stiffness : std::array<double, 9>{};
    // States late because a solver server stopped answering or was lost
    // (not because the hand is fast) may stay missing for the server
    // timeout and the re-planning after it: held too, not faded.
    // Once held for that, it stays held until the cell is complete again:
    // the servers that come back (SIGCONT) still have the late states to
    // compute, and were the force faded the moment they are heard again,
    // an 8 N force would drop to 0 within 0.15 s.
    const bool server_trouble =
      cause == MissingCause::not_computed &&
      (s.engine->degraded() ||
       (s.previous_held && s.previous_cause == MissingCause::not_computed));
    bool held = false;
    // Missing data is an event while in contact; a failure region or the
    // state space's edge also before it (the HIP got there before any cell
    // was complete: zero force, with nothing to hold, is reported too); and
    // data not computed yet once the HIP has left its rest position, where
    // the force is no longer zero (Start = immediately: the hand can push
    // 7 mm into the liver at 0 N before the first cell is complete, and
    // that must be counted). At rest the zero force is the right one.
    const bool moved =
      finite && Utilities::norm(position) > 1e-3 * s.grid.spacing();
    const bool event =
      cause != MissingCause::none &&
      (s.in_contact || moved || cause != MissingCause::not_computed);
    if (event)
      {
        held = (cause != MissingCause::not_computed || server_trouble) &&
               finite && s.hold.valid();
        if (held)
          {
            target      = s.hold.force(position);
            render      = true;
            s.stiffness = s.hold.stiffness_matrix(position);
          }
        // With contact patches the last complete cell's patches answer
        // instead of the spring or the fade: the tissue there as last
        // known, zero off its surface. Still an event of its kind.
        if (s.patch_contact && s.in_contact && finite &&
            s.render_last_patches(position, target, s.stiffness))
          render = true;
        s.count_missing(cause, held, position, finite, dt);
      }
    s.previous_held  = held;
    s.previous_cause = event ? cause : MissingCause::none;
    s.last_cause.store(static_cast<std::uint8_t>(cause),
                       std::memory_order_relaxed);
    s.was_complete = complete;
    s.complete.store(complete, std::memory_order_relaxed);

    // Never a NaN, never more than the device's limit, never a jump.
    return s.filtered(target, render);
  }



  bool
  Interaction::data_complete() const noexcept
  {
    return impl->complete.load(std::memory_order_relaxed);
  }



  std::vector<unsigned int>
  Interaction::used_points() const
  {
    std::vector<unsigned int> points;
    for (unsigned int p = 0; p < impl->grid.size(); ++p)
      if (impl->used[p].load(std::memory_order_relaxed))
        points.push_back(p);
    return points;
  }



  const std::array<double, 9> &
  Interaction::stiffness() const noexcept
  {
    return impl->stiffness;
  }



  MissingCause
  Interaction::missing_cause() const noexcept
  {
    return static_cast<MissingCause>(
      impl->last_cause.load(std::memory_order_relaxed));
  }



  bool
  Interaction::engine_lost() const noexcept
  {
    return impl->engine->lost_every_worker();
  }



  bool
  Interaction::initial_cloud_complete() const
  {
    Impl &s = *impl;
    // Not while a solver server is in trouble (silent, or lost within the
    // last 3 s): its work is being planned again, and an engine idle for a
    // moment in between made the motion start on 23 of 81 states.
    if (!s.initial_done.load() && s.is_attached.load() && s.engine->idle() &&
        !s.engine->degraded())
      s.initial_done.store(true);
    return s.initial_done.load();
  }



  unsigned int
  Interaction::rest_neighbourhood_missing() const
  {
    const Impl     &s      = *impl;
    const GridIndex rest   = s.grid.nearest({{0, 0, 0}});
    unsigned int    absent = 0;
    for (int i = -1; i <= 1; ++i)
      for (int j = -1; j <= 1; ++j)
        for (int k = -1; k <= 1; ++k)
          {
            const GridIndex g{{rest[0] + i, rest[1] + j, rest[2] + k}};
            if (s.grid.contains(g) &&
                s.cache.status(s.grid.linear(g)) == PointStatus::missing)
              ++absent;
          }
    return absent;
  }



  unsigned int
  Interaction::initial_cloud_size() const noexcept
  {
    return impl->cloud_size;
  }



  namespace
  {
    /**
     * The checks of Interaction::change_parameters(): that @p parameters
     * change only what may change during an interaction, and that @p scene
     * with them is valid and selects nodes on @p mesh. @p scene becomes the
     * changed scene; returns its nodes.
     */
    NodeSelection
    checked_change(Scene                           &scene,
                   const Mesh                      &mesh,
                   const Parameters::AllParameters &parameters)
    {
      // What the grid, the cache, the mesh and the engine's threads were
      // built for cannot change here.
      const Parameters::AllParameters &o = scene.parameters;
      // The Mesh subsection is compared as a whole: a field-by-field list
      // misses the fields nobody added to it (the surface settings), and a
      // live change of one would be accepted and then ignored.
      const char *fixed = nullptr;
      if (o.mesh != parameters.mesh)
        fixed = "Mesh";
      else if (o.state_space.grid_spacing !=
                 parameters.state_space.grid_spacing ||
               o.state_space.extent != parameters.state_space.extent)
        fixed = "State space";
      else if (o.engine.type != parameters.engine.type ||
               o.engine.workers != parameters.engine.workers ||
               o.engine.memory_budget != parameters.engine.memory_budget)
        fixed = "Engine";
      else if (o.scheduler.cloud_radius != parameters.scheduler.cloud_radius ||
               o.scheduler.rate != parameters.scheduler.rate ||
               o.scheduler.look_ahead_time !=
                 parameters.scheduler.look_ahead_time)
        fixed = "Scheduler";
      else if (o.haptics.force_limit != parameters.haptics.force_limit ||
               o.haptics.max_force_change !=
                 parameters.haptics.max_force_change)
        fixed = "Haptics";
      if (fixed != nullptr)
        throw std::invalid_argument(
          std::string("Interaction::change_parameters: the subsection '") +
          fixed +
          "' cannot change during an interaction (the mesh, state grid, cache, "
          "engine and force filter are built for it). Change only the "
          "material, the boundary conditions, the effects or the solver "
          "settings, or create a new Interaction from the changed scene.");

      // Check the new scene and select its nodes before anything changes, so
      // that bad parameters leave the interaction as it was.
      scene.parameters = parameters;
      scene.validate();
      return select_nodes(scene, mesh);
    }
  } // namespace



  void
  Interaction::change_parameters(const Parameters::AllParameters &parameters)
  {
    Impl                       &s = *impl;
    std::lock_guard<std::mutex> lock(s.control_mutex);
    if (s.is_attached.load())
      throw std::logic_error(
        "Interaction::change_parameters: detach first (parameters can "
        "change only while no contact is active)");

    Scene         changed = s.scene;
    NodeSelection nodes   = checked_change(changed, s.mesh, parameters);

    // The engine's solvers are built from s.nodes: commit, and restore the
    // old scene if the engine cannot take the new one (the cache is
    // invalidated either way, so nothing computed before is used again).
    Scene         old_scene = std::move(s.scene);
    NodeSelection old_nodes = std::move(s.nodes);
    s.scene                 = std::move(changed);
    s.nodes                 = std::move(nodes);
    try
      {
        s.engine->change_parameters(parameters);
      }
    catch (...)
      {
        s.scene = std::move(old_scene);
        s.nodes = std::move(old_nodes);
        throw;
      }
    // The store holds states of the old physics: nothing of the new ones
    // may go into it (its fingerprint would lie).
    if (s.store)
      {
        s.store.reset();
        s.store_error = "the parameters changed during the interaction, so "
                        "the states computed after the change were not "
                        "stored (they belong to other physics)";
      }
  }



  void
  Interaction::check_parameters(
    const Parameters::AllParameters &parameters) const
  {
    Scene scene = this->scene();
    checked_change(scene, impl->mesh, parameters);
  }



  unsigned int
  Interaction::stored_points() const
  {
    const Impl &s = *impl;
    return s.loaded.states + s.loaded.failures + s.stored.load();
  }



  bool
  Interaction::store_write_failed() const
  {
    return impl->store_write_failed.load();
  }



  std::string
  Interaction::store_report() const
  {
    const Impl &s = *impl;
    if (s.scene.parameters.state_space.store.empty())
      return "";
    std::string r =
      "loaded " + std::to_string(s.loaded.states) + " states" +
      (s.loaded.patches > 0 ?
         " (" + std::to_string(s.loaded.patches) + " with contact patches)" :
         std::string()) +
      " and " + std::to_string(s.loaded.failures) + " failure points from " +
      s.scene.parameters.state_space.store +
      (s.loaded.damaged > 0 ?
         " (" + std::to_string(s.loaded.damaged) +
           " damaged records skipped: their checksums do not match)" :
         std::string()) +
      "; appended " + std::to_string(s.stored.load());
    if (!s.store_error.empty())
      r += "; " + s.store_error;
    return r;
  }



  unsigned int
  Interaction::poll_events(std::ostream &log)
  {
    Impl               &s = *impl;
    const std::uint64_t events =
      s.missing_events.load(std::memory_order_acquire) +
      s.held_events[0].load(std::memory_order_acquire) +
      s.held_events[1].load(std::memory_order_acquire) +
      s.held_events[2].load(std::memory_order_acquire);
    if (events == s.reported_events)
      return 0;
    const unsigned int n = events - s.reported_events;
    s.reported_events    = events;
    Utilities::Point3 p;
    for (unsigned int d = 0; d < 3; ++d)
      p[d] = s.event_position[d].load(std::memory_order_relaxed);
    const double t =
      std::chrono::duration<double>(Clock::now() - s.attach_time).count();
    const std::uint8_t code  = s.event_cause.load(std::memory_order_relaxed);
    const auto         cause = static_cast<MissingCause>(code & 0x0f);
    const bool         held  = code & 0x10;
    const bool         nothing_held = code & 0x20; // no complete cell before it
    const std::string  why =
      cause == MissingCause::failure_region ?
         "the HIP is in a failure region (no equilibrium was found for a "
         "corner of its cell)" :
       cause == MissingCause::outside ?
         "the HIP left the state space (extent +-" +
          Utilities::to_string(1000 * s.grid.half_width() * s.grid.spacing(),
                               4) +
          " mm)" :
       held ? "the states of the HIP's cell are late: a solver server is silent "
              "or was lost, and its work is planned again" :
              "the states of the HIP's cell are not computed yet";
    const std::string what =
      held ? "the force is held from the last computed cell, " +
               Utilities::to_string(
                 s.event_stiffness.load(std::memory_order_relaxed) / 1000, 3) +
               " N/mm deeper" :
      cause == MissingCause::not_computed ?
             "the force fades to zero until they are computed" :
      nothing_held ? "the force is zero: no cell was complete before it, so "
                     "there is no force to hold" :
                     "the force fades to zero";
    log << "palpate: missing data at t = " << Utilities::to_string(t, 4)
        << " s, HIP at (" << Utilities::to_string(p, 3) << ") m: " << why
        << "; " << what << (n > 1 ? " (" + std::to_string(n) + " events)" : "")
        << std::endl;
    return n;
  }



  EngineLoad
  Interaction::engine_load() const
  {
    return impl->engine->load();
  }



  RunSummary
  Interaction::summary() const
  {
    const Impl &s = *impl;
    RunSummary  r;
    r.scene                  = s.scene.file();
    r.engine                 = s.engine->description();
    const EngineStatistics e = s.engine->statistics();
    r.states_computed        = e.computed;
    r.states_failed          = e.failed;
    r.tasks_dropped          = e.dropped;
    r.tasks_cancelled        = e.cancelled + e.preempted;
    r.results_discarded      = e.discarded;
    r.solver_errors          = e.errors;
    r.last_solver_error      = e.last_error;
    std::vector<double> times;
    double              span = 0;
    for (const auto &t : e.tasks)
      {
        if (t.converged)
          times.push_back(1000 * t.duration);
        span = std::max(span, t.start + t.duration);
      }
    if (!times.empty())
      {
        std::nth_element(times.begin(),
                         times.begin() + times.size() / 2,
                         times.end());
        r.median_state_ms = times[times.size() / 2];
      }
    r.messages         = e.messages;
    r.bytes            = e.bytes;
    r.local_sources    = e.local_sources;
    r.fetched_sources  = e.fetched_sources;
    r.states_to_client = e.states_to_client;
    r.lost_servers     = e.lost_servers;
    if (!e.transfer_seconds.empty())
      {
        auto t = e.transfer_seconds;
        std::sort(t.begin(), t.end());
        r.transfer_p50_ms = 1000 * t[t.size() / 2];
        r.transfer_max_ms = 1000 * t.back();
      }
    const unsigned int workers = std::max(1u, s.engine->n_workers());
    r.worker_busy_fraction     = span > 0 ? e.busy_time / (span * workers) : 0;
    for (unsigned int p = 0; p < s.grid.size(); ++p)
      r.states_used += s.used[p].load(std::memory_order_relaxed);
    r.corner_reads           = s.corner_reads.load();
    r.corner_hits            = s.corner_hits.load();
    r.missing_events         = s.missing_events.load();
    r.missing_seconds        = 1e-9 * s.missing_nanoseconds.load();
    r.failure_region_events  = s.held_events[0].load();
    r.failure_region_seconds = 1e-9 * s.held_nanoseconds[0].load();
    r.outside_events         = s.held_events[1].load();
    r.outside_seconds        = 1e-9 * s.held_nanoseconds[1].load();
    r.server_hold_events     = s.held_events[2].load();
    r.server_hold_seconds    = 1e-9 * s.held_nanoseconds[2].load();
    r.non_finite_forces      = s.non_finite.load();
    r.largest_force          = s.largest_force.load();
    r.largest_force_change   = s.largest_change.load();
    return r;
  }



  const Scene &
  Interaction::scene() const
  {
    return impl->scene;
  }



  const Mesh &
  Interaction::mesh() const
  {
    return impl->mesh;
  }



  const NodeSelection &
  Interaction::nodes() const
  {
    return impl->nodes;
  }



  const StateGrid &
  Interaction::grid() const
  {
    return impl->grid;
  }



  const StateCache &
  Interaction::cache() const
  {
    return impl->cache;
  }



  const HipChannel &
  Interaction::hip() const
  {
    return impl->hip;
  }
} // namespace palpate
