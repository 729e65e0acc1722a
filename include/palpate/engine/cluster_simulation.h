// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

#ifndef palpate_engine_cluster_simulation_h
#define palpate_engine_cluster_simulation_h

#include <palpate/base/utilities.h>
#include <palpate/engine/scheduler.h>
#include <palpate/state_space/state_grid.h>

#include <cstdint>
#include <functional>
#include <limits>
#include <set>
#include <utility>
#include <vector>

namespace palpate
{
  /**
   * The network between the client and the solver servers, and between the
   * servers: every message costs a fixed latency plus its size over the
   * bandwidth. Links are not shared (no contention): a state message is a
   * few kilobytes and a task lasts milliseconds to seconds, so queueing on
   * a link is negligible next to the solve.
   */
  struct NetworkModel
  {
    /** One-way latency of a message (s). Default: 100 us, MPI over
     * Gigabit Ethernet through sockets, as on the paper's cluster. */
    double latency = 100e-6;

    /** Bandwidth of a link (bytes/s). Default: 1 Gbit/s. */
    double bandwidth = 125e6;

    /** Size of a notification ("compute g from g'", "g done, force f")
     * (bytes). */
    double notification_bytes = 64;

    /** Time from sending a message of @p bytes to its arrival (s). */
    double
    message_time(const double bytes) const
    {
      return latency + bytes / bandwidth;
    }
  };

  /**
   * How long the solve of one state takes on a server (s): either a fixed
   * time, or drawn from a list of measured times. A drawn time depends
   * only on the seed and on the task (target and source), not on when or
   * where it runs, so runs with different server counts solve the same
   * states in the same times and differ only by the schedule.
   */
  class TaskDurations
  {
  public:
    /** Every task takes @p seconds. */
    static TaskDurations
    fixed(const double seconds);

    /** Each task takes one of @p seconds, chosen by a hash of @p seed and
     * the task (uniformly over the list). */
    static TaskDurations
    sampled(const std::vector<double> &seconds, const std::uint64_t seed);

    /** The time (s) of the task "compute @p target from @p source". */
    double
    operator()(const unsigned int target, const unsigned int source) const;

    /** The mean of the times (s). */
    double
    mean() const;

  private:
    std::vector<double> times;
    std::uint64_t       seed = 0;
  };

  /**
   * A discrete-event simulation of the distributed engine: one client
   * running the Scheduler (at its rate, and again whenever a server reports
   * a result, as the real engines do) and N solver servers, in virtual
   * time, with a network model and per-state solve times.
   *
   * What a task costs, from the scheduler's decision at time t to the
   * result at the client:
   *   - the notification "compute g from g', held by server S" reaches
   *     the chosen server after NetworkModel::message_time(notification);
   *   - if the server does not hold g' (lazy state transfer), it asks a
   *     holder for it (one notification) and receives the state message
   *     (@p state_bytes); a holder's communicator answers at once, whether
   *     or not its solver is busy (the paper's two threads per server);
   *     the rest state is known to every server and never travels;
   *   - the solve takes TaskDurations(g, g');
   *   - the result notification, carrying the force, reaches the client
   *     one notification later: from then on the force interpolator can
   *     use g and the scheduler may give g as a source.
   * A server is busy (counted in the busy-server curves) from the
   * scheduler's decision until the result reaches the client. Each server
   * keeps every state it computed or received (no memory budget).
   *
   * The scheduler gives the most urgent tasks to free servers, and a task
   * to a free server that already holds its source if there is one (the
   * paper's map of who holds what), else to the free server with the
   * lowest number. With Settings::servers = 0 there are as many servers
   * as tasks ever run at once (a new one joins when none is free): the
   * peak of the busy curve is then the number of servers the schedule
   * needs.
   */
  class ClusterSimulation
  {
  public:
    /** The cluster and the scheduler. */
    struct Settings
    {
      /** Cloud radius R (m). */
      double cloud_radius = 0.025;
      /** Scheduler look-ahead (s): 0 is the paper's sphere around the HIP. */
      double look_ahead_time = 0.2;
      /** Scheduler rate (Hz): the paper's and palpate's 100 Hz. */
      double scheduler_rate = 100;
      /** Time constant (s) of the first-order low-pass filter on the
       * HIP's velocity, run at the haptic rate, as the haptic side
       * publishes it to the scheduler (Interaction: 20 ms). */
      double velocity_time_constant = 0.02;
      /** Solver servers; 0: as many as ever needed. */
      unsigned int servers = 1;
      /** Size of a state message (bytes): displacements and multipliers. */
      double state_bytes = 1503 * 8;
      /** The network. */
      NetworkModel network;
      /** Rate (Hz) of the haptic loop: the velocity filter runs at it, and
       * the force interpolator's needs are checked at it for missing
       * data. */
      double haptic_rate = 1000;
    };

    /**
     * The HIP's motion: at rest at path(0) until the motion starts, then at
     * path(tau) for tau = t - start in [0, duration], then at rest at
     * path(duration).
     */
    struct Motion
    {
      /** Position (m) of the HIP (the active node's displacement) at
       * @p tau seconds after the start of the motion. */
      std::function<Utilities::Point3(double)> path;
      /** Length of the motion (s). */
      double duration = 0;
      /** Start of the motion (s); negative: as soon as the initial cloud
       * around path(0) is complete (nothing left to plan, no server busy),
       * as `palpate scene.prm` starts the device. */
      double start = -1;
    };

    /** One task: what the scheduler decided, and when each step happened
     * (all times in s of simulated time). */
    struct TaskRecord
    {
      unsigned int target, source, server;
      /** The scheduler gave the task to the server. */
      double assigned;
      /** Waiting for the source state (s): 0 if the server held it. */
      double transfer;
      /** The solve started and finished on the server. */
      double start, finish;
      /** The result (the force) reached the client. */
      double arrived;
      /** The target is a failure point. */
      bool failed;
    };

    /** What a run produced. */
    struct Result
    {
      /** Every task, in the order the scheduler gave them out. */
      std::vector<TaskRecord> tasks;
      /** Busy servers as a step function: (time s, count from then on). */
      std::vector<std::pair<double, unsigned int>> busy;
      /** When the motion started and ended (s). */
      double motion_start = 0, motion_end = 0;
      /** Tasks finished before the motion started (the initial cloud). */
      unsigned int initial_cloud_states = 0;
      /** Servers that ever had work. */
      unsigned int servers_used = 0;
      /** Tasks whose source came from another server, and tasks whose
       * source (not the rest state) the server already held. */
      unsigned int transfers = 0, transfers_avoided = 0;
      /** While the HIP moved: grid points that the scheduler planned at
       * least once when no server was free for them, and the most tasks
       * left waiting at one decision. */
      unsigned int waited = 0, max_waiting = 0;
      /** While the HIP moved, checked at the haptic rate: times the HIP's
       * cell went from complete to missing a corner's force (or the HIP
       * left the grid), and the time (s) it spent so. */
      unsigned int missing_events  = 0;
      double       missing_seconds = 0;

      /** The largest number of busy servers at any time in [@p from, @p
       * to] (s). */
      unsigned int
      peak_busy(const double from, const double to) const;
    };

    /** A simulation on @p grid, with @p durations per task. */
    ClusterSimulation(const StateGrid    &grid,
                      const Settings     &settings,
                      const TaskDurations durations);

    /** Grid points whose computation fails (failure points): they take
     * their time, and are never a source. */
    void
    set_failure_points(const std::set<unsigned int> &points);

    /**
     * Simulate: the rest state (grid point 0) is known at t = 0 on every
     * server; the HIP follows @p motion; the simulation ends @p
     * time_after_motion seconds after the motion, or at @p max_time (s).
     */
    Result
    run(const Motion &motion,
        const double  time_after_motion,
        const double  max_time = 1e4) const;

  private:
    const StateGrid       &grid;
    const Settings         settings;
    const TaskDurations    durations;
    const Scheduler        scheduler;
    std::set<unsigned int> failures;
  };
} // namespace palpate

#endif
