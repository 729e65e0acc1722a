// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

#include <palpate/base/exceptions.h>
#include <palpate/engine/hip_channel.h>
#include <palpate/engine/scheduler.h>
#include <palpate/engine/thread_engine.h>
#include <palpate/hyperelastic/state_solver.h>
#include <palpate/mesh/mesh.h>
#include <palpate/mesh/node_selection.h>
#include <palpate/scene/scene.h>
#include <palpate/state_space/state_cache.h>
#include <palpate/state_space/state_grid.h>

#include <sys/resource.h>
#include <sys/syscall.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <condition_variable>
#include <deque>
#include <mutex>
#include <set>
#include <string>
#include <thread>

namespace palpate
{
  using Clock = std::chrono::steady_clock;

  struct ThreadEngine::Impl
  {
    Impl(const Mesh                      &mesh,
         const NodeSelection             &nodes,
         const Parameters::AllParameters &p,
         const StateGrid                 &grid,
         StateCache                      &cache,
         const HipChannel                &hip)
      : mesh(mesh)
      , nodes(nodes)
      , parameters(p)
      , grid(grid)
      , cache(cache)
      , hip(hip)
      , scheduler(grid, p.scheduler.cloud_radius, p.scheduler.look_ahead_time)
      , in_progress(grid.size(), 0)
    {
      build_solvers();
    }

    void
    build_solvers()
    {
      solvers.clear();
      for (unsigned int w = 0; w < parameters.engine.workers; ++w)
        solvers.push_back(
          std::make_unique<StateSolver>(mesh, nodes, parameters));
    }

    /** The scheduler's view of a point (call with the mutex held). */
    PointKnowledge
    knowledge(const unsigned int p) const
    {
      if (in_progress[p])
        return PointKnowledge::in_progress;
      switch (cache.status(p))
        {
          case PointStatus::available:
            return cache.has_state(p) ? PointKnowledge::source :
                                        PointKnowledge::computed;
          case PointStatus::failed:
            return PointKnowledge::failed;
          default:
            return PointKnowledge::unknown;
        }
    }

    void
    scheduler_loop();

    void
    worker_loop(const unsigned int worker);

    double
    now() const
    {
      return std::chrono::duration<double>(Clock::now() - t0).count();
    }

    const Mesh                               &mesh;
    const NodeSelection                      &nodes;
    Parameters::AllParameters                 parameters;
    const StateGrid                          &grid;
    StateCache                               &cache;
    const HipChannel                         &hip;
    Scheduler                                 scheduler;
    std::vector<std::unique_ptr<StateSolver>> solvers;

    mutable std::mutex        mutex;
    std::condition_variable   work_available, work_done;
    std::deque<Task>          queue;
    std::vector<std::uint8_t> in_progress;
    unsigned int              busy            = 0;
    bool                      nothing_to_plan = false;
    std::atomic<bool>         is_running{false};
    std::vector<std::thread>  workers;
    std::thread               scheduler_thread;
    Clock::time_point         t0;
    EngineStatistics          stats;
  };



  void
  ThreadEngine::Impl::scheduler_loop()
  {
    const auto period =
      std::chrono::duration<double>(1.0 / parameters.scheduler.rate);
    auto next = Clock::now();
    while (is_running.load())
      {
        Utilities::Point3 position, velocity;
        hip.read(position, velocity);
        cache.set_focus(position);
        {
          std::unique_lock<std::mutex> lock(mutex);
          const auto                   plan = scheduler.plan(
            position,
            velocity,
            [this](const unsigned int p) { return knowledge(p); },
            2 * solvers.size());
          // Tasks planned before that are no longer wanted are dropped.
          // Queued tasks that are neither in the new plan nor in the cloud
          // any more are dropped.
          for (const Task &old : queue)
            if (!scheduler.in_cloud(old.target, position, velocity) &&
                std::none_of(plan.begin(), plan.end(), [&](const Task &t) {
                  return t.target == old.target;
                }))
              ++stats.dropped;
          queue.assign(plan.begin(), plan.end());
          nothing_to_plan = plan.empty();
        }
        work_available.notify_all();

        // Next tick, or earlier when a worker finishes (so a free worker
        // gets its next task without waiting a whole period).
        next += std::chrono::duration_cast<Clock::duration>(period);
        std::unique_lock<std::mutex> lock(mutex);
        work_done.wait_until(lock, next, [this] { return !is_running.load(); });
        if (Clock::now() > next)
          next = Clock::now();
      }
  }



  void
  ThreadEngine::Impl::worker_loop(const unsigned int worker)
  {
    // Below the haptic thread: a worker must never delay a haptic tick.
    setpriority(PRIO_PROCESS, static_cast<id_t>(syscall(SYS_gettid)), 10);
    StateSolver &solver = *solvers[worker];
    while (true)
      {
        Task          task;
        std::uint64_t generation;
        {
          std::unique_lock<std::mutex> lock(mutex);
          work_available.wait(lock, [this] {
            return !is_running.load() || !queue.empty();
          });
          if (!is_running.load())
            return;
          task = queue.front();
          queue.pop_front();
          // Planned against what was known at the last tick: skip what has
          // changed since (computed, taken by another worker).
          if (knowledge(task.target) != PointKnowledge::unknown)
            continue;
          in_progress[task.target] = 1;
          ++busy;
          generation = cache.generation();
        }

        const double start  = now();
        const auto   source = cache.state(task.source);
        State        result;
        if (source)
          result = solver.solve(*source, grid.position(task.target));
        const double duration = now() - start;

        if (source && result.converged)
          {
            result.history.clear();
            result.history.shrink_to_fit();
            cache.publish(task.target,
                          std::make_shared<const State>(std::move(result)),
                          generation);
          }
        else if (source)
          cache.publish_failure(task.target, generation);

        {
          std::lock_guard<std::mutex> lock(mutex);
          in_progress[task.target] = 0;
          --busy;
          if (source)
            {
              if (generation != cache.generation())
                ++stats.discarded;
              else if (result.converged)
                ++stats.computed;
              else
                ++stats.failed;
              stats.busy_time += duration;
              stats.tasks.push_back({task.target,
                                     task.source,
                                     start,
                                     duration,
                                     result.converged,
                                     result.status,
                                     result.newton_iterations,
                                     worker});
            }
        }
        work_done.notify_all();
      }
  }



  ThreadEngine::ThreadEngine(const Mesh                      &mesh,
                             const NodeSelection             &nodes,
                             const Parameters::AllParameters &parameters,
                             const StateGrid                 &grid,
                             StateCache                      &cache,
                             const HipChannel                &hip)
    : impl(std::make_unique<Impl>(mesh, nodes, parameters, grid, cache, hip))
  {}



  ThreadEngine::~ThreadEngine()
  {
    stop();
  }



  void
  ThreadEngine::start()
  {
    Impl &s = *impl;
    if (s.is_running.load())
      return;
    // The rest state is known without computing: the origin of the grid.
    const unsigned int origin = s.grid.linear({{0, 0, 0}});
    if (s.cache.status(origin) != PointStatus::available)
      s.cache.publish(origin,
                      std::make_shared<const State>(
                        s.solvers.front()->rest_state()),
                      s.cache.generation());
    s.t0 = Clock::now();
    s.is_running.store(true);
    s.nothing_to_plan = false;
    for (unsigned int w = 0; w < s.solvers.size(); ++w)
      s.workers.emplace_back([&s, w] { s.worker_loop(w); });
    s.scheduler_thread = std::thread([&s] { s.scheduler_loop(); });
  }



  void
  ThreadEngine::stop()
  {
    Impl &s = *impl;
    if (!s.is_running.exchange(false))
      return;
    s.work_available.notify_all();
    s.work_done.notify_all();
    if (s.scheduler_thread.joinable())
      s.scheduler_thread.join();
    for (auto &w : s.workers)
      w.join();
    s.workers.clear();
    std::lock_guard<std::mutex> lock(s.mutex);
    s.queue.clear();
  }



  bool
  ThreadEngine::running() const
  {
    return impl->is_running.load();
  }



  void
  ThreadEngine::change_parameters(const Parameters::AllParameters &parameters)
  {
    Impl &s = *impl;
    if (s.is_running.load())
      throw std::logic_error(
        "parameters can change only while no contact is active "
        "(detach first)");
    s.parameters = parameters;
    s.build_solvers();
    s.cache.invalidate();
  }



  bool
  ThreadEngine::idle() const
  {
    std::lock_guard<std::mutex> lock(impl->mutex);
    return impl->busy == 0 && impl->queue.empty() && impl->nothing_to_plan;
  }



  EngineStatistics
  ThreadEngine::statistics() const
  {
    std::lock_guard<std::mutex> lock(impl->mutex);
    return impl->stats;
  }



  std::string
  ThreadEngine::description() const
  {
    const unsigned int n = impl->solvers.size();
    return std::to_string(n) + " solver thread" + (n > 1 ? "s" : "") + ", " +
           impl->solvers.front()->linear_solver_name();
  }



  std::unique_ptr<PrecomputationEngine>
  PrecomputationEngine::create(const Scene         &scene,
                               const Mesh          &mesh,
                               const NodeSelection &nodes,
                               const StateGrid     &grid,
                               StateCache          &cache,
                               const HipChannel    &hip)
  {
    if (scene.parameters.engine.type == "mpi")
      {
        const unsigned int line = scene.line_of("Engine/Type");
        throw NotAvailableError(
          "The MPI engine (solver servers on other machines), asked for by "
          "Engine / Type = mpi" +
            (scene.file().empty() ?
               std::string() :
               " in '" + scene.file() + "'" +
                 (line > 0 ? ", line " + std::to_string(line) : "")) +
            ",",
          "Set Engine / Type = threads: it runs the same scheduler with "
          "solver threads on this machine.");
      }
    return std::make_unique<ThreadEngine>(
      mesh, nodes, scene.parameters, grid, cache, hip);
  }
} // namespace palpate
