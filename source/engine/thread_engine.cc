// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

#include <palpate/base/exceptions.h>
#include <palpate/engine/hip_channel.h>
#include <palpate/engine/mpi_engine.h>
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
#include <cstdlib>
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
      build_solvers(parameters);
    }

    /** One solver per worker for @p p; the current ones stay if this
     * throws. */
    void
    build_solvers(const Parameters::AllParameters &p)
    {
      std::vector<std::unique_ptr<StateSolver>> built;
      for (unsigned int w = 0; w < p.engine.workers; ++w)
        built.push_back(std::make_unique<StateSolver>(mesh, nodes, p));
      solvers.swap(built);
    }

    /** A stop check for a solve toward @p target: true once the HIP has
     * moved away from it (StateSolver::set_stop_check()). */
    std::function<bool()>
    left_behind(const Task &task) const;

    /**
     * With every worker busy and corners of the HIP's cell or of the cells
     * on its predicted path waiting (Task::corner, first in the queue):
     * give up as many running states as wait, of those that are no such
     * corner (Scheduler::path_corners()), the farthest from the path
     * first. On a real organ a state takes seconds: a corner that waits
     * for one is missing data when the hand gets there. (Mutex held.)
     */
    void
    preempt_for_path_corners(const Utilities::Point3 &position,
                             const Utilities::Point3 &velocity);

    /** The scheduler's view of a point (call with the mutex held). */
    PointKnowledge
    knowledge(const unsigned int p) const
    {
      return point_knowledge(in_progress[p] != 0,
                             cache.status(p),
                             cache.has_state(p));
    }

    /** The scheduler thread: schedule(), and whatever it throws stops
     * the engine through shut_down_after_error(). */
    void
    scheduler_loop();

    void
    schedule();

    void
    shut_down_after_error(const std::string &what);

    void
    worker_loop(const unsigned int worker);

    /** Count the task @p worker finished (started at @p start, its
     * solution @p result for the cache's @p generation; @p solved: solved
     * or failed rather than cancelled; @p error: what it threw), and free
     * its place. */
    void
    record_task(const unsigned int  worker,
                const Task         &task,
                const State        &result,
                const bool          solved,
                const std::string  &error,
                const double        start,
                const std::uint64_t generation);

    /** @p task's state by @p solver from @p source, the task's source. */
    State
    solve(StateSolver &solver, const Task &task, const State &source);

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
    // The sum of the running solves' start times (now()): with busy, the
    // time spent on them so far (load()).
    double running_since = 0;
    // Tasks finished so far, and how many had finished when the last plan
    // was made: the engine is idle only if that plan saw all of them.
    std::uint64_t finished = 0, finished_at_plan = 0;
    // A worker finished: plan again before the next tick.
    bool replan = false;
    // The bridge found nothing with this many tasks finished and the HIP
    // in this cell: do not scan the grid again until one changes.
    BridgeMemory      bridge;
    std::atomic<bool> is_running{false};
    // A stop signal: the running solves give up (abandon_running()).
    std::atomic<bool>        abandoning{false};
    bool                     started_once = false;
    std::vector<std::thread> workers;
    // Per worker: the point it solves (~0u: none; under the mutex), and
    // whether a corner of the HIP's path asked for the worker (read by the
    // solve's stop check).
    std::vector<unsigned int>            solving;
    std::unique_ptr<std::atomic<bool>[]> preempted;
    std::thread                          scheduler_thread;
    Clock::time_point                    t0;
    EngineStatistics                     stats;
    EngineFaults                         faults;
    unsigned int                         plans  = 0;
    bool                                 failed = false; // the scheduler threw
  };



  void
  ThreadEngine::Impl::scheduler_loop()
  {
    // The scheduler must not take the process down while a device renders
    // forces: whatever it throws is counted and reported, the workers stop
    // (is_running = false) and the interaction goes on with what is
    // cached, its force fading where states are missing.
    try
      {
        schedule();
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
  ThreadEngine::Impl::shut_down_after_error(const std::string &what)
  {
    {
      std::lock_guard<std::mutex> lock(mutex);
      ++stats.errors;
      stats.last_error = "scheduler thread: " + what;
      is_running       = false;
      failed           = true;
      queue.clear();
      nothing_to_plan = true;
    }
    work_available.notify_all();
    work_done.notify_all();
  }



  void
  ThreadEngine::Impl::schedule()
  {
    const auto period = std::chrono::duration_cast<Clock::duration>(
      std::chrono::duration<double>(1.0 / parameters.scheduler.rate));
    auto next = Clock::now() + period; // the next regular tick
    std::unique_lock<std::mutex> lock(mutex);
    while (is_running)
      {
        lock.unlock();
        Utilities::Point3 position, velocity;
        hip.read(position, velocity);
        cache.set_focus(position);
        GridIndex             cell;
        std::array<double, 3> local;
        grid.locate(position, cell, local);
        lock.lock();

        if (faults.scheduler_throws_at_plan > 0 &&
            ++plans == faults.scheduler_throws_at_plan)
          throw std::runtime_error("fault injected for a test (plan " +
                                   std::to_string(plans) + ")");
        const bool allow_bridge = bridge.allowed(finished, cell);
        const auto plan         = scheduler.plan(
          position,
          velocity,
          [this](const unsigned int p) { return knowledge(p); },
          2 * solvers.size(),
          allow_bridge);
        bridge.planned(plan.empty(), allow_bridge, finished, cell);
        // Queued tasks that are neither in the new plan nor in the cloud
        // any more are dropped.
        for (const Task &old : queue)
          if (!scheduler.in_cloud(old.target, position, velocity) &&
              std::none_of(plan.begin(), plan.end(), [&](const Task &t) {
                return t.target == old.target;
              }))
            ++stats.dropped;
        queue.assign(plan.begin(), plan.end());
        preempt_for_path_corners(position, velocity);
        nothing_to_plan  = plan.empty();
        finished_at_plan = finished;
        replan           = false;
        work_available.notify_all();

        // Plan again at the next tick, or earlier when a worker finishes
        // (so that a free worker gets its next task without waiting); an
        // early plan does not move the regular ticks.
        work_done.wait_until(lock, next, [this] {
          return !is_running || replan;
        });
        const auto now = Clock::now();
        if (now >= next)
          next = std::max(next + period, now);
      }
  }



  std::function<bool()>
  ThreadEngine::Impl::left_behind(const Task &task) const
  {
    // Left behind: farther from the HIP's predicted path than the cloud
    // reaches, and than when it was planned, each by two grid spacings (a
    // bridge's target lies outside the cloud but gets nearer; a hand that
    // wavers back and forth must not cancel what it comes back to). When
    // it was planned, not when it starts: a task queued before the HIP
    // jumped and taken after it is left behind from its first iteration.
    // (Task::priority is the distance from the path at the plan, or for a
    // corner of a cell on the path its arc length there: near, either way.)
    const Utilities::Point3 x = grid.position(task.target);
    Utilities::Point3       position, velocity;
    hip.read(position, velocity);
    const double margin = 2 * grid.spacing();
    const double limit =
      std::max(parameters.scheduler.cloud_radius,
               std::min(task.priority,
                        scheduler.distance_to_path(x, position, velocity))) +
      margin;
    return [this, x, limit] {
      Utilities::Point3 position, velocity;
      hip.read(position, velocity);
      return scheduler.distance_to_path(x, position, velocity) > limit;
    };
  }



  void
  ThreadEngine::Impl::preempt_for_path_corners(
    const Utilities::Point3 &position,
    const Utilities::Point3 &velocity)
  {
    if (busy < solvers.size())
      return; // a worker is free: it takes the corner
    unsigned int waiting = 0;
    for (const Task &t : queue)
      if (t.corner)
        ++waiting;
    for (unsigned int w = 0; w < solvers.size(); ++w)
      if (solving[w] != ~0u && preempted[w].load())
        waiting = waiting > 0 ? waiting - 1 : 0; // already freeing
    if (waiting == 0)
      return;
    const auto corners = scheduler.path_corners(position, velocity);
    const auto needed  = [&](const unsigned int p) {
      return std::binary_search(corners.begin(),
                                corners.end(),
                                std::make_pair(p, 0.0),
                                [](const auto &a, const auto &b) {
                                  return a.first < b.first;
                                });
    };
    std::vector<std::pair<double, unsigned int>> victims; // (distance, w)
    for (unsigned int w = 0; w < solvers.size(); ++w)
      if (solving[w] != ~0u && !preempted[w].load() && !needed(solving[w]))
        victims.emplace_back(scheduler.distance_to_path(
                               grid.position(solving[w]), position, velocity),
                             w);
    std::sort(victims.rbegin(), victims.rend());
    for (unsigned int k = 0; k < waiting && k < victims.size(); ++k)
      preempted[victims[k].second].store(true);
  }



  State
  ThreadEngine::Impl::solve(StateSolver &solver,
                            const Task  &task,
                            const State &source)
  {
    // The state behind the source on the same grid line, if held, makes
    // Newton's start second-order accurate. And the one behind that,
    // third-order.
    unsigned int                 b = 0, bb = 0;
    std::shared_ptr<const State> behind, behind2;
    if (grid.behind(task.source, task.target, b) && cache.has_state(b))
      {
        behind = cache.state(b);
        if (grid.behind(b, task.source, bb) && cache.has_state(bb))
          behind2 = cache.state(bb);
      }
    const Utilities::Point3 target = grid.position(task.target);
    State result = solver.solve(source, target, behind.get(), behind2.get());
    // A point around rest that failed from its neighbour is solved again
    // from rest: the path on which a sphere's offered radius was tried
    // (select_nodes() solves the 26 points around rest from rest). The path
    // matters on a nonlinear model: on liver-stvk.prm at Node id 47 a
    // 0.0249 m sphere converges at all 26 from rest, yet one fails from
    // its neighbour, and without this the force would be lost at rest
    // (the test engine/rest_retry).
    const unsigned int origin = grid.linear({{0, 0, 0}});
    if (!result.converged && result.status != SolveStatus::stopped &&
        task.source != origin && grid.beside_origin(task.target))
      {
        const auto rest = cache.state(origin);
        result = solver.solve(rest ? *rest : solver.rest_state(), target);
      }
    return result;
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
        double        start = 0;
        {
          std::unique_lock<std::mutex> lock(mutex);
          work_available.wait(lock,
                              [this] { return !is_running || !queue.empty(); });
          if (!is_running)
            return;
          task = queue.front();
          queue.pop_front();
          // Planned against what was known at the last tick: skip what has
          // changed since (computed, taken by another worker).
          if (!schedulable(knowledge(task.target)))
            continue;
          in_progress[task.target] = 1;
          solving[worker]          = task.target;
          preempted[worker].store(false);
          ++busy;
          generation = cache.generation();
          start      = now();
          running_since += start;
        }

        // A running state the HIP has moved away from is given up (on a
        // real organ a state takes seconds, in which a hand moves
        // centimetres): the worker is free for the states the HIP now
        // needs. Asked at every Newton iteration.
        solver.set_stop_check([left     = left_behind(task),
                               &flag    = preempted[worker],
                               &abandon = abandoning] {
          return flag.load(std::memory_order_relaxed) ||
                 abandon.load(std::memory_order_relaxed) || left();
        });

        // solve() reports numerical failures as failure points; anything
        // else that goes wrong (out of memory, a library error) must not
        // take the process down while a device renders forces: it becomes
        // a failure point too, and is counted and reported.
        State       result;
        bool        solved = false;
        std::string error;
        try
          {
            if (faults.workers_throw)
              throw std::runtime_error("fault injected for a test (task " +
                                       std::to_string(task.target) + ")");
            if (const auto source = cache.state(task.source))
              {
                result = solve(solver, task, *source);
                solved = true;
                if (result.status == SolveStatus::stopped)
                  solved = false; // cancelled: nothing learnt, nothing kept
                else if (result.converged)
                  {
                    result.history.clear();
                    result.history.shrink_to_fit();
                    cache.publish(task.target,
                                  std::make_shared<const State>(
                                    std::move(result)),
                                  generation);
                  }
                else
                  cache.publish_failure(task.target, generation, result.status);
              }
          }
        catch (const std::exception &e)
          {
            error = e.what();
          }
        catch (...)
          {
            error = "unknown exception";
          }
        if (!error.empty())
          {
            solved           = true;
            result.converged = false;
            // The solve threw (the message is reported): count it with the
            // solver's failures.
            cache.publish_failure(task.target,
                                  generation,
                                  SolveStatus::linear_solver_failure);
          }
        record_task(worker, task, result, solved, error, start, generation);
        work_done.notify_all();
      }
  }



  void
  ThreadEngine::Impl::record_task(const unsigned int  worker,
                                  const Task         &task,
                                  const State        &result,
                                  const bool          solved,
                                  const std::string  &error,
                                  const double        start,
                                  const std::uint64_t generation)
  {
    const double                duration = now() - start;
    std::lock_guard<std::mutex> lock(mutex);
    in_progress[task.target] = 0;
    solving[worker]          = ~0u;
    --busy;
    running_since -= start;
    ++finished;
    replan = true;
    if (result.status == SolveStatus::stopped)
      {
        ++(preempted[worker].load() ? stats.preempted : stats.cancelled);
        stats.busy_time += duration;
      }
    if (solved)
      {
        if (generation != cache.generation())
          ++stats.discarded;
        else if (result.converged)
          ++stats.computed;
        else
          ++stats.failed;
        if (!error.empty())
          {
            ++stats.errors;
            stats.last_error = error;
          }
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



  ThreadEngine::ThreadEngine(const Mesh                      &mesh,
                             const NodeSelection             &nodes,
                             const Parameters::AllParameters &parameters,
                             const StateGrid                 &grid,
                             StateCache                      &cache,
                             const HipChannel                &hip,
                             const EngineFaults              &faults)
    : impl(std::make_unique<Impl>(mesh, nodes, parameters, grid, cache, hip))
  {
    impl->faults = faults;
  }



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
    {
      std::lock_guard<std::mutex> lock(s.mutex);
      if (!s.started_once)
        s.t0 = Clock::now(); // task times count from the first attach
      s.started_once    = true;
      s.abandoning      = false;
      s.failed          = false;
      s.is_running      = true;
      s.nothing_to_plan = false;
      s.replan          = false;
      s.bridge.reset();
    }
    s.solving.assign(s.solvers.size(), ~0u);
    s.preempted = std::make_unique<std::atomic<bool>[]>(s.solvers.size());
    for (unsigned int w = 0; w < s.solvers.size(); ++w)
      s.workers.emplace_back([&s, w] { s.worker_loop(w); });
    s.scheduler_thread = std::thread([&s] { s.scheduler_loop(); });
  }



  void
  ThreadEngine::stop()
  {
    Impl &s = *impl;
    {
      // Under the mutex, so that no thread can test the flag, miss the
      // notification and then wait for ever.
      // (The scheduler may have stopped the engine itself after an error:
      // its threads are joined all the same.)
      std::lock_guard<std::mutex> lock(s.mutex);
      if (!s.is_running && !s.scheduler_thread.joinable())
        return;
      s.is_running = false;
    }
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



  void
  ThreadEngine::abandon_running()
  {
    impl->abandoning.store(true);
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
    // Nothing computed for the old parameters is used again, whatever
    // happens next; if the new solvers cannot be built, the old ones stay
    // (and the caller restores the old scene).
    s.cache.invalidate();
    s.build_solvers(parameters);
    s.parameters = parameters;
  }



  bool
  ThreadEngine::idle() const
  {
    std::lock_guard<std::mutex> lock(impl->mutex);
    if (impl->failed)
      return impl->busy == 0; // nothing more will be planned
    return impl->busy == 0 && impl->queue.empty() && impl->nothing_to_plan &&
           impl->finished_at_plan == impl->finished;
  }



  EngineStatistics
  ThreadEngine::statistics() const
  {
    std::lock_guard<std::mutex> lock(impl->mutex);
    return impl->stats;
  }



  EngineLoad
  ThreadEngine::load() const
  {
    const Impl                 &s = *impl;
    std::lock_guard<std::mutex> lock(s.mutex);
    EngineLoad                  l;
    l.workers  = s.solvers.size();
    l.busy     = s.busy;
    l.queued   = s.queue.size();
    l.computed = s.stats.computed;
    l.failed   = s.stats.failed;
    // With the running solves' time so far: a task longer than a live
    // view's sampling interval still shows as busy.
    l.busy_time =
      s.stats.busy_time + std::max(0.0, s.busy * s.now() - s.running_since);
    for (unsigned int p = 0; p < s.in_progress.size(); ++p)
      if (s.in_progress[p] != 0)
        l.in_progress.push_back(p);
    return l;
  }



  unsigned int
  ThreadEngine::n_workers() const
  {
    return impl->solvers.size();
  }



  std::string
  ThreadEngine::description() const
  {
    const unsigned int n = impl->solvers.size();
    // The Newton method too: 'Reuse factorization = by size' chose it
    // from the system's size, and the summary says which.
    return std::to_string(n) + " solver thread" + (n > 1 ? "s" : "") + ", " +
           impl->solvers.front()->linear_solver_name() + ", Newton steps " +
           (impl->solvers.front()->settings().reuse_factorization ?
              "by GMRES on a kept factorisation" :
              "with a factorisation each");
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
        if (mpi_size() < 2)
          throw InputError(
            scene.file(),
            scene.line_of("Engine/Type"),
            "Engine / Type = mpi",
            // Under mpirun -np 1 it is not "alone" by choice: say what
            // mpirun did (Open MPI sets OMPI_COMM_WORLD_SIZE).
            std::getenv("OMPI_COMM_WORLD_SIZE") != nullptr ?
              std::string("mpirun started only 1 process (-np 1), the haptic "
                          "client; the MPI engine needs at least one more, "
                          "a solver server") :
              std::string("the MPI engine needs solver servers, and this "
                          "palpate was not started by mpirun"),
            "start it with mpirun: `mpirun -np 3 palpate " +
              (scene.file().empty() ? std::string("SCENE.prm") : scene.file()) +
              "` runs the haptic client and 2 solver servers (add "
              "--oversubscribe to run more processes than cores); or set "
              "Engine / Type = threads.");
        return std::make_unique<MpiEngine>(scene.parameters, grid, cache, hip);
      }
    if (mpi_size() > 1)
      throw InputError(
        scene.file(),
        scene.line_of("Engine/Type"),
        "Engine / Type = " + scene.parameters.engine.type,
        "palpate runs under mpirun with " + std::to_string(mpi_size()) +
          " processes, but this engine uses threads of one process",
        "set Engine / Type = mpi to use the other processes as solver "
        "servers, or run palpate without mpirun.");
    return std::make_unique<ThreadEngine>(
      mesh, nodes, scene.parameters, grid, cache, hip);
  }
} // namespace palpate
