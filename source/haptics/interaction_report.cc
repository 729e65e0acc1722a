// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

// What an Interaction says of itself while and after it runs: the states
// stored and the store's trouble, the events of missing data for the log,
// the engine's load and the run's summary.

#include <palpate/haptics/interaction_impl.h>

#include <chrono>
#include <ostream>
#include <string>

namespace palpate
{
  using Clock = std::chrono::steady_clock;



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
    const bool         patched      = code & 0x40; // the last cell's patches
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
      patched ?
        std::string("the force comes from the last complete cell's contact "
                    "patches (the tissue there as last known)") :
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
    r.corner_reads            = s.corner_reads.load();
    r.corner_hits             = s.corner_hits.load();
    r.missing_events          = s.missing_events.load();
    r.missing_seconds         = 1e-9 * s.missing_nanoseconds.load();
    r.missing_patched_seconds = 1e-9 * s.patched_nanoseconds.load();
    r.patched_farthest        = s.patched_farthest.load();
    r.failure_region_events   = s.held_events[0].load();
    r.failure_region_seconds  = 1e-9 * s.held_nanoseconds[0].load();
    r.outside_events          = s.held_events[1].load();
    r.outside_seconds         = 1e-9 * s.held_nanoseconds[1].load();
    r.server_hold_events      = s.held_events[2].load();
    r.server_hold_seconds     = 1e-9 * s.held_nanoseconds[2].load();
    r.non_finite_forces       = s.non_finite.load();
    r.largest_force           = s.largest_force.load();
    r.largest_force_change    = s.largest_change.load();
    return r;
  }
} // namespace palpate
