// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

#include <palpate/engine/mpi_engine_impl.h>
#include <palpate/engine/mpi_protocol.h>

#include <algorithm>
#include <chrono>

namespace palpate
{
  using namespace MpiProtocol;
  using internal::Clock;

  void
  MpiEngine::Impl::cancel_left_behind()
  {
    Utilities::Point3 position, velocity;
    hip.read(position, velocity);
    for (auto &[point, limit] : cancel_limit)
      if (!limit.second && in_progress[point] != 0 &&
          scheduler.distance_to_path(grid.position(point), position, velocity) >
            limit.first)
        {
          Header h;
          h.kind  = Kind::cancel;
          h.point = point;
          // Not sent (the server is being lost): its result never comes
          // either, and lose() plans the point again.
          limit.second = messenger.send(in_progress[point], pack(h));
        }
  }



  void
  MpiEngine::Impl::cancel_every_task()
  {
    for (unsigned int p = 0; p < in_progress.size(); ++p)
      if (in_progress[p] != 0 && !cancel_limit[p].second)
        {
          Header h;
          h.kind                 = Kind::cancel;
          h.point                = p;
          cancel_limit[p].second = messenger.send(in_progress[p], pack(h));
        }
  }



  void
  MpiEngine::Impl::fetch_wanted_states()
  {
    for (const unsigned int p : cache.take_wanted())
      {
        if (requested.count(p) || holders[p] == 0)
          continue; // asked already, or nobody has it (recomputed later)
        int holder = 0;
        for (unsigned int r = 1; r < servers.size() && holder == 0; ++r)
          if ((holders[p] & bit(r)) && !servers[r].lost)
            holder = r;
        if (holder == 0)
          continue;
        Header request;
        request.kind       = Kind::request_state;
        request.point      = p;
        request.generation = cache.generation();
        if (messenger.send(holder, pack(request)))
          requested[p] = {Clock::now(), holder};
      }
  }



  void
  MpiEngine::Impl::plan_and_dispatch()
  {
    Utilities::Point3 position, velocity;
    hip.read(position, velocity);
    cache.set_focus(position);
    GridIndex             cell;
    std::array<double, 3> local;
    grid.locate(position, cell, local);

    // Idle servers first, then each server's second place.
    std::vector<int> free;
    for (const unsigned int depth : {0u, 1u})
      for (unsigned int r = 1; r < servers.size(); ++r)
        if (servers[r].ready && !servers[r].lost &&
            servers[r].tasks.size() <= depth)
          free.push_back(r);
    const unsigned int alive =
      std::count_if(servers.begin() + 1, servers.end(), [](const Server &s) {
        return !s.lost;
      });

    const bool allow_bridge = bridge.allowed(finished, cell);
    const auto plan         = scheduler.plan(
      position,
      velocity,
      [this](const unsigned int p) { return knowledge(p); },
      2 * std::max(1u, alive),
      allow_bridge);
    bridge.planned(plan.empty(), allow_bridge, finished, cell);
    nothing_to_plan  = plan.empty();
    finished_at_plan = finished;
    replan           = false;

    // Most urgent first; each to a free server that holds its source if
    // there is one (no transfer), else to the first free server, told
    // which server to fetch the source from. Corners of the HIP's path
    // that find no free server preempt running tasks (below).
    unsigned int     corners_waiting = 0;
    std::vector<int> queued_corners; // servers with a corner in second place
    for (const Task &task : plan)
      {
        if (free.empty())
          {
            corners_waiting +=
              task.corner && schedulable(knowledge(task.target));
            continue;
          }
        if (!schedulable(knowledge(task.target)) || holders[task.source] == 0)
          continue;
        send_task(task, free, queued_corners, position, velocity);
      }
    preempt_for_path_corners(corners_waiting,
                             queued_corners,
                             position,
                             velocity);
  }



  void
  MpiEngine::Impl::send_task(const Task              &task,
                             std::vector<int>        &free,
                             std::vector<int>        &queued_corners,
                             const Utilities::Point3 &position,
                             const Utilities::Point3 &velocity)
  {
    // Among the places of the least loaded servers (an idle server
    // never waits while another gets a second task), one whose server
    // holds the source.
    const std::size_t depth = servers[free.front()].tasks.size();
    const auto        last = std::find_if(free.begin(), free.end(), [&](int r) {
      return servers[r].tasks.size() > depth;
    });
    // Best of all, one that also holds the state behind the source on
    // the same grid line: its solve then starts from a second-order
    // extrapolation (StateSolver::solve with behind).
    unsigned int  b           = 0;
    std::uint64_t with_behind = 0;
    if (grid.behind(task.source, task.target, b))
      with_behind = holders[b];
    auto chosen = std::find_if(free.begin(), last, [&](int r) {
      return (holders[task.source] & with_behind & bit(r)) != 0;
    });
    if (chosen == last)
      chosen = std::find_if(free.begin(), last, [&](int r) {
        return (holders[task.source] & bit(r)) != 0;
      });
    const bool local = chosen != last;
    if (!local)
      chosen = free.begin();
    const int rank   = *chosen;
    int       holder = rank;
    if (!local)
      for (unsigned int r = 1; r < servers.size(); ++r)
        if ((holders[task.source] & bit(r)) && !servers[r].lost)
          {
            holder = r;
            break;
          }
    Header h;
    h.kind       = Kind::task;
    h.point      = task.target;
    h.source     = task.source;
    h.holder     = holder;
    h.generation = cache.generation();
    const auto x = grid.position(task.target);
    for (unsigned int d = 0; d < 3; ++d)
      h.position[d] = x[d];
    if (!messenger.send(rank, pack(h)))
      {
        lose(rank, "MPI could not send it a task");
        free.erase(chosen);
        return;
      }
    if (local && task.source != origin)
      ++stats.local_sources;
    Server &s = servers[rank];
    if (s.tasks.empty())
      s.task_start = Clock::now();
    else if (task.corner)
      queued_corners.push_back(rank); // behind the task it runs
    s.tasks.push_back(task.target);
    in_progress[task.target] = rank;
    // Cancelled once farther from the predicted path than the cloud
    // reaches, and than now, each by two grid spacings (as the thread
    // engine's workers do).
    cancel_limit[task.target] = {
      std::max(parameters.scheduler.cloud_radius,
               scheduler.distance_to_path(x, position, velocity)) +
        2 * grid.spacing(),
      false};
    ++busy;
    free.erase(chosen);
  }



  void
  MpiEngine::Impl::preempt_for_path_corners(
    const unsigned int       waiting,
    const std::vector<int>  &queued_corners,
    const Utilities::Point3 &position,
    const Utilities::Point3 &velocity)
  {
    if (waiting == 0 && queued_corners.empty())
      return;
    const auto corners = scheduler.path_corners(position, velocity);
    const auto corner  = [&](const unsigned int p) {
      return std::binary_search(corners.begin(),
                                corners.end(),
                                std::make_pair(p, 0.0),
                                [](const auto &a, const auto &b) {
                                  return a.first < b.first;
                                });
    };
    const auto cancel = [&](const unsigned int p) {
      preempted_points.insert(p);
      Header h;
      h.kind  = Kind::cancel;
      h.point = p;
      if (messenger.send(in_progress[p], pack(h)))
        cancel_limit[p].second = true;
    };
    // A corner queued behind a task that is none: that task goes.
    for (const int r : queued_corners)
      {
        const unsigned int p = servers[r].tasks.front();
        if (!corner(p) && !cancel_limit[p].second)
          cancel(p);
      }
    if (waiting == 0)
      return;
    // Corners that found no server: the running tasks (each server's
    // first) that are no corner and not cancelled yet, the farthest from
    // the path first.
    std::vector<std::pair<double, unsigned int>> victims; // (distance, point)
    unsigned int                                 freeing = 0;
    for (unsigned int r = 1; r < servers.size(); ++r)
      {
        const Server &s = servers[r];
        if (s.lost || s.tasks.empty())
          continue;
        const unsigned int p     = s.tasks.front();
        const auto         limit = cancel_limit.find(p);
        if (limit != cancel_limit.end() && limit->second.second)
          {
            ++freeing;
            continue;
          }
        if (corner(p))
          continue;
        victims.emplace_back(
          scheduler.distance_to_path(grid.position(p), position, velocity), p);
      }
    std::sort(victims.rbegin(), victims.rend());
    for (unsigned int k = 0; k + freeing < waiting && k < victims.size(); ++k)
      cancel(victims[k].second);
  }

} // namespace palpate
