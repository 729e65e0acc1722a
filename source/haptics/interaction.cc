// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

// Interaction (interaction.h): attaching to the engine and detaching from
// it, the force at each tick of the haptic loop (the real-time path: noexcept,
// no lock, no allocation), and what the haptic side asks of the data
// around the HIP.

#include <palpate/haptics/interaction_impl.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <mutex>
#include <thread>

namespace palpate
{
  using Clock = std::chrono::steady_clock;



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

    // The interpolation's force (State space / Interpolation), if the
    // corners it reads are there.
    const bool  attached = s.is_attached.load(std::memory_order_relaxed);
    ForceSample sample;
    if (attached && finite)
      sample = s.sample_at(position);
    const bool complete = sample.complete;
    if (complete)
      {
        s.in_contact             = true;
        s.last_complete_position = position;
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
    // Missing data is an event while in contact (since the first complete
    // cell), and before it once the HIP has left its rest position: in a
    // failure region or at the state space's edge (zero force, with
    // nothing to hold, is reported too), or where data is not computed yet
    // and the force is no longer zero (Start = immediately: the hand can
    // push 7 mm into the liver at 0 N before the first cell is complete,
    // and that must be counted). At rest before any cell was complete the
    // hand has felt nothing yet and has not moved: not an event, whatever
    // the corners of the cell around rest (the motion may start seconds
    // later, once the initial cloud is done).
    const bool moved =
      finite && Utilities::norm(position) > 1e-3 * s.grid.spacing();
    const bool event = cause != MissingCause::none && (s.in_contact || moved);
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
        // An interpolation that kept the last complete cell's data (the
        // contact patch: its patches) answers instead of the spring or the
        // fade: the tissue there as last known, zero off its surface.
        // Still an event of its kind.
        const bool patched =
          s.in_contact && finite &&
          s.interpolation->force_while_missing(position, target, s.stiffness);
        render = render || patched;
        if (patched)
          s.note_extrapolation(position, target);
        s.count_missing(cause, held, patched, position, dt, finite);
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
    return impl->cloud_points.size();
  }



  unsigned int
  Interaction::initial_cloud_missing() const
  {
    const Impl  &s      = *impl;
    unsigned int absent = 0;
    for (const unsigned int p : s.cloud_points)
      absent += s.cache.status(p) == PointStatus::missing;
    return absent;
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
