// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

#ifndef palpate_haptics_run_summary_h
#define palpate_haptics_run_summary_h

#include <cstdint>
#include <iosfwd>
#include <string>
#include <vector>

namespace palpate
{
  /**
   * What an interaction did, for the user (print()) and for tools
   * (write_csv(), write_json(); Output / Summary formats).
   */
  struct RunSummary
  {
    // Set-up.
    std::string scene, engine, trajectory;

    // The engine.
    unsigned int states_computed = 0, states_failed = 0, tasks_dropped = 0,
                 tasks_cancelled = 0, results_discarded = 0;
    /** Solves that threw instead of converging or failing (each is also a
     * failure point), and the last message. */
    unsigned int solver_errors = 0;
    std::string  last_solver_error;
    double       median_state_ms = 0, worker_busy_fraction = 0;

    // The MPI engine's traffic (zero with threads): messages and bytes
    // sent by all ranks, sources found on the chosen server and fetched
    // from another, whole states sent to the client, and the time from
    // "needed" to "arrived" of a transfer (median and largest, ms).
    std::uint64_t messages = 0, bytes = 0;
    unsigned int  local_sources = 0, fetched_sources = 0, states_to_client = 0;
    double        transfer_p50_ms = 0, transfer_max_ms = 0;
    /** Solver servers lost, one sentence each (the run then exits with a
     * non-zero status). */
    std::vector<std::string> lost_servers;

    // What the haptic side read.
    unsigned int  states_used  = 0;
    std::uint64_t corner_reads = 0, corner_hits = 0;
    /** Missing data where states were not computed yet: the force faded
     * to zero. */
    std::uint64_t missing_events  = 0;
    double        missing_seconds = 0;
    /** Of missing_seconds, the time the contact patch interpolation
     * rendered the force from the last complete cell's patches (the tissue
     * there as last known) instead of fading it. */
    double missing_patched_seconds = 0;
    /** The farthest (m) from where the data were last complete that the
     * last complete cell's contact patches rendered missing data (held or
     * not): their linear contact models, extrapolated that far. */
    double patched_farthest = 0;
    /** Where no state can come, the force was held (ForceHold): in failure
     * regions, and outside the state space. */
    std::uint64_t failure_region_events = 0, outside_events = 0;
    double        failure_region_seconds = 0, outside_seconds = 0;
    /** Held too while a solver server was silent or just lost
     * (PrecomputationEngine::degraded()): its states were late. */
    std::uint64_t server_hold_events  = 0;
    double        server_hold_seconds = 0;
    std::uint64_t non_finite_forces   = 0;
    double        largest_force = 0, largest_force_change = 0;

    // The built-in haptic loop (zero if the host application ran its own).
    bool loop_ran = false, realtime_priority = false;
    /** Whether the loop's memory could be locked (no page faults). */
    bool memory_locked = false;
    /** Whether the loop hit its time bound before the motion ended. */
    bool   loop_truncated = false;
    double loop_rate      = 0;
    /** A continuous loop's (the live view's) statistics cover only its last
     * this many seconds; 0: the whole run. */
    double statistics_window = 0;
    /** Seconds from attach to the motion's start (-1: it never started,
     * stopped during the initial cloud), and how long it lasted. */
    double        motion_start = 0, motion_duration = 0;
    std::uint64_t ticks = 0, deadline_misses = 0;
    double        period_p50_ms = 0, period_p99_ms = 0, period_p999_ms = 0,
           period_max_ms        = 0;
    double interpolation_p50_us = 0, interpolation_p999_us = 0;

    // The initial cloud (palpate's own run only): states available when
    // the motion started, and whether the cloud was complete then.
    unsigned int initial_cloud_states   = 0;
    bool         initial_cloud_complete = false;

    /** Why the run ended before its motion did ("by SIGINT (Ctrl-C) after
     * 2.1 s of the 8 s motion"; empty when it ran to the end), and the
     * signal's number (0 if none: e.g. standard output was closed). */
    std::string stopped_by;
    int         stop_signal = 0;

    // Shape output.
    unsigned int shape_frames = 0;

    /** A human-readable summary. */
    void
    print(std::ostream &out) const;

    /** key,value lines. */
    void
    write_csv(const std::string &filename) const;

    /** One JSON object. */
    void
    write_json(const std::string &filename) const;
  };
} // namespace palpate

#endif
