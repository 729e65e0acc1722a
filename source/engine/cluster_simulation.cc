// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

#include <palpate/engine/cluster_simulation.h>

#include <algorithm>
#include <cmath>
#include <queue>
#include <stdexcept>

namespace palpate
{
  namespace
  {
    // splitmix64: a well-mixed 64-bit hash, so that neighbouring tasks do
    // not draw neighbouring entries of the list of measured times.
    std::uint64_t
    mix(std::uint64_t x)
    {
      x += 0x9e3779b97f4a7c15ULL;
      x = (x ^ (x >> 30)) * 0xbf58476d1ce4e5b9ULL;
      x = (x ^ (x >> 27)) * 0x94d049bb133111ebULL;
      return x ^ (x >> 31);
    }

    // Two times closer than this are the same event: sums of latencies and
    // durations are not exact in floating point.
    constexpr double same_time = 1e-12;
  } // namespace



  TaskDurations
  TaskDurations::fixed(const double seconds)
  {
    return sampled({seconds}, 0);
  }



  TaskDurations
  TaskDurations::sampled(const std::vector<double> &seconds,
                         const std::uint64_t        seed)
  {
    if (seconds.empty())
      throw std::invalid_argument("TaskDurations needs at least one time");
    for (const double s : seconds)
      if (!(s >= 0) || !std::isfinite(s))
        throw std::invalid_argument("task durations must be finite and >= 0");
    TaskDurations d;
    d.times = seconds;
    d.seed  = seed;
    return d;
  }



  double
  TaskDurations::operator()(const unsigned int target,
                            const unsigned int source) const
  {
    if (times.size() == 1)
      return times[0];
    const std::uint64_t h =
      mix(seed ^ mix((std::uint64_t(target) << 32) | source));
    return times[h % times.size()];
  }



  double
  TaskDurations::mean() const
  {
    double sum = 0;
    for (const double t : times)
      sum += t;
    return sum / times.size();
  }



  unsigned int
  ClusterSimulation::Result::peak_busy(const double from, const double to) const
  {
    // The count in effect at `from` is the last step at or before it;
    // then every step up to `to`.
    unsigned int peak = 0, current = 0;
    for (const auto &[time, count] : busy)
      {
        if (time > to + same_time)
          break;
        if (time <= from + same_time)
          current = count;
        else
          peak = std::max(peak, count);
      }
    return std::max(peak, current);
  }



  ClusterSimulation::ClusterSimulation(const StateGrid    &grid,
                                       const Settings     &settings,
                                       const TaskDurations durations)
    : grid(grid)
    , settings(settings)
    , durations(durations)
    , scheduler(grid, settings.cloud_radius, settings.look_ahead_time)
  {
    if (!(settings.scheduler_rate > 0) || !(settings.haptic_rate > 0) ||
        !(settings.velocity_time_constant >= 0) ||
        !(settings.network.bandwidth > 0) || !(settings.network.latency >= 0))
      throw std::invalid_argument(
        "ClusterSimulation: rates and bandwidth must be positive, the "
        "latency and the velocity time constant non-negative");
  }



  void
  ClusterSimulation::set_failure_points(const std::set<unsigned int> &points)
  {
    failures = points;
  }



  namespace
  {
    /**
     * One ClusterSimulation::run(): the simulated servers, the network and
     * the client, and the steps of the event loop that advances them.
     */
    class ClusterRun
    {
    public:
      using Settings   = ClusterSimulation::Settings;
      using Motion     = ClusterSimulation::Motion;
      using TaskRecord = ClusterSimulation::TaskRecord;
      using Result     = ClusterSimulation::Result;

      /** Everything at rest at t = 0; only the rest state is known. */
      ClusterRun(const StateGrid              &grid,
                 const Settings               &settings,
                 const TaskDurations          &durations,
                 const Scheduler              &scheduler,
                 const std::set<unsigned int> &failures,
                 const Motion                 &motion);

      /**
       * Run the events (scheduler ticks and results reaching the client)
       * until @p time_after_motion seconds after the motion, or @p
       * max_time.
       */
      void
      simulate(const double time_after_motion, const double max_time);

      /** The result, with the motion's times and the missing data. */
      Result
      finish();

    private:
      /** Where the HIP is at @p t. */
      Utilities::Point3
      hip(const double t) const;

      /** Whether the HIP is moving at @p t. */
      bool
      moving(const double t) const;

      /** Take in the results that reached the client by @p t. */
      void
      receive_results(const double t);

      /** Run the haptic side's velocity filter up to @p t. */
      void
      filter_velocity(const double t);

      /** The scheduler's plan for the HIP at @p x. */
      std::vector<Task>
      plan_at(const Utilities::Point3 &x);

      /** Give out the tasks of @p plan at @p t, most urgent first. */
      void
      give_out(const std::vector<Task> &plan, const double t);

      /**
       * The server for @p task: -1 if there is none. @p held: the server
       * holds the task's source.
       */
      int
      choose_server(const Task &task, bool &held);

      /** Give @p task to @p server at @p t. */
      void
      assign(const Task        &task,
             const unsigned int server,
             const bool         held,
             const double       t);

      /** Count the haptic ticks of the motion that miss data. */
      void
      count_missing_data();

      const StateGrid              &grid;
      const Settings               &settings;
      const TaskDurations          &durations;
      const Scheduler              &scheduler;
      const std::set<unsigned int> &failures;
      const Motion                 &motion;

      Result result;

      // What the scheduler knows, when each result reached the client, and
      // which servers hold each state. The rest state is computed by nobody:
      // every server can set up a zero displacement itself.
      const unsigned int                     rest;
      std::vector<PointKnowledge>            known;
      std::vector<double>                    arrived;
      std::vector<std::vector<unsigned int>> holders;

      const bool   unlimited;
      const double notify;
      const double fetch;

      // Servers: busy or free; the free ones in a set, so that "the free
      // server with the lowest number" is its first element.
      std::vector<bool>      busy;
      std::set<unsigned int> free;
      unsigned int           n_busy = 0;

      // Results on their way to the client: (arrival time, task number).
      using Arrival = std::pair<double, std::size_t>;
      std::priority_queue<Arrival, std::vector<Arrival>, std::greater<Arrival>>
        arrivals;

      // The motion. Its start is fixed, or found when the initial cloud is
      // complete; until then the HIP rests at path(0).
      double start;

      // The bridge scans the whole grid; as ThreadEngine does, do not scan
      // again while nothing finished and the HIP stayed in the same cell.
      std::uint64_t     finished = 0;
      BridgeMemory      bridge;
      Utilities::Point3 planned_at, planned_velocity{{0, 0, 0}};
      bool              changed = true;

      // The haptic side's velocity filter.
      std::uint64_t     haptic_tick = 0;
      Utilities::Point3 v{{0, 0, 0}}, previous{{0, 0, 0}};
      const double      alpha;
      // Grid points planned while no server was free for them, in motion.
      std::vector<bool> waited;
    };



    ClusterRun::ClusterRun(const StateGrid              &grid,
                           const Settings               &settings,
                           const TaskDurations          &durations,
                           const Scheduler              &scheduler,
                           const std::set<unsigned int> &failures,
                           const Motion                 &motion)
      : grid(grid)
      , settings(settings)
      , durations(durations)
      , scheduler(scheduler)
      , failures(failures)
      , motion(motion)
      , rest(grid.linear({{0, 0, 0}}))
      , known(grid.size(), PointKnowledge::unknown)
      , arrived(grid.size(), std::numeric_limits<double>::infinity())
      , holders(grid.size())
      , unlimited(settings.servers == 0)
      , notify(
          settings.network.message_time(settings.network.notification_bytes))
      , fetch(notify + settings.network.message_time(settings.state_bytes))
      , busy(unlimited ? 0 : settings.servers, false)
      , start(motion.start)
      , alpha(
          std::min(1.0,
                   1.0 / (settings.haptic_rate *
                          std::max(settings.velocity_time_constant, 1e-300))))
      , waited(grid.size(), false)
    {
      known[rest]   = PointKnowledge::source;
      arrived[rest] = 0;
      for (unsigned int s = 0; s < busy.size(); ++s)
        free.insert(s);
      const double nan = std::numeric_limits<double>::quiet_NaN();
      planned_at       = {{nan, nan, nan}};
    }



    Utilities::Point3
    ClusterRun::hip(const double t) const
    {
      if (start < 0 || t <= start)
        return motion.path(0.0);
      return motion.path(std::min(t - start, motion.duration));
    }



    bool
    ClusterRun::moving(const double t) const
    {
      return start >= 0 && t >= start - same_time &&
             t <= start + motion.duration + same_time;
    }



    void
    ClusterRun::simulate(const double time_after_motion, const double max_time)
    {
      std::uint64_t tick = 0;
      while (true)
        {
          // The next event: a scheduler tick or a result reaching the
          // client.
          const double next_tick = tick / settings.scheduler_rate;
          const double t         = arrivals.empty() ?
                                     next_tick :
                                     std::min(next_tick, arrivals.top().first);
          const double end =
            start >= 0 ?
              std::min(max_time, start + motion.duration + time_after_motion) :
              max_time;
          if (t > end + same_time)
            break;
          if (next_tick <= t + same_time)
            ++tick;

          receive_results(t);
          filter_velocity(t);
          const Utilities::Point3 x = hip(t);
          // The same knowledge, position and velocity give the same plan
          // (the Scheduler is stateless): skip the work, not the event.
          if (x != planned_at || v != planned_velocity)
            changed = true;
          if (!changed)
            continue;
          changed          = false;
          planned_at       = x;
          planned_velocity = v;

          const std::vector<Task> plan = plan_at(x);
          give_out(plan, t);

          if (result.busy.empty() || result.busy.back().second != n_busy)
            result.busy.emplace_back(t, n_busy);

          // The initial cloud is complete when there is nothing left to
          // plan and nothing under way: the device starts moving.
          if (start < 0 && plan.empty() && n_busy == 0)
            {
              start   = t;
              changed = true;
            }
        }
    }



    void
    ClusterRun::receive_results(const double t)
    {
      // Results that arrived: the state becomes a source (its server
      // holds it) or a failure point; the server is free again.
      while (!arrivals.empty() && arrivals.top().first <= t + same_time)
        {
          const TaskRecord &task = result.tasks[arrivals.top().second];
          arrivals.pop();
          known[task.target] =
            task.failed ? PointKnowledge::failed : PointKnowledge::source;
          arrived[task.target] = task.arrived;
          if (!task.failed)
            holders[task.target].push_back(task.server);
          busy[task.server] = false;
          free.insert(task.server);
          --n_busy;
          ++finished;
          changed = true;
          if (start < 0 || task.arrived < start)
            ++result.initial_cloud_states;
        }
    }



    void
    ClusterRun::filter_velocity(const double t)
    {
      // Where the HIP is and where it is going, as the haptic side
      // publishes it: the velocity is the low-pass filtered difference
      // of the positions at the haptic ticks up to now.
      for (; haptic_tick / settings.haptic_rate <= t + same_time; ++haptic_tick)
        {
          const Utilities::Point3 y = hip(haptic_tick / settings.haptic_rate);
          if (haptic_tick > 0)
            for (unsigned int d = 0; d < 3; ++d)
              v[d] +=
                alpha * ((y[d] - previous[d]) * settings.haptic_rate - v[d]);
          previous = y;
        }
    }



    std::vector<Task>
    ClusterRun::plan_at(const Utilities::Point3 &x)
    {
      GridIndex             cell;
      std::array<double, 3> local;
      grid.locate(x, cell, local);
      const bool allow_bridge = bridge.allowed(finished, cell);
      // As many tasks as ThreadEngine plans (twice the workers), or all
      // of them with unlimited servers.
      const auto plan = scheduler.plan(
        x,
        v,
        [this](const unsigned int p) { return known[p]; },
        unlimited ? grid.size() : 2 * settings.servers,
        allow_bridge);
      bridge.planned(plan.empty(), allow_bridge, finished, cell);
      return plan;
    }



    void
    ClusterRun::give_out(const std::vector<Task> &plan, const double t)
    {
      unsigned int waiting = 0;
      for (const Task &task : plan)
        {
          if (!schedulable(known[task.target]))
            continue;
          bool      held   = false;
          const int server = choose_server(task, held);
          if (server < 0)
            {
              ++waiting;
              if (moving(t) && !waited[task.target])
                {
                  waited[task.target] = true;
                  ++result.waited;
                }
              continue;
            }
          assign(task, server, held, t);
        }
      if (moving(t))
        result.max_waiting = std::max(result.max_waiting, waiting);
    }



    int
    ClusterRun::choose_server(const Task &task, bool &held)
    {
      // A free server that holds the source, else the first free
      // one, else (unlimited) a new one.
      int server = -1;
      if (task.source != rest)
        for (const unsigned int s : holders[task.source])
          if (!busy[s] && (server < 0 || s < unsigned(server)))
            server = s;
      held = server >= 0 || task.source == rest;
      if (server < 0 && !free.empty())
        server = *free.begin();
      if (server < 0 && unlimited)
        {
          server = busy.size();
          busy.push_back(false);
        }
      return server;
    }



    void
    ClusterRun::assign(const Task        &task,
                       const unsigned int server,
                       const bool         held,
                       const double       t)
    {
      TaskRecord r;
      r.target   = task.target;
      r.source   = task.source;
      r.server   = server;
      r.assigned = t;
      r.transfer = held ? 0.0 : fetch;
      r.start    = t + notify + r.transfer;
      r.finish   = r.start + durations(task.target, task.source);
      r.arrived  = r.finish + notify;
      r.failed   = failures.count(task.target) > 0;
      if (held)
        result.transfers_avoided += task.source != rest;
      else
        {
          // The server keeps the copy it fetched.
          ++result.transfers;
          holders[task.source].push_back(server);
        }

      known[task.target] = PointKnowledge::in_progress;
      busy[server]       = true;
      free.erase(server);
      ++n_busy;
      arrivals.emplace(r.arrived, result.tasks.size());
      result.tasks.push_back(r);
    }



    ClusterSimulation::Result
    ClusterRun::finish()
    {
      result.servers_used = busy.size();
      if (start < 0)
        start = std::numeric_limits<double>::infinity();
      result.motion_start = start;
      result.motion_end   = start + motion.duration;
      count_missing_data();
      return std::move(result);
    }



    void
    ClusterRun::count_missing_data()
    {
      // Missing data, as the force interpolator meets it: at every haptic
      // tick of the motion, each corner of the HIP's cell must have reached
      // the client and not be a failure point.
      const double dt          = 1.0 / settings.haptic_rate;
      bool         was_missing = false;
      for (std::uint64_t k = 0;; ++k)
        {
          const double t = start + k * dt;
          if (!std::isfinite(t) || t > result.motion_end + same_time)
            break;
          const Utilities::Point3 x = hip(t);
          GridIndex               cell;
          std::array<double, 3>   local;
          bool                    missing = !grid.locate(x, cell, local);
          if (!missing)
            for (const unsigned int c : grid.corners(cell))
              missing = missing || known[c] == PointKnowledge::failed ||
                        arrived[c] > t + same_time;
          if (missing)
            {
              result.missing_seconds += dt;
              result.missing_events += !was_missing;
            }
          was_missing = missing;
        }
    }
  } // namespace



  ClusterSimulation::Result
  ClusterSimulation::run(const Motion &motion,
                         const double  time_after_motion,
                         const double  max_time) const
  {
    ClusterRun run(grid, settings, durations, scheduler, failures, motion);
    run.simulate(time_after_motion, max_time);
    return run.finish();
  }
} // namespace palpate
