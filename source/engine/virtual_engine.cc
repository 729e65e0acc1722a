// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

#include <palpate/engine/virtual_engine.h>

#include <algorithm>
#include <cmath>
#include <deque>

namespace palpate
{
  VirtualEngine::VirtualEngine(const StateGrid   &grid,
                               const double       cloud_radius,
                               const double       look_ahead_time,
                               const unsigned int workers,
                               const double       task_duration,
                               const double       tick)
    : grid(grid)
    , scheduler(grid, cloud_radius, look_ahead_time)
    , workers(workers)
    , task_duration(task_duration)
    , tick(tick)
    , known(grid.size(), PointKnowledge::unknown)
  {}



  void
  VirtualEngine::set_failure_points(const std::set<unsigned int> &points)
  {
    failures = points;
  }



  std::vector<VirtualEngine::Started>
  VirtualEngine::run(const std::function<Utilities::Point3(double)> &hip,
                     const double                                    duration)
  {
    std::vector<Started> started;
    known.assign(grid.size(), PointKnowledge::unknown);
    known[grid.linear({{0, 0, 0}})] = PointKnowledge::source;
    dropped                         = 0;

    struct Running
    {
      unsigned int target;
      double       finish;
    };
    std::vector<std::vector<Running>> busy(workers);
    std::deque<Task>                  queue;

    const unsigned int n_ticks =
      static_cast<unsigned int>(std::llround(duration / tick));
    for (unsigned int k = 0; k <= n_ticks; ++k)
      {
        const double t = k * tick;
        // Tasks that finished by now publish their state or failure.
        for (auto &w : busy)
          if (!w.empty() && w.front().finish <= t + 1e-12)
            {
              const unsigned int p = w.front().target;
              known[p] = failures.count(p) ? PointKnowledge::failed :
                                             PointKnowledge::source;
              w.clear();
            }

        // Plan, as ThreadEngine's scheduler thread does at every tick.
        const Utilities::Point3 x        = hip(t),
                                previous = hip(t > 0 ? t - tick : t);
        Utilities::Point3 v;
        for (unsigned int d = 0; d < 3; ++d)
          v[d] = t > 0 ? (x[d] - previous[d]) / tick : 0.0;
        const auto plan = scheduler.plan(
          x, v, [this](const unsigned int p) { return known[p]; }, 2 * workers);
        // Queued tasks that are neither in the new plan nor in the cloud
        // any more are dropped.
        for (const Task &old : queue)
          if (!scheduler.in_cloud(old.target, x, v) &&
              std::none_of(plan.begin(), plan.end(), [&](const Task &t) {
                return t.target == old.target;
              }))
            ++dropped;
        queue.assign(plan.begin(), plan.end());

        // Free workers take tasks, most urgent first.
        for (unsigned int w = 0; w < workers; ++w)
          while (busy[w].empty() && !queue.empty())
            {
              const Task task = queue.front();
              queue.pop_front();
              if (!schedulable(known[task.target]))
                continue;
              known[task.target] = PointKnowledge::in_progress;
              busy[w].push_back({task.target, t + task_duration});
              started.push_back({t, task.target, task.source, w});
            }
      }
    return started;
  }
} // namespace palpate
