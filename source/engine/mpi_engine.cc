// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

// The client side of the MPI engine (rank 0). See mpi_engine.h for the
// design; the servers are in mpi_server.cc, the messages in
// mpi_protocol.h.

#include <palpate/base/environment.h>
#include <palpate/base/exceptions.h>
#include <palpate/engine/hip_channel.h>
#include <palpate/engine/mpi_engine.h>
#include <palpate/engine/mpi_protocol.h>
#include <palpate/engine/scheduler.h>
#include <palpate/hyperelastic/state.h>
#include <palpate/state_space/state_cache.h>
#include <palpate/state_space/state_grid.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <condition_variable>
#include <deque>
#include <iomanip>
#include <map>
#include <mutex>
#include <set>
#include <sstream>
#include <thread>

namespace palpate
{
  using namespace MpiProtocol;
  namespace
  {
    using Clock = std::chrono::steady_clock;

    // Whether some MpiEngine shut the servers down already (or there are
    // none): release_solver_servers() then has nothing to do.
    std::atomic<bool> servers_released{false};

    void
    send_shutdown(Messenger &messenger, const std::vector<bool> &lost)
    {
      Header h;
      h.kind = Kind::shutdown;
      for (const bool l : lost)
        if (l)
          h.flags |= Flags::peers_lost;
      for (int r = 1; r < messenger.size(); ++r)
        if (r >= static_cast<int>(lost.size()) || !lost[r])
          messenger.send(r, pack(h));
      // A lost server had its shutdown when it was lost (lose()); one
      // that is dead, or still stopped, may never take it, and the client
      // must not wait for it here.
      messenger.flush(5, lost);
      servers_released = true;
    }



    // Tell every ready server not lost that the client is alive, at most
    // every 0.1 s (a server that hears nothing from the client for Engine
    // / Server timeout ends: run_solver_server()).
    template <typename Servers>
    void
    send_heartbeats(Messenger         &messenger,
                    const Servers     &servers,
                    Clock::time_point &last)
    {
      if (Clock::now() - last < std::chrono::milliseconds(100))
        return;
      last = Clock::now();
      Header beat;
      beat.kind          = Kind::heartbeat;
      const auto message = pack(beat);
      for (unsigned int r = 1; r < servers.size(); ++r)
        if (servers[r].ready && !servers[r].lost)
          messenger.send(r, message);
    }
  } // namespace



  int
  mpi_rank()
  {
    int initialized = 0, rank = 0;
    MPI_Initialized(&initialized);
    if (initialized)
      MPI_Comm_rank(MPI_COMM_WORLD, &rank);
    return rank;
  }



  int
  mpi_size()
  {
    int initialized = 0, size = 1;
    MPI_Initialized(&initialized);
    if (initialized)
      MPI_Comm_size(MPI_COMM_WORLD, &size);
    return size;
  }



  void
  release_solver_servers()
  {
    if (servers_released.exchange(true) || mpi_rank() != client_rank ||
        mpi_size() < 2)
      return;
    Messenger messenger(MPI_COMM_WORLD);
    send_shutdown(messenger, {});
  }



  struct MpiEngine::Impl
  {
    Impl(const Parameters::AllParameters &p,
         const StateGrid                 &grid,
         StateCache                      &cache,
         const HipChannel                &hip)
      : parameters(p)
      , grid(grid)
      , cache(cache)
      , hip(hip)
      , scheduler(grid, p.scheduler.cloud_radius, p.scheduler.look_ahead_time)
      , messenger(MPI_COMM_WORLD)
      , origin(grid.linear({{0, 0, 0}}))
      , holders(grid.size(), 0)
      , in_progress(grid.size(), 0)
      , t0(Clock::now())
    {}

    /** One solver server, as the client sees it. */
    struct Server
    {
      bool ready = false, lost = false;
      // The targets it was given, in order: the first is being computed
      // (since task_start), the next waits on the server so that it never
      // idles for a round trip between two tasks.
      std::deque<unsigned int> tasks;
      Clock::time_point        task_start, last_heard;
      // Its counters, as it last reported them.
      std::uint64_t messages_sent = 0, bytes_sent = 0;
    };

    double
    now() const
    {
      return std::chrono::duration<double>(Clock::now() - t0).count();
    }

    std::uint64_t
    bit(const int rank) const
    {
      return std::uint64_t(1) << (rank - 1);
    }

    /** The scheduler's view of a point (call with the mutex held). */
    PointKnowledge
    knowledge(const unsigned int p) const
    {
      return point_knowledge(in_progress[p] != 0,
                             cache.status(p),
                             holders[p] != 0);
    }

    void
    wait_for_servers();

    /** The communicator thread: communicate(), and whatever it throws
     * ends the engine through shut_down_after_error(). */
    void
    loop();

    void
    communicate();

    void
    shut_down_after_error(const std::string &what);

    void
    handle(const int from, const std::vector<char> &message);

    void
    plan_and_dispatch();

    void
    lose(const int rank, const std::string &why);

    void
    fetch_wanted_states();

    /** Send Kind::cancel for the running or queued tasks the HIP has moved
     * away from (cancel_limit). */
    void
    cancel_left_behind();

    /** Send Kind::cancel for every running or queued task (a stop signal:
     * abandon_running()). */
    void
    cancel_every_task();

    /** With @p waiting corners of the HIP's path that found no free
     * server: cancel as many running tasks that are no such corner, the
     * farthest from the path first (as the thread engine does); and the
     * running task of each server in @p queued_corners, which has a
     * corner in its second place, unless it is a corner itself. */
    void
    preempt_for_path_corners(const unsigned int       waiting,
                             const std::vector<int>  &queued_corners,
                             const Utilities::Point3 &position,
                             const Utilities::Point3 &velocity);

    Parameters::AllParameters parameters;
    const StateGrid          &grid;
    StateCache               &cache;
    const HipChannel         &hip;
    Scheduler                 scheduler;
    Messenger                 messenger;
    const unsigned int        origin;
    std::vector<Server>       servers; // by rank; [0] unused
    std::string               linear_solver;
    // The rest state's stiffness, from the servers' ready messages.
    std::array<double, 9> rest_stiffness     = {};
    bool                  has_rest_stiffness = false;
    /** The rest state's contact patch (Interpolation = contact patch). */
    std::shared_ptr<const ContactPatch> rest_patch;

    // Which servers hold the whole state of each point (bit r-1 for rank
    // r), and which server computes it (its rank, or 0).
    std::vector<std::uint64_t> holders;
    // A stop signal: cancel every task (abandon_running()).
    std::atomic<bool> abandoning{false};
    std::vector<int>  in_progress;
    // For each dispatched task: the distance from the HIP's predicted path
    // beyond which it is cancelled (left_behind()), and whether the cancel
    // was sent.
    std::map<unsigned int, std::pair<double, bool>> cancel_limit;
    // The points whose cancel was a preemption (counted apart).
    std::set<unsigned int> preempted_points;
    // States the client asked for (lazy transfer to the shape output):
    // when, and from whom.
    std::map<unsigned int, std::pair<Clock::time_point, int>> requested;

    mutable std::mutex      mutex;
    std::condition_variable stopped;
    std::atomic<bool>       attached{false}, quit{false};
    /** A server silent past its heartbeats, or one lost within the last
     * 3 s (degraded()); and when the last one was lost. */
    std::atomic<bool> trouble{false};
    /** Every server lost (lost_every_worker()). */
    std::atomic<bool> all_lost{false};
    Clock::time_point last_loss{};
    unsigned int      busy            = 0;
    bool              nothing_to_plan = false, replan = false;
    std::uint64_t     finished = 0, finished_at_plan = 0;
    BridgeMemory      bridge;
    Clock::time_point next_tick;
    std::thread       thread;
    Clock::time_point t0;
    EngineStatistics  stats;
  };



  void
  MpiEngine::Impl::wait_for_servers()
  {
    servers.assign(messenger.size(), Server());
    // Each server builds the mesh and its solver as the client did; a
    // large mesh takes a while, a server that never reports is lost.
    const auto        deadline = Clock::now() + std::chrono::seconds(600);
    unsigned int      ready    = 0;
    std::vector<char> message;
    Clock::time_point last_beat{};
    while (ready + 1 < servers.size())
      {
        send_heartbeats(messenger, servers, last_beat);
        int from = 0;
        if (messenger.receive(from, message))
          {
            const Header h = header_of(message);
            if (h.kind != Kind::ready || servers[from].ready)
              continue;
            if (h.flags & Flags::error)
              {
                std::vector<bool> lost(servers.size(), false);
                send_shutdown(messenger, lost);
                throw std::runtime_error(
                  "MPI solver server " + std::to_string(from) +
                  " could not set up its solver: " + h.text);
              }
            servers[from].ready      = true;
            servers[from].last_heard = Clock::now();
            linear_solver            = h.text;
            if (h.flags & Flags::stiffness)
              {
                std::copy(h.stiffness, h.stiffness + 9, rest_stiffness.begin());
                has_rest_stiffness = true;
              }
            if (h.flags & Flags::patch)
              rest_patch = patch_of(message);
            ++ready;
          }
        else if (Clock::now() > deadline)
          {
            std::vector<bool> lost(servers.size(), false);
            send_shutdown(messenger, lost);
            throw std::runtime_error(
              "MPI engine: only " + std::to_string(ready) + " of " +
              std::to_string(servers.size() - 1) +
              " solver servers reported ready within 600 s");
          }
        else
          std::this_thread::sleep_for(std::chrono::microseconds(500));
      }
    // The rest state is known everywhere without computing.
    for (unsigned int r = 1; r < servers.size(); ++r)
      holders[origin] |= bit(r);
  }



  void
  MpiEngine::Impl::lose(const int rank, const std::string &why)
  {
    Server &s = servers[rank];
    if (s.lost)
      return;
    s.lost    = true;
    last_loss = Clock::now();
    Environment::peer_lost();
    std::ostringstream what;
    what << "solver server " << rank << " lost at t = " << std::fixed
         << std::setprecision(2) << now() << " s: " << why;
    if (!s.tasks.empty())
      {
        what << "; its task" << (s.tasks.size() > 1 ? "s" : "")
             << " (grid point";
        for (const unsigned int t : s.tasks)
          {
            what << " " << t;
            in_progress[t] = 0;
            cancel_limit.erase(t);
            preempted_points.erase(t);
            --busy;
            ++finished;
          }
        what << ") planned again";
        s.tasks.clear();
      }
    unsigned int orphans = 0;
    for (auto &h : holders)
      if (h & bit(rank))
        {
          h &= ~bit(rank);
          orphans += (h == 0);
        }
    if (orphans > 0)
      what << "; " << orphans
           << " states only it held are recomputed when needed";
    stats.lost_servers.push_back(what.str());
    replan        = true;
    bool any_left = false;
    for (unsigned int r = 1; r < servers.size(); ++r)
      any_left = any_left || !servers[r].lost;
    all_lost.store(!any_left, std::memory_order_relaxed);
    // It is told to go at once: a server that was only stopped (SIGSTOP,
    // a machine that froze) and comes back reads this first and exits,
    // instead of waiting for a client that no longer talks to it, which
    // kept mpirun from ever returning. The client never waits for this
    // send to complete (send_shutdown skips lost ranks).
    {
      Header h;
      h.kind = Kind::shutdown;
      h.flags |= Flags::peers_lost;
      messenger.send(rank, pack(h));
    }
    // The survivors stop waiting for what they asked of it.
    for (unsigned int r = 1; r < servers.size(); ++r)
      if (!servers[r].lost)
        {
          Header h;
          h.kind   = Kind::peer_lost;
          h.holder = rank;
          messenger.send(r, pack(h));
        }
  }



  void
  MpiEngine::Impl::handle(const int from, const std::vector<char> &message)
  {
    if (from <= 0 || from >= static_cast<int>(servers.size()) ||
        servers[from].lost)
      return; // a lost server's late words are not trusted
    Server &server    = servers[from];
    server.last_heard = Clock::now();
    const Header h    = header_of(message);
    switch (h.kind)
      {
        case Kind::heartbeat:
          server.messages_sent = h.messages_sent;
          server.bytes_sent    = h.bytes_sent;
          break;
        case Kind::dropped:
          holders[h.point] &= ~bit(from);
          // No server holds it any more: unless this process does, it is
          // gone (a store waiting for it stops waiting).
          if (holders[h.point] == 0)
            cache.mark_dropped(h.point);
          break;
        case Kind::result:
          {
            server.messages_sent = h.messages_sent;
            server.bytes_sent    = h.bytes_sent;
            if (server.tasks.empty() || server.tasks.front() != h.point)
              break; // not what we asked it for (cannot happen)
            const double start =
              std::chrono::duration<double>(server.task_start - t0).count();
            server.tasks.pop_front();
            server.task_start    = Clock::now(); // the next one starts now
            in_progress[h.point] = 0;
            --busy;
            ++finished;
            replan = true;
            if (h.flags & Flags::source_missing)
              {
                // The holder dropped it (or died) after the plan: not a
                // failure point, just plan again without that holder.
                holders[h.source] &= ~(h.source == origin ? 0 : bit(h.holder));
                break;
              }
            if (h.flags & Flags::fetched_source)
              {
                ++stats.fetched_sources;
                stats.transfer_seconds.push_back(h.fetch_seconds);
                holders[h.source] |= bit(from);
              }
            cancel_limit.erase(h.point);
            if (static_cast<SolveStatus>(h.status) == SolveStatus::stopped)
              {
                // Cancelled (the HIP moved away) or preempted: nothing
                // learnt.
                ++(preempted_points.erase(h.point) > 0 ? stats.preempted :
                                                         stats.cancelled);
                stats.busy_time += h.duration;
                break;
              }
            const bool converged = h.flags & Flags::converged;
            if (h.generation != cache.generation())
              ++stats.discarded;
            else if (converged)
              {
                holders[h.point] |= bit(from);
                std::array<double, 9> stiffness;
                std::copy(h.stiffness, h.stiffness + 9, stiffness.begin());
                cache.publish_force(
                  h.point,
                  {{h.force[0], h.force[1], h.force[2]}},
                  h.generation,
                  (h.flags & Flags::stiffness) ? &stiffness : nullptr,
                  (h.flags & Flags::patch) ? patch_of(message) : nullptr);
                ++stats.computed;
              }
            else
              {
                // A solve that threw reports "converged" as its status:
                // count it with the solver's failures.
                const auto reason = static_cast<SolveStatus>(h.status);
                cache.publish_failure(h.point,
                                      h.generation,
                                      reason == SolveStatus::converged ?
                                        SolveStatus::linear_solver_failure :
                                        reason);
                ++stats.failed;
              }
            if (h.flags & Flags::error)
              {
                ++stats.errors;
                stats.last_error = h.text;
              }
            stats.busy_time += h.duration;
            stats.tasks.push_back({h.point,
                                   h.source,
                                   start,
                                   h.duration,
                                   converged,
                                   static_cast<SolveStatus>(h.status),
                                   h.newton_iterations,
                                   static_cast<unsigned int>(from)});
            break;
          }
        case Kind::state:
          {
            const auto r = requested.find(h.point);
            if (r == requested.end())
              break;
            stats.transfer_seconds.push_back(
              std::chrono::duration<double>(Clock::now() - r->second.first)
                .count());
            ++stats.states_to_client;
            requested.erase(r);
            auto state = std::make_shared<State>(state_of(message));
            cache.publish(h.point, std::move(state), h.generation);
            break;
          }
        case Kind::state_missing:
          holders[h.point] &= ~(h.point == origin ? 0 : bit(from));
          requested.erase(h.point);
          break;
        default:
          break;
      }
  }



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
        // Among the places of the least loaded servers (an idle server
        // never waits while another gets a second task), one whose server
        // holds the source.
        const std::size_t depth = servers[free.front()].tasks.size();
        const auto last = std::find_if(free.begin(), free.end(), [&](int r) {
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
            continue;
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
    preempt_for_path_corners(corners_waiting,
                             queued_corners,
                             position,
                             velocity);
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



  void
  MpiEngine::Impl::loop()
  {
    // The communicator must not take the process down while a device
    // renders forces: whatever it throws ends the distributed engine
    // cleanly (every server counted lost, with the reason, and released
    // at the end); the interaction goes on with what is cached.
    try
      {
        communicate();
      }
    catch (const std::exception &e)
      {
        shut_down_after_error(e.what());
      }
    catch (...)
      {
        shut_down_after_error("an exception of unknown type");
      }
  }



  void
  MpiEngine::Impl::shut_down_after_error(const std::string &what)
  {
    std::lock_guard<std::mutex> lock(mutex);
    ++stats.errors;
    stats.last_error = "MPI communicator thread: " + what;
    for (unsigned int r = 1; r < servers.size(); ++r)
      lose(r, "the client's communicator thread failed (" + what + ")");
    quit = true;
    stopped.notify_all();
  }



  void
  MpiEngine::Impl::communicate()
  {
    const auto period = std::chrono::duration_cast<Clock::duration>(
      std::chrono::duration<double>(1.0 / parameters.scheduler.rate));
    next_tick = Clock::now();
    std::vector<char> message;
    Clock::time_point last_beat{};
    while (!quit)
      {
        bool activity = false;
        {
          std::lock_guard<std::mutex> lock(mutex);
          send_heartbeats(messenger, servers, last_beat);
          int from = 0;
          while (messenger.receive(from, message))
            {
              activity = true;
              handle(from, message);
            }
          fetch_wanted_states();

          // Liveness: silence, or a task that never ends.
          const auto t       = Clock::now();
          bool       silence = false;
          for (unsigned int r = 1; r < servers.size(); ++r)
            {
              Server &s = servers[r];
              if (s.lost)
                continue;
              const double silent =
                std::chrono::duration<double>(t - s.last_heard).count();
              // Heartbeats come every 0.1 s: three missed is trouble long
              // before Engine / Server timeout declares the server lost.
              silence = silence || (s.ready && silent > 0.3);
              if (silent > parameters.engine.server_timeout)
                lose(r,
                     "it sent nothing for " + Utilities::to_string(silent, 3) +
                       " s (Engine / Server timeout)");
              else if (!s.tasks.empty() &&
                       std::chrono::duration<double>(t - s.task_start).count() >
                         parameters.engine.task_timeout)
                lose(r,
                     "its task ran longer than Engine / Task timeout (" +
                       Utilities::to_string(parameters.engine.task_timeout, 3) +
                       " s): it hung, or a state on this mesh takes longer "
                       "than that (then raise Task timeout above the longest "
                       "state time)");
            }

          trouble.store(
            silence ||
              (last_loss != Clock::time_point{} &&
               std::chrono::duration<double>(t - last_loss).count() < 3.0),
            std::memory_order_relaxed);

          if (attached && (replan || t >= next_tick))
            {
              cancel_left_behind();
              plan_and_dispatch();
              if (t >= next_tick)
                next_tick = std::max(next_tick + period, t);
            }
          // After abandon_running(), attached or not (stop() waits for
          // the cancelled tasks' answers).
          if (abandoning.exchange(false))
            cancel_every_task();
          if (!attached && busy == 0)
            stopped.notify_all();
        }
        messenger.progress();
        if (!activity)
          std::this_thread::sleep_for(std::chrono::microseconds(500));
      }
  }



  MpiEngine::MpiEngine(const Parameters::AllParameters &parameters,
                       const StateGrid                 &grid,
                       StateCache                      &cache,
                       const HipChannel                &hip)
    : impl(std::make_unique<Impl>(parameters, grid, cache, hip))
  {
    Impl &s = *impl;
    if (s.messenger.size() > 65)
      {
        send_shutdown(s.messenger, {});
        throw NotAvailableError(
          "The MPI engine with " + std::to_string(s.messenger.size() - 1) +
            " solver servers,",
          "Run it with at most 64 servers (mpirun -np 65 or fewer).");
      }
    s.wait_for_servers();
    servers_released = false;
    s.thread         = std::thread([&s] { s.loop(); });
  }



  MpiEngine::~MpiEngine()
  {
    Impl &s = *impl;
    stop();
    s.quit = true;
    if (s.thread.joinable())
      s.thread.join();
    std::vector<bool> lost(s.servers.size(), false);
    for (unsigned int r = 1; r < s.servers.size(); ++r)
      lost[r] = s.servers[r].lost;
    send_shutdown(s.messenger, lost);
  }



  void
  MpiEngine::start()
  {
    Impl &s = *impl;
    if (s.attached)
      return;
    // The rest state is known without computing: the origin of the grid.
    if (s.cache.status(s.origin) != PointStatus::available)
      s.cache.publish_force(s.origin,
                            {{0, 0, 0}},
                            s.cache.generation(),
                            s.has_rest_stiffness ? &s.rest_stiffness : nullptr,
                            s.rest_patch);
    std::lock_guard<std::mutex> lock(s.mutex);
    s.nothing_to_plan = false;
    s.replan          = true;
    s.bridge.reset();
    s.attached = true;
  }



  void
  MpiEngine::stop()
  {
    Impl                        &s = *impl;
    std::unique_lock<std::mutex> lock(s.mutex);
    if (!s.attached)
      return;
    s.attached = false;
    // Running tasks finish (their servers may also be lost meanwhile).
    s.stopped.wait(lock, [&s] { return s.busy == 0; });
  }



  void
  MpiEngine::abandon_running()
  {
    impl->abandoning.store(true);
  }



  bool
  MpiEngine::running() const
  {
    return impl->attached.load();
  }



  void
  MpiEngine::change_parameters(const Parameters::AllParameters &)
  {
    throw NotAvailableError(
      "Changing the parameters during an interaction with Engine / Type = "
      "mpi,",
      "Restart palpate with the new scene, or use Engine / Type = threads.");
  }



  bool
  MpiEngine::idle() const
  {
    std::lock_guard<std::mutex> lock(impl->mutex);
    return impl->busy == 0 && impl->nothing_to_plan && !impl->replan &&
           impl->finished_at_plan == impl->finished;
  }



  EngineStatistics
  MpiEngine::statistics() const
  {
    const Impl                 &s = *impl;
    std::lock_guard<std::mutex> lock(s.mutex);
    EngineStatistics            e = s.stats;
    e.messages                    = s.messenger.messages_sent;
    e.bytes                       = s.messenger.bytes_sent;
    for (unsigned int r = 1; r < s.servers.size(); ++r)
      {
        e.messages += s.servers[r].messages_sent;
        e.bytes += s.servers[r].bytes_sent;
      }
    return e;
  }



  EngineLoad
  MpiEngine::load() const
  {
    const Impl                 &s = *impl;
    std::lock_guard<std::mutex> lock(s.mutex);
    EngineLoad                  l;
    for (std::size_t r = 1; r < s.servers.size(); ++r) // servers not lost
      l.workers += !s.servers[r].lost;
    l.busy      = s.busy;
    l.computed  = s.stats.computed;
    l.failed    = s.stats.failed;
    l.busy_time = s.stats.busy_time;
    // With the running tasks' time so far: a task longer than a live view's
    // sampling interval still shows as busy.
    const auto now = Clock::now();
    for (std::size_t r = 1; r < s.servers.size(); ++r)
      if (!s.servers[r].lost && !s.servers[r].tasks.empty())
        l.busy_time +=
          std::chrono::duration<double>(now - s.servers[r].task_start).count();
    for (unsigned int p = 0; p < s.in_progress.size(); ++p)
      if (s.in_progress[p] != 0)
        l.in_progress.push_back(p);
    return l;
  }



  unsigned int
  MpiEngine::n_workers() const
  {
    return impl->servers.size() - 1;
  }



  bool
  MpiEngine::degraded() const noexcept
  {
    return impl->trouble.load(std::memory_order_relaxed);
  }



  bool
  MpiEngine::lost_every_worker() const noexcept
  {
    return impl->all_lost.load(std::memory_order_relaxed);
  }



  std::string
  MpiEngine::description() const
  {
    const unsigned int n = n_workers();
    return std::to_string(n) + " MPI solver server" + (n > 1 ? "s" : "") +
           " (1 solver thread each), " + impl->linear_solver;
  }
} // namespace palpate
