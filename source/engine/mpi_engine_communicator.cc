// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

#include <palpate/base/environment.h>
#include <palpate/engine/mpi_engine_impl.h>
#include <palpate/engine/mpi_protocol.h>
#include <palpate/hyperelastic/state.h>

#include <algorithm>
#include <chrono>
#include <iomanip>
#include <mutex>
#include <sstream>
#include <thread>

namespace palpate
{
  using namespace MpiProtocol;
  using internal::Clock;
  using internal::send_heartbeats;
  using internal::send_shutdown;

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
          handle_result(from, h, message);
          break;
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
  MpiEngine::Impl::handle_result(const int                  from,
                                 const MpiProtocol::Header &h,
                                 const std::vector<char>   &message)
  {
    Server &server       = servers[from];
    server.messages_sent = h.messages_sent;
    server.bytes_sent    = h.bytes_sent;
    if (server.tasks.empty() || server.tasks.front() != h.point)
      return; // not what we asked it for (cannot happen)
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
        return;
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
        return;
      }
    const bool converged = h.flags & Flags::converged;
    if (h.generation != cache.generation())
      ++stats.discarded;
    else if (converged)
      {
        holders[h.point] |= bit(from);
        std::array<double, 9> stiffness;
        std::copy(h.stiffness, h.stiffness + 9, stiffness.begin());
        cache.publish_force(h.point,
                            {{h.force[0], h.force[1], h.force[2]}},
                            h.generation,
                            (h.flags & Flags::stiffness) ? &stiffness : nullptr,
                            (h.flags & Flags::patch) ? patch_of(message) :
                                                       nullptr);
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
} // namespace palpate
