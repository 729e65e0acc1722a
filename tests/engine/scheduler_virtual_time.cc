// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

// The scheduler on a simulated clock (no threads, no FE solves): a 5 mm
// grid, a cloud of 12 mm, 0.2 s look-ahead, 2 workers, 30 ms per task,
// ticks of 10 ms. The HIP rests for 0.5 s, then moves along +x at 20 mm/s;
// the grid point (2, 0, 0) on its path is a failure point.
//
// The schedule (order, sources, workers) is fixed by the policy and is
// compared line by line with the saved output. Independently of it, the
// test checks the rules: the corners of the HIP's cell come first; every
// source was computed before its task started and is an axis neighbour;
// no point is scheduled twice (so the failure point is never retried);
// every target was in the cloud, or a corner of a cell on the HIP's
// predicted path (two cells ahead), when its task started; and queued tasks
// that fell out of the cloud were dropped (a second run, where the HIP
// jumps).

#include <palpate/engine/virtual_engine.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <set>

#include "../tests.h"

int
main(int argc, char **argv)
{
  palpate::Environment env(argc, argv);
  initlog();

  const palpate::StateGrid grid(0.005, 0.05);
  const double radius = 0.012, look_ahead = 0.2, duration = 0.03, tick = 0.01;
  palpate::VirtualEngine engine(grid, radius, look_ahead, 2, duration, tick);
  const unsigned int     failure = grid.linear({{2, 0, 0}});
  engine.set_failure_points({failure});

  palpate::GridIndex    lower;
  std::array<double, 3> local;
  const auto            hip = [](const double t) {
    return palpate::Utilities::Point3{{t < 0.5 ? 0.0 : 0.02 * (t - 0.5), 0, 0}};
  };
  const auto tasks = engine.run(hip, 1.5);

  const auto name = [&](const unsigned int p) {
    const auto g = grid.index(p);
    return "(" + std::to_string(g[0]) + "," + std::to_string(g[1]) + "," +
           std::to_string(g[2]) + ")";
  };
  deallog << tasks.size() << " tasks started, " << engine.n_dropped()
          << " queued tasks dropped" << std::endl;
  deallog << "the first 24, as started (time s: target <- source, worker):"
          << std::endl;
  for (unsigned int k = 0; k < 24 && k < tasks.size(); ++k)
    deallog << "  " << std::setprecision(3) << tasks[k].time << ": "
            << name(tasks[k].target) << " <- " << name(tasks[k].source)
            << ", worker " << tasks[k].worker << std::endl;
  deallog << "after the HIP starts moving, the first 12:" << std::endl;
  unsigned int shown = 0;
  for (const auto &t : tasks)
    if (t.time >= 0.5 && shown++ < 12)
      deallog << "  " << std::setprecision(3) << t.time << ": "
              << name(t.target) << " <- " << name(t.source) << ", worker "
              << t.worker << std::endl;

  // The rules.
  bool corners_first = true;
  for (unsigned int k = 0; k < 7; ++k)
    {
      const auto g  = grid.index(tasks[k].target);
      corners_first = corners_first && g[0] >= 0 && g[0] <= 1 && g[1] >= 0 &&
                      g[1] <= 1 && g[2] >= 0 && g[2] <= 1;
    }
  std::map<unsigned int, double> finished{{grid.linear({{0, 0, 0}}), 0.0}};
  bool sources_ready = true, unique = true, in_cloud = true,
       axis_neighbours = true;
  const palpate::Scheduler scheduler(grid, radius, look_ahead);
  for (const auto &t : tasks)
    {
      const auto it = finished.find(t.source);
      sources_ready = sources_ready && it != finished.end() &&
                      it->second <= t.time + 1e-12 && t.source != failure;
      unique       = unique && finished.count(t.target) == 0;
      const auto a = grid.index(t.target), b = grid.index(t.source);
      axis_neighbours =
        axis_neighbours &&
        std::abs(a[0] - b[0]) + std::abs(a[1] - b[1]) + std::abs(a[2] - b[2]) ==
          1;
      const auto x = hip(t.time), x0 = hip(t.time > 0 ? t.time - tick : 0.0);
      const palpate::Utilities::Point3 v{{(x[0] - x0[0]) / tick, 0, 0}};
      const auto                       path = scheduler.path_corners(x, v);
      in_cloud =
        in_cloud && (scheduler.in_cloud(t.target, x, v) ||
                     std::any_of(path.begin(), path.end(), [&](const auto &c) {
                       return c.first == t.target;
                     }));
      finished[t.target] = t.time + duration;
    }
  unsigned int failure_attempts = 0;
  for (const auto &t : tasks)
    failure_attempts += t.target == failure;
  deallog << "the 7 missing corners of the HIP's cell come first: "
          << (corners_first ? "yes" : "NO") << std::endl;
  deallog << "every source computed before its task, never a failure point: "
          << (sources_ready ? "yes" : "NO") << std::endl;
  deallog << "every source an axis neighbour of its target: "
          << (axis_neighbours ? "yes" : "NO") << std::endl;
  deallog << "no point scheduled twice: " << (unique ? "yes" : "NO")
          << "; the failure point was tried " << failure_attempts
          << " time(s) and is known as failed: "
          << (engine.knowledge(failure) == palpate::PointKnowledge::failed ?
                "yes" :
                "NO")
          << std::endl;
  deallog << "every target in the cloud or on the predicted path when its "
             "task started: "
          << (in_cloud ? "yes" : "NO") << std::endl;
  // A second run where the HIP jumps 3 cm at t = 0.2 s: the tasks queued
  // around the old position leave the cloud and are dropped, and the new
  // cloud is computed, reaching out from what exists.
  palpate::VirtualEngine jumper(grid, radius, look_ahead, 2, duration, tick);
  const auto             jump = [](const double t) {
    return palpate::Utilities::Point3{{t < 0.2 ? 0.0 : 0.03, 0, 0}};
  };
  const auto jump_tasks = jumper.run(jump, 2.0);
  grid.locate(jump(2.0), lower, local);
  bool reached = true;
  for (const unsigned int c : grid.corners(lower))
    reached = reached && jumper.knowledge(c) == palpate::PointKnowledge::source;
  deallog << "HIP jumping 3 cm: " << jump_tasks.size()
          << " tasks, queued tasks dropped when they "
          << "left the cloud: " << (jumper.n_dropped() > 0 ? "yes" : "NO")
          << ", the new cell is computed by t = 2 s: "
          << (reached ? "yes" : "NO") << std::endl;

  // A third run: the HIP rests at the origin behind a wall of failure
  // points (the plane i = 1): the cloud points beyond it cannot be reached
  // from inside the cloud, and no bridge may grow around them (a bridge
  // only ever steps toward the HIP).
  palpate::VirtualEngine walled(grid, radius, look_ahead, 2, duration, tick);
  std::set<unsigned int> wall;
  for (int j = -grid.half_width(); j <= grid.half_width(); ++j)
    for (int k = -grid.half_width(); k <= grid.half_width(); ++k)
      wall.insert(grid.linear({{1, j, k}}));
  walled.set_failure_points(wall);
  const auto rest = [](const double) {
    return palpate::Utilities::Point3{{0, 0, 0}};
  };
  const auto   wall_tasks = walled.run(rest, 2.0);
  unsigned int outside = 0, behind = 0, cloud_points = 0, failed = 0;
  for (const auto &t : wall_tasks)
    outside += !scheduler.in_cloud(t.target, {{0, 0, 0}}, {{0, 0, 0}});
  for (unsigned int p = 0; p < grid.size(); ++p)
    if (scheduler.in_cloud(p, {{0, 0, 0}}, {{0, 0, 0}}))
      {
        ++cloud_points;
        behind += grid.index(p)[0] > 1 &&
                  walled.knowledge(p) == palpate::PointKnowledge::unknown;
        failed += walled.knowledge(p) == palpate::PointKnowledge::failed;
      }
  deallog << "HIP behind a wall of failure points: " << cloud_points
          << " cloud points, " << wall_tasks.size() << " tasks (" << failed
          << " failed), " << outside << " outside the cloud, " << behind
          << " behind the wall left unknown" << std::endl;

  // States dropped for the memory budget: held states for i <= -1, the
  // plane i = 0 computed but no longer held, unknown beyond. The cloud
  // beyond can only be reached through i = 0: those points are planned
  // again (from their held neighbours), nothing beyond yet.
  const auto evicted = [&](const unsigned int p) {
    const int i = grid.index(p)[0];
    return i <= -1 ? palpate::PointKnowledge::source :
           i == 0  ? palpate::PointKnowledge::computed :
                     palpate::PointKnowledge::unknown;
  };
  const auto   replan = scheduler.plan({{0, 0, 0}}, {{0, 0, 0}}, evicted, 1000);
  unsigned int plane = 0, from_held = 0;
  for (const auto &t : replan)
    {
      plane += grid.index(t.target)[0] == 0;
      from_held += grid.index(t.source)[0] == -1;
    }
  deallog << "states dropped on the way: " << replan.size() << " planned, "
          << plane << " of them recomputations on the plane i = 0, "
          << from_held << " from held states" << std::endl;

  // Where the HIP is at the end, its cell is complete.
  grid.locate(hip(1.5), lower, local);
  bool complete = true;
  for (const unsigned int c : grid.corners(lower))
    complete =
      complete && engine.knowledge(c) == palpate::PointKnowledge::source;
  deallog << "the HIP's cell at t = 1.5 s is complete: "
          << (complete ? "yes" : "NO") << std::endl;
}
