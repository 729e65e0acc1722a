// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

// A running state the HIP has moved away from is given up (issue 25: on a
// real organ a state takes seconds, in which a hand moves centimetres, and
// a worker that finishes it is a worker missing where the hand is now).
// The threaded engine on the paper's liver, each state made slow (40
// increments, about half a second):
// - the HIP moves 4 mm within its cell while states run (less than two grid
// spacings
//   beyond the cloud): nothing is cancelled;
// - the HIP jumps 9 cm away: the states running near rest are cancelled
//   within a Newton iteration (the workers free in well under the time a
//   state takes); a cancelled state is neither a state nor a failure point
//   (the cache holds only converged states, no failure point), and it is
//   counted as cancelled, not failed;
// - preemption: with both workers on states of the cloud and the HIP
//   moving on to cells whose corners are not computed yet (they wait in
//   the queue: corners of the cells on the predicted path come first), a
//   running state that is no such corner is given up for them, sooner
//   than a state's time, and the HIP's new cell gets its corners.

#include <palpate/engine/hip_channel.h>
#include <palpate/engine/scheduler.h>
#include <palpate/engine/thread_engine.h>
#include <palpate/mesh/mesh.h>
#include <palpate/mesh/node_selection.h>
#include <palpate/state_space/state_cache.h>
#include <palpate/state_space/state_grid.h>

#include <chrono>
#include <thread>

#include "../tests.h"

namespace
{
  using Clock = std::chrono::steady_clock;

  /** Wait at most @p seconds for @p done(); the seconds it took, or -1. */
  template <typename Predicate>
  double
  wait_for(const Predicate &done, const double seconds)
  {
    const auto start = Clock::now();
    while (!done())
      {
        const double t =
          std::chrono::duration<double>(Clock::now() - start).count();
        if (t > seconds)
          return -1;
        std::this_thread::sleep_for(std::chrono::milliseconds(2));
      }
    return std::chrono::duration<double>(Clock::now() - start).count();
  }
} // namespace

int
main(int argc, char **argv)
{
  palpate::Environment env(argc, argv);
  initlog();

  palpate::Scene scene            = shipped_scene("paper-stvk.prm");
  auto          &p                = scene.parameters;
  p.nonlinear_solver.n_increments = 40;
  p.engine.workers                = 2;
  const Body            body(scene);
  palpate::StateGrid    grid(p.state_space.grid_spacing, p.state_space.extent);
  palpate::StateCache   cache(grid, 1 << 28);
  palpate::HipChannel   hip;
  palpate::ThreadEngine engine(body.mesh, body.nodes, p, grid, cache, hip);

  engine.start();
  // Both workers on the cloud around rest.
  const bool busy = wait_for([&] { return engine.load().busy == 2; }, 60) >= 0;
  {
    // 4 mm, inside the cell the rest position is located in (its corners
    // were computed first): a move that leaves no corner of the HIP's cell
    // waiting, so that nothing is preempted either.
    palpate::GridIndex    rest_cell;
    std::array<double, 3> local;
    grid.locate({{0, 0, 0}}, rest_cell, local);
    palpate::Utilities::Point3 centre = grid.position(rest_cell);
    for (auto &c : centre)
      c += 0.5 * grid.spacing();
    const double n = palpate::Utilities::norm(centre);
    hip.write(
      {{0.004 * centre[0] / n, 0.004 * centre[1] / n, 0.004 * centre[2] / n}},
      {{0, 0, 0}});
  }
  // Until a few states are computed there (however slow the machine is:
  // the time of a state is measured from them below).
  wait_for([&] { return engine.statistics().computed >= 4; }, 300);
  const auto near = engine.statistics();
  deallog << "both workers busy: " << ok(busy)
          << "; the HIP moves 4 mm: nothing cancelled "
          << ok(near.cancelled == 0) << ", states still computed "
          << ok(near.computed > 0) << std::endl;

  // The time one state takes here (the median of those computed).
  std::vector<double> durations;
  for (const auto &t : near.tasks)
    if (t.converged)
      durations.push_back(t.duration);
  std::sort(durations.begin(), durations.end());
  const double state_time =
    durations.empty() ? 0 : durations[durations.size() / 2];

  // Away: the running states are left behind.
  wait_for([&] { return engine.load().busy == 2; }, 60);
  const unsigned int before = engine.statistics().cancelled;
  hip.write({{0, 0, -0.09}}, {{0, 0, 0}});
  const double freed =
    wait_for([&] { return engine.statistics().cancelled >= before + 1; }, 60);
  engine.stop();
  const auto stats = engine.statistics();
  // A worker sees the cancellation between two Newton iterations: it is
  // free sooner than a state's time, which a worker that ignored the
  // cancel would need (the bound is logical, not a speed: a fraction of it
  // depends on how loaded the machine is).
  deallog << "the HIP jumps 9 cm away: running states cancelled "
          << ok(stats.cancelled >= 1) << ", sooner than a state's time "
          << ok(freed >= 0 && freed < state_time) << std::endl;
  deallog << "no failure point published " << ok(cache.counts().second == 0)
          << ", none counted " << ok(stats.failed == 0)
          << ", every cached state converged ";
  bool converged = true;
  for (unsigned int q = 0; q < grid.size(); ++q)
    if (const auto s = cache.state(q))
      converged = converged && s->converged;
  deallog << ok(converged) << std::endl;
  std::cout << "state time " << state_time << " s, freed after " << freed
            << " s, cancelled " << stats.cancelled << std::endl;

  // Preemption for the corners on the HIP's path.
  {
    palpate::StateCache      cache(grid, 1 << 28);
    palpate::HipChannel      hip;
    palpate::ThreadEngine    engine(body.mesh, body.nodes, p, grid, cache, hip);
    const palpate::Scheduler scheduler(grid,
                                       p.scheduler.cloud_radius,
                                       p.scheduler.look_ahead_time);
    // Where the HIP goes: 7.5 mm along x, moving on at 10 mm/s.
    const palpate::Utilities::Point3 x{{0.0075, 0.0025, 0.0025}},
      v{{0.01, 0, 0}};
    const auto path    = scheduler.path_corners(x, v);
    const auto on_path = [&](const unsigned int q) {
      for (const auto &c : path)
        if (c.first == q)
          return true;
      return false;
    };
    engine.start();
    // Until both workers solve states of the cloud that are not corners
    // of the cells on that path.
    const bool ready = wait_for(
                         [&] {
                           const auto l = engine.load();
                           if (l.in_progress.size() != 2)
                             return false;
                           for (const unsigned int q : l.in_progress)
                             if (on_path(q))
                               return false;
                           return true;
                         },
                         120) >= 0;
    hip.write(x, v);
    const double preempted =
      wait_for([&] { return engine.statistics().preempted >= 1; }, 60);
    palpate::GridIndex    cell;
    std::array<double, 3> local;
    grid.locate(x, cell, local);
    const double corners = wait_for(
      [&] {
        for (const unsigned int c : grid.corners(cell))
          if (cache.status(c) != palpate::PointStatus::available)
            return false;
        return true;
      },
      120);
    engine.stop();
    deallog << "preemption: both workers on cloud states off the new path "
            << ok(ready) << "; the HIP moves on: a running state given up "
            << ok(preempted >= 0 && preempted < state_time)
            << ", the HIP's new cell complete " << ok(corners >= 0)
            << ", no failure point " << ok(cache.counts().second == 0)
            << std::endl;
    std::cout << "preempted after " << preempted << " s, cell complete after "
              << corners << " s" << std::endl;
  }
}
