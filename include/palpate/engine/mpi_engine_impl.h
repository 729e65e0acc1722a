// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

#ifndef palpate_engine_mpi_engine_impl_h
#define palpate_engine_mpi_engine_impl_h

// Not an interface: the client side of the MPI engine (rank 0, MpiEngine),
// shared by its source files, one job each:
//   mpi_engine.cc               the engine's members as its users call
//                               them, and the MPI process's (ranks, the
//                               servers' release)
//   mpi_engine_communicator.cc  the communicator thread: the servers'
//                               start, their messages, their liveness,
//                               and losing one
//   mpi_engine_dispatch.cc      what the servers compute: the plan, the
//                               tasks sent, cancelled and preempted, the
//                               states fetched for the client
// The servers are in mpi_server.cc, the messages in mpi_protocol.h. Users
// of the engine include mpi_engine.h, never this header.

#include <palpate/engine/hip_channel.h>
#include <palpate/engine/mpi_engine.h>
#include <palpate/engine/mpi_protocol.h>
#include <palpate/engine/scheduler.h>
#include <palpate/state_space/state_cache.h>
#include <palpate/state_space/state_grid.h>

#include <array>
#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <deque>
#include <map>
#include <memory>
#include <mutex>
#include <set>
#include <string>
#include <thread>
#include <vector>

namespace palpate
{
  namespace internal
  {
    using Clock = std::chrono::steady_clock;

    /** Whether some MpiEngine shut the servers down already (or there are
     * none): release_solver_servers() then has nothing to do. */
    extern std::atomic<bool> servers_released;

    /** Tell every server not in @p lost to shut down, and wait (a little)
     * for the messages to leave. */
    void
    send_shutdown(MpiProtocol::Messenger  &messenger,
                  const std::vector<bool> &lost);

    // Tell every ready server not lost that the client is alive, at most
    // every 0.1 s (a server that hears nothing from the client for Engine
    // / Server timeout ends: run_solver_server()).
    template <typename Servers>
    void
    send_heartbeats(MpiProtocol::Messenger &messenger,
                    const Servers          &servers,
                    Clock::time_point      &last)
    {
      if (Clock::now() - last < std::chrono::milliseconds(100))
        return;
      last = Clock::now();
      MpiProtocol::Header beat;
      beat.kind          = MpiProtocol::Kind::heartbeat;
      const auto message = MpiProtocol::pack(beat);
      for (unsigned int r = 1; r < servers.size(); ++r)
        if (servers[r].ready && !servers[r].lost)
          messenger.send(r, message);
    }
  } // namespace internal



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
      , t0(internal::Clock::now())
    {}

    /** One solver server, as the client sees it. */
    struct Server
    {
      bool ready = false, lost = false;
      // The targets it was given, in order: the first is being computed
      // (since task_start), the next waits on the server so that it never
      // idles for a round trip between two tasks.
      std::deque<unsigned int>    tasks;
      internal::Clock::time_point task_start, last_heard;
      // Its counters, as it last reported them.
      std::uint64_t messages_sent = 0, bytes_sent = 0;
    };

    double
    now() const
    {
      return std::chrono::duration<double>(internal::Clock::now() - t0).count();
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

    /** A server's result (Kind::result, header @p h) for the task it was
     * given first: published to the cache, counted, and the server's next
     * task started (call with the mutex held). */
    void
    handle_result(const int                  from,
                  const MpiProtocol::Header &h,
                  const std::vector<char>   &message);

    void
    plan_and_dispatch();

    /** Send @p task to one of the @p free servers (taken from them): one
     * that holds its source if there is one, else the first, told where to
     * fetch the source; a server with a path corner queued second is added
     * to @p queued_corners. */
    void
    send_task(const Task              &task,
              std::vector<int>        &free,
              std::vector<int>        &queued_corners,
              const Utilities::Point3 &position,
              const Utilities::Point3 &velocity);

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
    MpiProtocol::Messenger    messenger;
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
    std::map<unsigned int, std::pair<internal::Clock::time_point, int>>
      requested;

    mutable std::mutex      mutex;
    std::condition_variable stopped;
    std::atomic<bool>       attached{false}, quit{false};
    /** A server silent past its heartbeats, or one lost within the last
     * 3 s (degraded()); and when the last one was lost. */
    std::atomic<bool> trouble{false};
    /** Every server lost (lost_every_worker()). */
    std::atomic<bool>           all_lost{false};
    internal::Clock::time_point last_loss{};
    unsigned int                busy            = 0;
    bool                        nothing_to_plan = false, replan = false;
    std::uint64_t               finished = 0, finished_at_plan = 0;
    BridgeMemory                bridge;
    internal::Clock::time_point next_tick;
    std::thread                 thread;
    internal::Clock::time_point t0;
    EngineStatistics            stats;
  };
} // namespace palpate

#endif
