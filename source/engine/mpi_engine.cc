// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

// The client side of the MPI engine (rank 0). See mpi_engine.h for the
// design, mpi_engine_impl.h for its pieces; the servers are in
// mpi_server.cc, the messages in mpi_protocol.h.

#include <palpate/base/exceptions.h>
#include <palpate/engine/mpi_engine.h>
#include <palpate/engine/mpi_engine_impl.h>
#include <palpate/engine/mpi_protocol.h>

#include <chrono>
#include <mutex>

namespace palpate
{
  using namespace MpiProtocol;
  using internal::Clock;
  using internal::send_shutdown;
  using internal::servers_released;

  namespace internal
  {
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
  } // namespace internal



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
