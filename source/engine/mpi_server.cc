// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

// A solver server of the MPI engine (ranks 1..N-1). Two threads, as in the
// paper's Fig. 2:
// - the solver thread computes one task at a time, start to end;
// - the communicator (this process's main thread) is the only thread that
//   calls MPI for palpate: it receives tasks and requests, answers
//   requests for states this server holds while the solver is busy,
//   fetches remote sources for the solver, and sends results, drops and
//   heartbeats. MUMPS runs on MPI_COMM_SELF in the solver thread at the
//   same time, which is why palpate asks for MPI_THREAD_MULTIPLE.

#include <palpate/base/environment.h>
#include <palpate/engine/mpi_engine.h>
#include <palpate/engine/mpi_protocol.h>
#include <palpate/hyperelastic/state_solver.h>
#include <palpate/scene/scene.h>
#include <palpate/state_space/state_grid.h>

#include <sys/resource.h>
#include <sys/syscall.h>
#include <sys/types.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <condition_variable>
#include <csignal>
#include <cstring>
#include <deque>
#include <iostream>
#include <map>
#include <memory>
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

    using Utilities::seconds_since;

    // Freeze this process for @p seconds as a stopped machine would (every
    // thread, heartbeats included), for tests: a child that touches
    // nothing of MPI's resumes it. With @p seconds = 0 nothing resumes it:
    // the test sends SIGCONT when what it checks has happened.
    void
    pause_for(const double seconds)
    {
      const pid_t me = getpid();
      if (seconds > 0 && fork() == 0)
        {
          const timespec t{static_cast<time_t>(seconds),
                           static_cast<long>((seconds - std::floor(seconds)) *
                                             1e9)};
          nanosleep(&t, nullptr);
          kill(me, SIGCONT);
          _exit(0);
        }
      std::raise(SIGSTOP);
    }

    std::size_t
    bytes_of(const State &s)
    {
      return sizeof(State) +
             (s.solution.size() + s.multipliers.size()) * sizeof(double) +
             (s.contact_patch ? s.contact_patch->memory() : 0);
    }

    /**
     * What the two threads of a server share, under one mutex.
     */
    struct Shared
    {
      std::mutex              mutex;
      std::condition_variable wake_solver;
      std::deque<Header>      tasks;
      bool                    stop = false;

      // The states this server holds, and their bytes; the origin's rest
      // state is always held and never counted.
      std::map<unsigned int, std::shared_ptr<const State>> store;
      std::size_t                                          bytes = 0;

      // Remote sources. The communicator requests a task's source from
      // its holder as soon as the task arrives (prefetch: it is usually
      // here before the solver finishes the task ahead of it); the solver
      // asks for one itself only if that failed or it was dropped since.
      // requested: in flight, by point; to_request: asked by the solver,
      // not sent yet; failed: the holder did not have it; transferred:
      // arrived from another server, not yet reported to the client.
      std::map<unsigned int, int>              requested;
      std::deque<std::pair<unsigned int, int>> to_request;
      std::set<unsigned int>                   failed, transferred;

      // Points whose tasks the client cancelled (Kind::cancel): the
      // running solve stops at its next Newton iteration, a queued one
      // ends at once; both report SolveStatus::stopped.
      std::set<unsigned int> cancelled;
      // The point being solved now (~0u: none).
      unsigned int solving = ~0u;

      // Messages the solver thread wants sent (the communicator sends).
      std::deque<std::pair<Header, std::shared_ptr<const State>>> outbox;
    };
  } // namespace



  namespace
  {
    /**
     * One solver server: set up, then a solver thread and a communicator
     * (this thread) until the client says shutdown or is lost. The steps
     * are named as in run(); what the two threads share is `shared`, under
     * its mutex.
     */
    class SolverServer
    {
    public:
      SolverServer(const Scene         &scene,
                   const Mesh          &mesh,
                   const NodeSelection &nodes,
                   const ServerFaults  &faults)
        : messenger(MPI_COMM_WORLD)
        , p(scene.parameters)
        , mesh(mesh)
        , nodes(nodes)
        , faults(faults)
        , grid(p.state_space.grid_spacing, p.state_space.extent)
        , origin(grid.linear({{0, 0, 0}}))
        , budget(static_cast<std::size_t>(p.engine.memory_budget * 1048576.0))
      {}

      /** The server's whole life; run_solver_server() returns it. */
      int
      run()
      {
        if (!set_up())
          return 1;
        std::thread solver_thread([this] { solve_tasks(); });
        const bool  client_lost = !communicate();
        {
          std::lock_guard<std::mutex> lock(shared.mutex);
          shared.stop = true;
          shared.wake_solver.notify_all();
        }
        solver_thread.join();
        if (client_lost)
          return 2;
        messenger.flush(5);
        return 0;
      }

    private:
      /** Build the solver and the rest state, and tell the client (its
       * linear solver, or why it failed: the client tells the user). */
      bool
      set_up();

      /** The solver thread: one task at a time, until shutdown. */
      void
      solve_tasks();

      /** A task's source state: the rest state, one held here, or one
       * fetched from its holder through the communicator (null if it did
       * not come). Sets result's fetch time and flags. */
      std::shared_ptr<const State>
      source_of(const Header                 &task,
                Header                       &result,
                std::unique_lock<std::mutex> &lock);

      /** Solve @p task from @p source, with the lock released (the
       * communicator answers requests meanwhile, and may cancel it); keep
       * a converged state and put the result in the outbox. */
      void
      solve(const Header                       &task,
            const std::shared_ptr<const State> &source,
            Header                             &result,
            std::unique_lock<std::mutex>       &lock);

      /** Over budget: drop the states farthest from @p target (the HIP is
       * near it) but @p keep, and tell the client. Under the lock. */
      void
      keep_within_budget(const unsigned int       keep,
                         const Utilities::Point3 &target);

      /** The communicator: receive, send what the solver thread wants
       * sent, beat, until shutdown (true) or the client is lost (false). */
      bool
      communicate();

      /** Act on one message from @p from; false on shutdown. */
      bool
      handle(const int from, const std::vector<char> &message);

      /** A state this server asked another for (Kind::state), or its
       * holder's word that it has none (Kind::state_missing). */
      void
      take_state(const Header &h, const std::vector<char> &message);

      /** Send the solver thread's requests, results and drops; whether
       * there were any. */
      bool
      send_outbox();

      /** Whether the client has been silent too long (and say so). */
      bool
      client_silent();

      /** The whole state of point @p q if this server holds it (the rest
       * state always), else null. Under the lock. */
      std::shared_ptr<const State>
      held(const unsigned int q) const
      {
        if (q == origin)
          return rest;
        const auto i = shared.store.find(q);
        return i == shared.store.end() ? std::shared_ptr<const State>() :
                                         i->second;
      }

      /** Ask the communicator to request point @p q from @p holder, unless
       * it is on its way already. Under the lock. */
      void
      request(const unsigned int q, const int holder)
      {
        if (lost_peers.count(holder))
          {
            shared.failed.insert(q); // it will not come
            return;
          }
        if (shared.requested.count(q))
          return;
        shared.failed.erase(q);
        shared.requested[q] = holder;
        shared.to_request.emplace_back(q, holder);
      }

      Messenger                        messenger;
      const Parameters::AllParameters &p;
      const Mesh                      &mesh;
      const NodeSelection             &nodes;
      const ServerFaults               faults;
      const StateGrid                  grid;
      const unsigned int               origin;
      const std::size_t                budget;

      std::unique_ptr<StateSolver> solver;
      std::shared_ptr<const State> rest;
      Shared                       shared;
      // Servers the client said were lost (Kind::peer_lost); under
      // shared.mutex.
      std::set<int> lost_peers;

      // The communicator's own.
      Clock::time_point last_heartbeat = Clock::now() - std::chrono::seconds(1);
      unsigned int      tasks_received = 0;
      // The client's words (its heartbeats come every 0.1 s once its
      // engine runs). Before the first, the client may still be setting up
      // (reading a store, solving references): it has as long as it gives
      // servers to report ready.
      Clock::time_point last_from_client  = Clock::now();
      bool              heard_from_client = false;
      // The communicator's last turn, and the longest time this process
      // stood still between two (s).
      Clock::time_point last_loop   = Clock::now();
      double            stalled_for = 0;
    };



    bool
    SolverServer::set_up()
    {
      Header ready;
      ready.kind = Kind::ready;
      try
        {
          solver = std::make_unique<StateSolver>(mesh, nodes, p);
          rest   = std::make_shared<const State>(solver->rest_state());
          ready.set_text(solver->linear_solver_name() + ", Newton steps " +
                         (solver->settings().reuse_factorization ?
                            "by GMRES on a kept factorisation" :
                            "with a factorisation each"));
          if (rest->has_stiffness)
            {
              // The client publishes the rest state itself.
              ready.flags |= Flags::stiffness;
              for (unsigned int d = 0; d < 9; ++d)
                ready.stiffness[d] = rest->stiffness[d];
            }
        }
      catch (const std::exception &e)
        {
          ready.flags = Flags::error;
          ready.set_text(e.what());
        }
      // The rest state's contact patch rides on it (the client publishes
      // the rest state itself).
      if (!(ready.flags & Flags::error) && rest && rest->contact_patch)
        {
          ready.flags |= Flags::patch;
          messenger.send(client_rank, pack(ready, *rest->contact_patch));
        }
      else
        messenger.send(client_rank, pack(ready));
      if (!solver)
        messenger.flush(5);
      return solver != nullptr;
    }



    void
    SolverServer::solve_tasks()
    {
      // Below the client's haptic thread when they share a machine.
      setpriority(PRIO_PROCESS, static_cast<id_t>(syscall(SYS_gettid)), 10);
      std::unique_lock<std::mutex> lock(shared.mutex);
      while (true)
        {
          shared.wake_solver.wait(lock, [&] {
            return shared.stop || !shared.tasks.empty();
          });
          if (shared.stop)
            return;
          const Header task = shared.tasks.front();
          shared.tasks.pop_front();

          Header result;
          result.kind       = Kind::result;
          result.point      = task.point;
          result.source     = task.source;
          result.holder     = task.holder;
          result.generation = task.generation;

          // Cancelled while it waited here: it ends at once.
          if (shared.cancelled.erase(task.point) > 0)
            {
              result.status = static_cast<std::int32_t>(SolveStatus::stopped);
              shared.outbox.emplace_back(result, nullptr);
              continue;
            }
          const std::shared_ptr<const State> source =
            source_of(task, result, lock);
          if (shared.stop)
            return;
          if (!source)
            {
              result.flags |= Flags::source_missing;
              shared.outbox.emplace_back(result, nullptr);
              continue;
            }
          solve(task, source, result, lock);
        }
    }



    std::shared_ptr<const State>
    SolverServer::source_of(const Header                 &task,
                            Header                       &result,
                            std::unique_lock<std::mutex> &lock)
    {
      std::shared_ptr<const State> source = held(task.source);
      if (!source && task.holder != messenger.rank())
        {
          const auto asked = Clock::now();
          request(task.source, task.holder);
          // The holder answers within a round trip; a holder that died
          // never does, and the task then ends as source_missing for the
          // client to plan again.
          shared.wake_solver.wait_for(lock, std::chrono::seconds(10), [&] {
            return shared.stop || shared.store.count(task.source) ||
                   shared.failed.count(task.source);
          });
          if (shared.stop)
            return nullptr;
          shared.failed.erase(task.source);
          shared.requested.erase(task.source);
          source               = held(task.source);
          result.fetch_seconds = seconds_since(asked);
        }
      if (source && shared.transferred.erase(task.source) > 0)
        result.flags |= Flags::fetched_source;
      return source;
    }



    void
    SolverServer::solve(const Header                       &task,
                        const std::shared_ptr<const State> &source,
                        Header                             &result,
                        std::unique_lock<std::mutex>       &lock)
    {
      // The states behind the source on the same grid line, if held here
      // (they are not fetched), make Newton's start second- or third-order.
      std::shared_ptr<const State> behind, behind2;
      if (unsigned int b = 0;
          task.source != origin && grid.behind(task.source, task.point, b))
        {
          behind = held(b);
          if (unsigned int bb = 0;
              behind && b != origin && grid.behind(b, task.source, bb))
            behind2 = held(bb);
        }

      shared.solving = task.point;
      lock.unlock();
      const Utilities::Point3 target{
        {task.position[0], task.position[1], task.position[2]}};
      const auto start = Clock::now();
      State      state;
      solver->set_stop_check([this, point = task.point] {
        std::lock_guard<std::mutex> guard(shared.mutex);
        return shared.stop || shared.cancelled.count(point) > 0;
      });
      try
        {
          state = solver->solve(*source, target, behind.get(), behind2.get());
          // As ThreadEngine's workers do: a point around rest that failed
          // from its neighbour is solved again from rest, the path on
          // which a sphere's offered radius was tried.
          if (!state.converged && state.status != SolveStatus::stopped &&
              task.source != origin && grid.beside_origin(task.point))
            state = solver->solve(*rest, target);
        }
      catch (const std::exception &e)
        {
          state.converged = false;
          result.flags |= Flags::error;
          result.set_text(e.what());
        }
      result.duration          = seconds_since(start);
      result.status            = static_cast<std::int32_t>(state.status);
      result.newton_iterations = state.newton_iterations;
      lock.lock();
      shared.solving = ~0u;
      shared.cancelled.erase(task.point);

      if (state.converged)
        {
          result.flags |= Flags::converged;
          for (unsigned int d = 0; d < 3; ++d)
            result.force[d] = state.force[d];
          if (state.has_stiffness)
            {
              result.flags |= Flags::stiffness;
              for (unsigned int d = 0; d < 9; ++d)
                result.stiffness[d] = state.stiffness[d];
            }
          state.history.clear();
          state.history.shrink_to_fit();
          auto kept = std::make_shared<const State>(std::move(state));
          shared.bytes += bytes_of(*kept);
          shared.store[task.point] = kept;
          // The contact patch goes with the result: the haptic loop
          // solves against it at every tick.
          if (kept->contact_patch)
            {
              result.flags |= Flags::patch;
              shared.outbox.emplace_back(result, std::move(kept));
              keep_within_budget(task.point, target);
              return;
            }
        }
      shared.outbox.emplace_back(result, nullptr);
      keep_within_budget(task.point, target);
    }



    void
    SolverServer::keep_within_budget(const unsigned int       keep,
                                     const Utilities::Point3 &target)
    {
      if (shared.bytes <= budget)
        return;
      std::vector<std::pair<double, unsigned int>> by_distance;
      for (const auto &s : shared.store)
        if (s.first != keep)
          by_distance.emplace_back(Utilities::distance(grid.position(s.first),
                                                       target),
                                   s.first);
      std::sort(by_distance.begin(), by_distance.end());
      while (shared.bytes > 0.9 * budget && !by_distance.empty())
        {
          const unsigned int q = by_distance.back().second;
          by_distance.pop_back();
          shared.bytes -= bytes_of(*shared.store[q]);
          shared.store.erase(q);
          Header dropped;
          dropped.kind  = Kind::dropped;
          dropped.point = q;
          shared.outbox.emplace_back(dropped, nullptr);
        }
    }



    bool
    SolverServer::communicate()
    {
      std::vector<char> message;
      while (true)
        {
          // A loop that took seconds means this process itself was
          // stopped (SIGSTOP, a frozen machine): remembered for the
          // message if the client then seems silent.
          if (const double gap = seconds_since(last_loop); gap > 1)
            stalled_for = gap;
          last_loop     = Clock::now();
          bool activity = false;
          int  from     = 0;
          while (messenger.receive(from, message))
            {
              activity = true;
              if (!handle(from, message))
                return true; // shutdown
            }
          activity = send_outbox() || activity;
          if (seconds_since(last_heartbeat) >= 0.1)
            {
              Header beat;
              beat.kind          = Kind::heartbeat;
              beat.messages_sent = messenger.messages_sent + 1;
              beat.bytes_sent    = messenger.bytes_sent + sizeof(Header);
              messenger.send(client_rank, pack(beat));
              last_heartbeat = Clock::now();
            }
          if (client_silent())
            return false;
          messenger.progress();
          // Polling every millisecond costs the solver thread (which may
          // share the core) little and delays a reply by at most that; the
          // client keeps a second task waiting here, so the solver never
          // waits for the communicator between two tasks.
          if (!activity)
            std::this_thread::sleep_for(std::chrono::milliseconds(1));
        }
    }



    bool
    SolverServer::handle(const int from, const std::vector<char> &message)
    {
      const Header h = header_of(message);
      if (from == client_rank)
        {
          last_from_client  = Clock::now();
          heard_from_client = true;
        }
      switch (h.kind)
        {
          case Kind::task:
            {
              ++tasks_received;
              if (faults.die_after_tasks > 0 &&
                  tasks_received >= faults.die_after_tasks)
                std::raise(SIGKILL); // a crashed machine, for tests
              if (faults.pause_after_tasks > 0 &&
                  tasks_received == faults.pause_after_tasks)
                pause_for(faults.pause_seconds); // a frozen one
              std::lock_guard<std::mutex> lock(shared.mutex);
              shared.tasks.push_back(h);
              shared.wake_solver.notify_all();
              // Prefetch its source from the server that holds it.
              if (h.holder != messenger.rank() && !held(h.source))
                request(h.source, h.holder);
              break;
            }
          case Kind::request_state:
            {
              std::shared_ptr<const State> s;
              {
                std::lock_guard<std::mutex> lock(shared.mutex);
                s = held(h.point);
              }
              Header reply = h;
              reply.kind   = s ? Kind::state : Kind::state_missing;
              reply.holder = messenger.rank();
              messenger.send(from, s ? pack(reply, *s) : pack(reply));
              break;
            }
          case Kind::state:
          case Kind::state_missing:
            take_state(h, message);
            break;
          case Kind::peer_lost:
            {
              // Sources asked of the lost server never come: the tasks
              // waiting for them end as source_missing now, and the client
              // plans them from another source.
              std::lock_guard<std::mutex> lock(shared.mutex);
              lost_peers.insert(h.holder);
              for (auto it = shared.requested.begin();
                   it != shared.requested.end();)
                if (it->second == h.holder)
                  {
                    shared.failed.insert(it->first);
                    it = shared.requested.erase(it);
                  }
                else
                  ++it;
              shared.wake_solver.notify_all();
              break;
            }
          case Kind::cancel:
            {
              // Only a task this server has (queued or running): a cancel
              // that crossed the result on the way is moot.
              std::lock_guard<std::mutex> lock(shared.mutex);
              const bool queued = std::any_of(shared.tasks.begin(),
                                              shared.tasks.end(),
                                              [&](const Header &t) {
                                                return t.point == h.point;
                                              });
              if (queued || shared.solving == h.point)
                shared.cancelled.insert(h.point);
              break;
            }
          case Kind::shutdown:
            if (h.flags & Flags::peers_lost)
              Environment::peer_lost();
            return false;
          case Kind::heartbeat: // the client is alive
          default:
            break;
        }
      return true;
    }



    void
    SolverServer::take_state(const Header &h, const std::vector<char> &message)
    {
      std::lock_guard<std::mutex> lock(shared.mutex);
      if (!shared.requested.erase(h.point))
        return; // not asked for (any more)
      if (h.kind == Kind::state)
        {
          if (!shared.store.count(h.point))
            {
              auto s = std::make_shared<const State>(state_of(message));
              shared.bytes += bytes_of(*s);
              shared.store[h.point] = std::move(s);
            }
          shared.transferred.insert(h.point);
        }
      else
        shared.failed.insert(h.point);
      shared.wake_solver.notify_all();
    }



    bool
    SolverServer::send_outbox()
    {
      std::unique_lock<std::mutex> lock(shared.mutex);
      for (const auto &[point, holder] : shared.to_request)
        {
          Header request;
          request.kind  = Kind::request_state;
          request.point = point;
          if (!messenger.send(holder, pack(request)))
            {
              shared.requested.erase(point);
              shared.failed.insert(point);
              shared.wake_solver.notify_all();
            }
        }
      shared.to_request.clear();
      auto outbox = std::move(shared.outbox);
      shared.outbox.clear();
      lock.unlock();
      for (auto &[h, s] : outbox)
        {
          // The counters ride on every result: the client adds up the
          // traffic of all ranks.
          std::vector<char> message =
            (h.flags & Flags::patch) && s && s->contact_patch ?
              pack(h, *s->contact_patch) :
              pack(h);
          h.messages_sent = messenger.messages_sent + 1;
          h.bytes_sent    = messenger.bytes_sent + message.size();
          std::memcpy(message.data(), &h, sizeof(Header));
          messenger.send(client_rank, std::move(message));
        }
      return !outbox.empty();
    }



    bool
    SolverServer::client_silent()
    {
      // A client that went silent was killed, or is cut off: nobody will
      // ever read what this server computes, and under mpirun
      // --enable-recovery nobody else ends it.
      const double silent = seconds_since(last_from_client);
      if (silent <= (heard_from_client ? p.engine.server_timeout : 600.0))
        return false;
      // One write for the whole message: two servers that end at once
      // wrote theirs piece by piece through mpirun, and the pieces mixed
      // (engine/mpi_client_loss counted one message of two).
      std::ostringstream message;
      if (stalled_for >= 0.5 * silent)
        // This process stood still (SIGSTOP, a frozen machine): the client
        // is fine, and has declared this server lost meanwhile.
        message << "\npalpate (solver server, MPI rank " << messenger.rank()
                << "): this server stood still for "
                << Utilities::to_string(stalled_for, 3)
                << " s (stopped with SIGSTOP, or frozen), longer than "
                   "Engine / Server timeout: the client has declared it "
                   "lost meanwhile, and it ends.\n";
      else
        message << "\npalpate (solver server, MPI rank " << messenger.rank()
                << "): the client (rank " << client_rank
                << ") sent nothing for " << Utilities::to_string(silent, 3)
                << " s ("
                << (heard_from_client ?
                      "Engine / Server timeout" :
                      "since this server was ready; it has 600 s")
                << "): it is lost (killed, or cut off), and this server "
                   "ends.\n";
      std::cerr << message.str() << std::flush;
      Environment::peer_lost();
      return true;
    }
  } // namespace



  int
  run_solver_server(const Scene         &scene,
                    const Mesh          &mesh,
                    const NodeSelection &nodes,
                    const ServerFaults  &faults)
  {
    SolverServer server(scene, mesh, nodes, faults);
    return server.run();
  }
} // namespace palpate
