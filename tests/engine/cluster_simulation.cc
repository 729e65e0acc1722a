// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

// The virtual-time cluster simulation against a schedule computed by hand.
//
// Set-up: a 5 mm grid (points -2..2 per axis, numbered i fastest, so that
// (i, j, k) has number (i + 2) + 5 (j + 2) + 25 (k + 2)), a cloud of radius
// 4.5 mm and no look-ahead (the cloud around a cell centre is exactly the
// cell's 8 corners, all of them corners: they are ordered by grid number),
// 2 servers, every solve 100 ms, the scheduler at 100 Hz, latency 1 ms,
// notifications of 0 bytes, states of 1000 bytes over 1 MB/s (a state
// message takes 1 ms + 1 ms). A task therefore takes, from the decision
// at t: 1 ms for the notification, 3 ms more if the server must fetch the
// source (request 1 ms, state message 2 ms), 100 ms of solve, 1 ms for the
// result; the server is free for the next decision at that moment.
//
// The HIP rests at the centre of the cell (0,0,0)-(1,1,1); the motion,
// from t = 0.5 s, is a jump to the centre of the next cell along +x, which
// the scheduler sees at its next tick, t = 0.51 s.
//
//   t = 0      (1,0,0) (0,1,0) (0,0,1) have a source (the rest state, on
//              every server): (1,0,0) -> S0, (0,1,0) -> S1; (0,0,1) waits.
//   t = 0.102  both results in. (1,1,0) from (1,0,0) [S0 holds it; the tie
//              with (0,1,0) goes to the lower number] -> S0;
//              (0,0,1) from rest -> S1. (1,0,1), (0,1,1) wait.
//   t = 0.204  (1,0,1) from (1,0,0) [tie with (0,0,1), lower number] -> S0;
//              (0,1,1) from (0,1,0) -> S1, which holds it.
//   t = 0.306  (1,1,1) from (1,1,0) [lowest of three] -> S0, which holds it.
//              Result at 0.408: the cloud is complete.
//   t = 0.51   after the jump: (2,0,0) from (1,0,0) -> S0 (holder);
//              (2,1,0) from (1,1,0): S0 is taken, S1 fetches it (3 ms):
//              solve 0.514 - 0.614, result at 0.615.
//   t = 0.612  S0 is back: (2,0,1) from (2,0,0) [tie with (1,0,1)] -> S0;
//              (2,1,1) waits (its only source is (1,1,1), S1 is busy).
//   t = 0.615  (2,1,1) from (2,1,0) [tie with (1,1,1)] -> S1, which holds
//              it. Result at 0.717.
// No transfer except the one at t = 0.51 (7 transfers avoided: tasks whose
// source, not the rest state, the server held). While the HIP moves (0.5 -
// 0.8 s) two points are planned when no server is free for them, (2,0,1)
// and (2,1,1) (at most 2 at once), and the HIP's cell misses corners from
// the haptic tick after 0.5 s until 0.717 s: one
// missing-data event of 216 haptic ticks (0.216 s). At most 2 servers
// busy.
//
// With unlimited servers the first three tasks start at once on 3 servers;
// at 0.102 (1,0,1) and (0,1,1) go to the servers that are free (1 and 2),
// which fetch their sources (3 ms); after the jump the four new corners
// start at once (peak 4 busy, 3 of them fetching).
//
// The test checks every task (target, source, server, decision time,
// transfer, start, finish, arrival) against this table, the counters and
// the busy curve; the log shows the schedule.

#include <palpate/engine/cluster_simulation.h>

#include <cmath>

#include "../tests.h"

namespace
{
  struct Expected
  {
    palpate::GridIndex target, source;
    unsigned int       server;
    double             assigned, transfer;
  };
} // namespace

int
main(int argc, char **argv)
{
  palpate::Environment env(argc, argv);
  initlog();

  const palpate::StateGrid             grid(0.005, 0.01);
  palpate::ClusterSimulation::Settings settings;
  settings.cloud_radius               = 0.0045;
  settings.look_ahead_time            = 0;
  settings.scheduler_rate             = 100;
  settings.servers                    = 2;
  settings.state_bytes                = 1000;
  settings.network.latency            = 0.001;
  settings.network.bandwidth          = 1e6;
  settings.network.notification_bytes = 0;

  palpate::ClusterSimulation::Motion motion;
  motion.path = [](const double tau) {
    return palpate::Utilities::Point3{
      {tau > 0 ? 0.0075 : 0.0025, 0.0025, 0.0025}};
  };
  motion.start    = 0.5;
  motion.duration = 0.3;

  const auto name = [&](const unsigned int p) {
    const auto g = grid.index(p);
    return "(" + std::to_string(g[0]) + "," + std::to_string(g[1]) + "," +
           std::to_string(g[2]) + ")";
  };
  const auto show = [&](const palpate::ClusterSimulation::Result &r) {
    for (const auto &t : r.tasks)
      deallog << "  " << std::setprecision(4) << t.assigned << ": "
              << name(t.target) << " <- " << name(t.source) << ", server "
              << t.server << ", transfer " << t.transfer << " s, solve "
              << t.start << " - " << t.finish << ", result at " << t.arrived
              << std::endl;
  };

  const palpate::ClusterSimulation simulation(
    grid, settings, palpate::TaskDurations::fixed(0.1));
  const auto r = simulation.run(motion, 0.2);
  deallog << "2 servers: " << r.tasks.size() << " tasks" << std::endl;
  show(r);

  const std::vector<Expected> hand = {
    {{{1, 0, 0}}, {{0, 0, 0}}, 0, 0.0, 0},
    {{{0, 1, 0}}, {{0, 0, 0}}, 1, 0.0, 0},
    {{{1, 1, 0}}, {{1, 0, 0}}, 0, 0.102, 0},
    {{{0, 0, 1}}, {{0, 0, 0}}, 1, 0.102, 0},
    {{{1, 0, 1}}, {{1, 0, 0}}, 0, 0.204, 0},
    {{{0, 1, 1}}, {{0, 1, 0}}, 1, 0.204, 0},
    {{{1, 1, 1}}, {{1, 1, 0}}, 0, 0.306, 0},
    {{{2, 0, 0}}, {{1, 0, 0}}, 0, 0.51, 0},
    {{{2, 1, 0}}, {{1, 1, 0}}, 1, 0.51, 0.003},
    {{{2, 0, 1}}, {{2, 0, 0}}, 0, 0.612, 0},
    {{{2, 1, 1}}, {{2, 1, 0}}, 1, 0.615, 0}};
  bool matches = r.tasks.size() == hand.size();
  for (unsigned int k = 0; matches && k < hand.size(); ++k)
    {
      const auto  &t = r.tasks[k];
      const auto  &e = hand[k];
      const double start =
        e.assigned + 0.001 + e.transfer; // notification, then the fetch
      matches = matches && t.target == grid.linear(e.target) &&
                t.source == grid.linear(e.source) && t.server == e.server &&
                std::abs(t.assigned - e.assigned) < 1e-9 &&
                std::abs(t.transfer - e.transfer) < 1e-9 &&
                std::abs(t.start - start) < 1e-9 &&
                std::abs(t.finish - (start + 0.1)) < 1e-9 &&
                std::abs(t.arrived - (start + 0.101)) < 1e-9 && !t.failed;
    }
  deallog << "matches the hand-computed schedule: " << (matches ? "yes" : "NO")
          << std::endl;
  deallog << "transfers " << r.transfers << ", avoided " << r.transfers_avoided
          << "; servers used " << r.servers_used << ", peak busy "
          << r.peak_busy(0, 1) << std::endl;
  deallog << "motion " << r.motion_start << " - " << r.motion_end
          << " s: points that waited " << r.waited << " (at most "
          << r.max_waiting << " tasks), missing-data events "
          << r.missing_events << " (" << std::setprecision(4)
          << r.missing_seconds << " s)" << std::endl;
  deallog << "initial cloud: " << r.initial_cloud_states << " states"
          << std::endl;
  deallog << "busy servers (time s: count):";
  for (const auto &[time, count] : r.busy)
    deallog << " " << std::setprecision(4) << time << ":" << count;
  deallog << std::endl;

  // Unlimited servers: as many as are ever needed at once.
  settings.servers = 0;
  const palpate::ClusterSimulation unlimited(
    grid, settings, palpate::TaskDurations::fixed(0.1));
  const auto u = unlimited.run(motion, 0.2);
  deallog << "unlimited servers: " << u.tasks.size() << " tasks, "
          << u.servers_used << " servers used, peak busy while moving "
          << u.peak_busy(u.motion_start, u.motion_end)
          << ", points that waited " << u.waited << ", missing-data events "
          << u.missing_events << " (" << u.missing_seconds << " s)"
          << std::endl;
  show(u);

  // The cloud-start rule: with start < 0 the motion begins when the
  // initial cloud is complete (result at 0.408 s, the next decision is at
  // that instant).
  settings.servers = 2;
  motion.start     = -1;
  const palpate::ClusterSimulation after_cloud(
    grid, settings, palpate::TaskDurations::fixed(0.1));
  const auto a = after_cloud.run(motion, 0.2);
  deallog << "motion after the initial cloud: starts at " << a.motion_start
          << " s after " << a.initial_cloud_states << " states" << std::endl;

  // Sampled durations depend on the task only: two simulations with
  // different server counts give each task the same time.
  const auto sampled = palpate::TaskDurations::sampled({0.1, 0.2, 0.3}, 7);
  bool       same    = true;
  for (unsigned int p = 0; p < 20; ++p)
    same = same && sampled(p, p + 1) == sampled(p, p + 1) &&
           (sampled(p, p + 1) == 0.1 || sampled(p, p + 1) == 0.2 ||
            sampled(p, p + 1) == 0.3);
  deallog << "sampled durations: deterministic and from the list: "
          << (same ? "yes" : "NO") << ", mean " << sampled.mean() << std::endl;
}
