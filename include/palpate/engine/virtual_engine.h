// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

#ifndef palpate_engine_virtual_engine_h
#define palpate_engine_virtual_engine_h

#include <palpate/base/utilities.h>
#include <palpate/engine/scheduler.h>
#include <palpate/state_space/state_grid.h>

#include <functional>
#include <set>
#include <vector>

namespace palpate
{
  /**
   * The engine's scheduling loop on a simulated clock: no threads, no FE
   * solves, every task takes a fixed time. It runs the same Scheduler
   * policy as ThreadEngine, tick by tick, so its schedule is what the
   * policy decides, exactly and reproducibly. Tests check it; it also
   * answers "how fast could the HIP move with N workers and tasks of T
   * seconds" without a cluster.
   */
  class VirtualEngine
  {
  public:
    /** One task as it was started. */
    struct Started
    {
      double       time;
      unsigned int target, source, worker;
    };

    /**
     * @p workers solver workers, each task @p task_duration seconds, the
     * scheduler every @p tick seconds.
     */
    VirtualEngine(const StateGrid   &grid,
                  const double       cloud_radius,
                  const double       look_ahead_time,
                  const unsigned int workers,
                  const double       task_duration,
                  const double       tick);

    /** Grid points whose computation fails (failure points). */
    void
    set_failure_points(const std::set<unsigned int> &points);

    /**
     * Simulate @p duration seconds with the HIP at @p hip(t); the origin is
     * computed at t = 0. Returns the tasks in the order they started.
     */
    std::vector<Started>
    run(const std::function<Utilities::Point3(double)> &hip,
        const double                                    duration);

    /** Queued tasks dropped because they left the cloud. */
    unsigned int
    n_dropped() const
    {
      return dropped;
    }

    /** What is known about @p point at the end of the run. */
    PointKnowledge
    knowledge(const unsigned int point) const
    {
      return known[point];
    }

  private:
    const StateGrid            &grid;
    const Scheduler             scheduler;
    const unsigned int          workers;
    const double                task_duration, tick;
    std::set<unsigned int>      failures;
    std::vector<PointKnowledge> known;
    unsigned int                dropped = 0;
  };
} // namespace palpate

#endif
