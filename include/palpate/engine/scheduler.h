// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

#ifndef palpate_engine_scheduler_h
#define palpate_engine_scheduler_h

#include <palpate/base/utilities.h>
#include <palpate/state_space/state_cache.h>
#include <palpate/state_space/state_grid.h>

#include <cstdint>
#include <functional>
#include <vector>

namespace palpate
{
  /** What the scheduler knows about one grid point. */
  enum class PointKnowledge : std::uint8_t
  {
    /** Nothing computed, nothing under way. */
    unknown,
    /** A worker is computing it. */
    in_progress,
    /** Computed, and its whole state is held: it can be a source. */
    source,
    /** Computed, but its whole state was dropped (force only). */
    computed,
    /** A failure point: never retried in this generation. */
    failed
  };

  /**
   * "Compute the state at grid point target, starting from the computed
   * state at its neighbour source" (incremental staging over the path
   * source -> target).
   */
  struct Task
  {
    unsigned int target;
    unsigned int source;
    /** Lower is more urgent: the distance (m) of the target from the
     * HIP's predicted path. */
    double priority;
    /** A corner of the HIP's cell: before every other task. */
    bool corner = false;
  };

  /**
   * What the scheduler knows about a point, from what an engine knows:
   * whether a task for it is under way, its status in the cache, and
   * whether its whole state is held somewhere (so it can be a source).
   */
  inline PointKnowledge
  point_knowledge(const bool        in_progress,
                  const PointStatus status,
                  const bool        held)
  {
    if (in_progress)
      return PointKnowledge::in_progress;
    switch (status)
      {
        case PointStatus::available:
          return held ? PointKnowledge::source : PointKnowledge::computed;
        case PointStatus::failed:
          return PointKnowledge::failed;
        default:
          return PointKnowledge::unknown;
      }
  }

  /** Whether a point in this state can be the target of a task: unknown,
   * or computed but its whole state dropped (it is then recomputed when
   * the cloud needs it as a source again). */
  inline bool
  schedulable(const PointKnowledge k)
  {
    return k == PointKnowledge::unknown || k == PointKnowledge::computed;
  }

  /**
   * What an engine remembers between plans about Scheduler::plan's bridge:
   * when the bridge found nothing, the grid is not scanned again until a
   * task has finished or the HIP is in another cell (nothing it could find
   * has changed).
   */
  class BridgeMemory
  {
  public:
    /** Whether the next plan may build a bridge. */
    bool
    allowed(const std::uint64_t tasks_finished, const GridIndex &cell) const
    {
      return !(tasks_finished == failed_at && cell == failed_cell);
    }

    /** After a plan made with @p allowed_bridge: remember a fruitless one. */
    void
    planned(const bool          plan_empty,
            const bool          allowed_bridge,
            const std::uint64_t tasks_finished,
            const GridIndex    &cell)
    {
      if (plan_empty && allowed_bridge)
        {
          failed_at   = tasks_finished;
          failed_cell = cell;
        }
    }

    /** Forget (a new attach). */
    void
    reset()
    {
      failed_at = ~std::uint64_t(0);
    }

  private:
    std::uint64_t failed_at   = ~std::uint64_t(0);
    GridIndex     failed_cell = {{0, 0, 0}};
  };

  /**
   * The scheduling policy: which states to compute next.
   *
   * The *cloud* is the set of grid points within the cloud radius R of the
   * HIP's predicted path, the segment from the HIP to where it will be
   * after the look-ahead time at its current velocity (with zero velocity
   * or look-ahead, the paper's sphere around the HIP). Points of the cloud
   * that are not computed, not failed and not under way are candidates;
   * each needs a source, an axis neighbour whose state is held (the one
   * nearest the HIP). A point whose whole state was dropped for the memory
   * budget is a candidate again where an unknown cloud point needs it as a
   * source. The corners of the cell the HIP is in come first
   * (interaction can start, or go on, as soon as they exist), then the
   * corners of the cells the predicted path passes through, in the order
   * the HIP will reach them (motion prediction: a straight stroke needs
   * only these 4 new states per cell, not the whole tube around it); then
   * the rest of the cloud by distance from the predicted path (ties by grid
   * number). If unknown points of the cloud remain but none can
   * be reached and none is under way (the HIP jumped, or outran the
   * computed front), the plan builds a bridge: the points next to held
   * states that are nearest the HIP's path, even outside the cloud, each
   * nearer to the path than its source (so a bridge only ever leads toward
   * the cloud, and cloud points walled off by failure points do not make it
   * grow). The bridge scans the whole grid; @p allow_bridge = false skips
   * it (the engine does when nothing changed since a bridge found
   * nothing).
   *
   * The class holds no state between calls: the same inputs give the same
   * plan, which is what the virtual-time tests check.
   */
  class Scheduler
  {
  public:
    /** @p cloud_radius (m) and @p look_ahead_time (s). */
    Scheduler(const StateGrid &grid,
              const double     cloud_radius,
              const double     look_ahead_time);

    /**
     * The most urgent tasks (at most @p max_tasks) for the HIP at @p hip
     * moving with @p velocity (m/s), given what is known about each point.
     * The bridge is built only if @p allow_bridge.
     */
    std::vector<Task>
    plan(const Utilities::Point3                           &hip,
         const Utilities::Point3                           &velocity,
         const std::function<PointKnowledge(unsigned int)> &knowledge,
         const unsigned int                                 max_tasks,
         const bool allow_bridge = true) const;

    /** Whether @p point belongs to the cloud for this HIP and velocity. */
    bool
    in_cloud(const unsigned int       point,
             const Utilities::Point3 &hip,
             const Utilities::Point3 &velocity) const;

    /**
     * The corners of the cells the HIP is in and will pass through (its
     * predicted path, at least two grid spacings long along the motion), each
     * with the arc length (m) at which the path first enters one of its
     * cells; sorted by point. plan() puts these first (Task::corner).
     */
    std::vector<std::pair<unsigned int, double>>
    path_corners(const Utilities::Point3 &hip,
                 const Utilities::Point3 &velocity) const;

    /** Distance of @p x from the predicted path of the HIP (m). */
    double
    distance_to_path(const Utilities::Point3 &x,
                     const Utilities::Point3 &hip,
                     const Utilities::Point3 &velocity) const;

  private:
    const StateGrid &grid;
    const double     radius, look_ahead;
  };
} // namespace palpate

#endif
