// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

#include <palpate/haptics/device.h>
#include <palpate/haptics/haptic_loop.h>
#include <palpate/haptics/interaction.h>
#include <palpate/haptics/run_summary.h>

#include <pthread.h>
#include <sched.h>
#include <sys/mman.h>
#include <time.h>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <sstream>
#include <stdexcept>
#include <thread>
#include <vector>

namespace palpate
{
  struct HapticLoop::Impl
  {
    Interaction        &interaction;
    Device             &device;
    const double        rate;
    const bool          continuous;
    const std::size_t   capacity; // statistics samples (a window if continuous)
    std::vector<double> period, lateness, interpolation; // seconds
    std::uint64_t       n        = 0; // ticks sampled (held ticks are not)
    std::uint64_t       misses   = 0;
    bool                realtime = false, locked = false, truncated = false;
    double              motion_duration = 0, motion_elapsed = 0;
    std::atomic<bool>   motion_requested{false};
    std::atomic<long long> motion_start_ns{
      -1};                            // since the loop started; -1: not yet
    std::atomic<long long> t0_ns{-1}; // the loop's start (CLOCK_MONOTONIC)
    std::atomic<bool>      done{false}, stop{false};
    // hold(): asked for, and the loop's word that it is outside the device
    // and force path (sequentially consistent: see hold()).
    std::atomic<bool> hold_requested{false}, holding{false};
    std::thread       thread;
    double            motion_started_at = 0;
    // The force log (Effects / Force log), allocated here or not at all: a
    // ring of rows of the motion, filled by the loop (never waiting: a
    // full ring drops the row and counts it) and emptied by
    // drain_force_log(). A bounded loop's holds every tick of its run.
    struct LogRow
    {
      double            t;
      Utilities::Point3 x, f;
    };
    std::vector<LogRow>              log;
    std::atomic<std::size_t>         log_head{0};
    mutable std::atomic<std::size_t> log_tail{0};
    std::atomic<std::uint64_t>       log_dropped{0};

    Impl(Interaction &i,
         Device      &d,
         const double r,
         const double max_seconds,
         const bool   force_log)
      : interaction(i)
      , device(d)
      , rate(r)
      , continuous(max_seconds >= HapticLoop::continuous)
      , capacity(HapticLoop::max_ticks(r,
                                       continuous ?
                                         HapticLoop::continuous_window :
                                         max_seconds))
      , period(capacity)
      , lateness(capacity)
      , interpolation(capacity)
      // A continuous loop's log: 4 s of ticks, drained a few times a
      // second.
      , log(force_log ? (continuous ? HapticLoop::max_ticks(r, 4) : capacity) :
                        0)
    {}

    void
    run();

    /** run(), before the first tick: real-time priority, memory locked,
     * and the force path run once, so that no tick pays for them. */
    void
    prepare_realtime() noexcept;

    /** run(): sleep until @p deadline plus one period of @p period_ns,
     * count the missed deadlines and move @p deadline past those that
     * passed; returns the wake time (ns) and its lateness @p late (s). */
    long long
    wait_for_tick(long long      &deadline,
                  const long long period_ns,
                  double         &late) noexcept;

    /** run(): one tick's work in statistics slot @p i, woken at @p wake
     * (ns, the loop started at @p t0): the device's position, the force
     * timed, rendered and logged. Returns whether the motion is over. */
    bool
    render_tick(const std::size_t i,
                const long long   wake,
                const long long   t0) noexcept;

    /** render_tick(): the row (@p t, @p x, @p f) into the force log, or
     * counted as dropped when the ring is full (never waiting). */
    void
    log_force(const double             t,
              const Utilities::Point3 &x,
              const Utilities::Point3 &f) noexcept;

    /** Whether the loop is to hold (see HapticLoop::hold()); says so. */
    bool
    held() noexcept
    {
      holding.store(false);
      if (!hold_requested.load())
        return false;
      holding.store(true);
      return true;
    }
  };



  namespace
  {
    long long
    nanoseconds(const timespec &t)
    {
      return static_cast<long long>(t.tv_sec) * 1000000000LL + t.tv_nsec;
    }

    timespec
    to_timespec(const long long ns)
    {
      return {static_cast<time_t>(ns / 1000000000LL),
              static_cast<long>(ns % 1000000000LL)};
    }
  } // namespace



  void
  HapticLoop::Impl::prepare_realtime() noexcept
  {
    // Real-time priority if the system allows it (root, or CAP_SYS_NICE,
    // or an rtprio limit); otherwise normal priority, and the summary says
    // so.
    sched_param parameters{};
    parameters.sched_priority = 80;
    realtime =
      pthread_setschedparam(pthread_self(), SCHED_FIFO, &parameters) == 0;

    // No page fault inside the loop: lock what is mapped now (the solvers
    // and the statistics arrays were allocated before), touch a stack
    // reserve, and run the force path once before the first deadline.
    locked = mlockall(MCL_CURRENT) == 0;
    {
      volatile char stack[256 * 1024];
      for (std::size_t i = 0; i < sizeof(stack); i += 4096)
        stack[i] = 0;
    }
    if (!held())
      interaction.force(device.position(0));
  }



  long long
  HapticLoop::Impl::wait_for_tick(long long      &deadline,
                                  const long long period_ns,
                                  double         &late) noexcept
  {
    deadline += period_ns;
    const timespec next = to_timespec(deadline);
    while (clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &next, nullptr) ==
           EINTR)
      {} // a signal: sleep on until the deadline
    timespec now;
    clock_gettime(CLOCK_MONOTONIC, &now);
    const long long wake = nanoseconds(now);
    late                 = 1e-9 * (wake - deadline);
    if (late > 0.5e-3)
      ++misses;
    // After a stall, no burst of catch-up ticks (each would be allowed
    // the maximum force change): the deadlines that passed are missed.
    if (wake - deadline >= period_ns)
      {
        const long long passed = (wake - deadline) / period_ns;
        deadline += passed * period_ns;
        misses += passed;
      }
    return wake;
  }



  bool
  HapticLoop::Impl::render_tick(const std::size_t i,
                                const long long   wake,
                                const long long   t0) noexcept
  {
    // The device's clock: the motion starts at the first tick after
    // start_motion().
    long long start = motion_start_ns.load(std::memory_order_relaxed);
    if (start < 0 && motion_requested.load(std::memory_order_acquire))
      {
        start             = wake - t0;
        motion_started_at = 1e-9 * start;
        motion_start_ns.store(start, std::memory_order_release);
      }
    const double t            = start < 0 ? 0.0 : 1e-9 * (wake - t0 - start);
    motion_elapsed            = std::min(t, motion_duration);
    const Utilities::Point3 x = device.position(t);

    timespec a, b;
    clock_gettime(CLOCK_MONOTONIC, &a);
    const Utilities::Point3 f = interaction.force(x);
    clock_gettime(CLOCK_MONOTONIC, &b);
    interpolation[i] = 1e-9 * (nanoseconds(b) - nanoseconds(a));
    device.render(f);
    if (t > 0 && !log.empty())
      log_force(t, x, f);
    ++n;

    return start >= 0 && (device.finished(t) || t > motion_duration);
  }



  void
  HapticLoop::Impl::log_force(const double             t,
                              const Utilities::Point3 &x,
                              const Utilities::Point3 &f) noexcept
  {
    const std::size_t h = log_head.load(std::memory_order_relaxed);
    if (h - log_tail.load(std::memory_order_acquire) < log.size())
      {
        log[h % log.size()] = {t, x, f};
        log_head.store(h + 1, std::memory_order_release);
      }
    else
      log_dropped.fetch_add(1, std::memory_order_relaxed);
  }



  // The loop at the device's rate: each tick waits for its deadline, then
  // (unless held) samples the timing and renders the force.
  void
  HapticLoop::Impl::run()
  {
    prepare_realtime();

    const long long period_ns =
      static_cast<long long>(std::llround(1e9 / rate));
    timespec now;
    clock_gettime(CLOCK_MONOTONIC, &now);
    const long long t0 = nanoseconds(now);
    t0_ns.store(t0, std::memory_order_release);
    long long deadline = t0, previous_wake = t0;
    bool      motion_over = false;
    while (!stop.load(std::memory_order_relaxed))
      {
        // A bounded loop's arrays hold its whole run; a continuous loop's
        // statistics wrap (the last continuous_window seconds).
        if (!continuous && n == capacity)
          {
            truncated = !motion_over;
            break;
          }
        double          late;
        const long long wake = wait_for_tick(deadline, period_ns, late);
        // Held (another thread changes the interaction): keep time only.
        // The tick is not sampled (it did no work).
        if (held())
          {
            previous_wake = wake;
            continue;
          }
        const std::size_t i = n % capacity;
        lateness[i]         = late;
        period[i]           = 1e-9 * (wake - previous_wake);
        previous_wake       = wake;

        if (render_tick(i, wake, t0))
          {
            motion_over = true;
            break;
          }
      }
    done.store(true, std::memory_order_release);
  }



  HapticLoop::HapticLoop(Interaction &interaction,
                         Device      &device,
                         const double rate,
                         const double max_seconds,
                         const bool   force_log)
    : impl(std::make_unique<Impl>(interaction,
                                  device,
                                  rate,
                                  max_seconds,
                                  force_log))
  {}



  std::size_t
  HapticLoop::max_ticks(const double rate, const double max_seconds)
  {
    return static_cast<std::size_t>(max_seconds * rate) + 16;
  }



  HapticLoop::~HapticLoop()
  {
    join();
  }



  void
  HapticLoop::start(const double motion_duration)
  {
    impl->motion_duration = motion_duration;
    impl->thread          = std::thread([this] { impl->run(); });
  }



  double
  HapticLoop::motion_time() const noexcept
  {
    const long long start =
      impl->motion_start_ns.load(std::memory_order_acquire);
    const long long t0 = impl->t0_ns.load(std::memory_order_acquire);
    if (start < 0 || t0 < 0)
      return -1;
    timespec now;
    clock_gettime(CLOCK_MONOTONIC, &now);
    return 1e-9 * (nanoseconds(now) - t0 - start);
  }



  void
  HapticLoop::start_motion() noexcept
  {
    // The loop thread starts the motion at its next tick (it may still be
    // setting itself up).
    impl->motion_requested.store(true, std::memory_order_release);
  }



  void
  HapticLoop::hold()
  {
    Impl &s = *impl;
    s.hold_requested.store(true);
    // The loop says it holds at its next tick; before its first, or after
    // its last, it cannot be in the force path. Sequentially consistent:
    // the loop clears `holding` before it reads the request, so a loop
    // that read no request cannot leave `holding` true behind.
    while (s.thread.joinable() && !s.done.load() && !s.holding.load())
      std::this_thread::sleep_for(std::chrono::microseconds(100));
  }



  void
  HapticLoop::release() noexcept
  {
    impl->hold_requested.store(false);
  }



  bool
  HapticLoop::finished() const noexcept
  {
    return impl->done.load(std::memory_order_acquire);
  }



  void
  HapticLoop::join()
  {
    impl->stop.store(true);
    if (impl->thread.joinable())
      impl->thread.join();
  }



  namespace
  {
    double
    percentile(std::vector<double> v, const double q)
    {
      if (v.empty())
        return 0;
      const std::size_t k =
        std::min(v.size() - 1, static_cast<std::size_t>(q * v.size()));
      std::nth_element(v.begin(), v.begin() + k, v.end());
      return v[k];
    }
  } // namespace



  void
  HapticLoop::add_to(RunSummary &r) const
  {
    const Impl &s = *impl;
    // The ticks sampled (a continuous loop's last window); the first of a
    // run has no previous tick.
    const std::size_t stored = std::min<std::uint64_t>(s.n, s.capacity);
    const std::size_t first =
      s.n <= s.capacity ? std::min<std::size_t>(1, stored) : 0;
    std::vector<double> period(s.period.begin() + first,
                               s.period.begin() + stored);
    std::vector<double> interpolation(s.interpolation.begin(),
                                      s.interpolation.begin() + stored);
    r.loop_ran              = true;
    r.realtime_priority     = s.realtime;
    r.loop_rate             = s.rate;
    r.ticks                 = s.n;
    r.statistics_window     = s.n > s.capacity ? s.capacity / s.rate : 0;
    r.deadline_misses       = s.misses;
    r.period_p50_ms         = 1000 * percentile(period, 0.5);
    r.period_p99_ms         = 1000 * percentile(period, 0.99);
    r.period_p999_ms        = 1000 * percentile(period, 0.999);
    r.period_max_ms         = period.empty() ?
                                0 :
                                1000 * *std::max_element(period.begin(), period.end());
    r.interpolation_p50_us  = 1e6 * percentile(interpolation, 0.5);
    r.interpolation_p999_us = 1e6 * percentile(interpolation, 0.999);
    r.memory_locked         = s.locked;
    r.loop_truncated        = s.truncated;
    r.motion_start    = s.motion_start_ns.load() < 0 ? -1 : s.motion_started_at;
    r.motion_duration = s.motion_elapsed;
  }



  std::size_t
  HapticLoop::drain_force_log(std::ostream &csv) const
  {
    const Impl       &s    = *impl;
    const std::size_t head = s.log_head.load(std::memory_order_acquire);
    std::size_t       tail = s.log_tail.load(std::memory_order_relaxed);
    const std::size_t n    = head - tail;
    // The rows in writes of whole rows, each flushed: a process killed
    // meanwhile leaves whole rows (a row cut in two by the stream's buffer
    // was what a SIGKILL left before).
    while (tail != head)
      {
        std::ostringstream rows;
        rows << std::setprecision(9);
        for (unsigned int k = 0; k < 4096 && tail != head; ++k, ++tail)
          {
            const auto &r = s.log[tail % s.log.size()];
            rows << r.t << "," << r.x[0] << "," << r.x[1] << "," << r.x[2]
                 << "," << r.f[0] << "," << r.f[1] << "," << r.f[2] << "\n";
          }
        s.log_tail.store(tail, std::memory_order_release);
        const std::string text = rows.str();
        csv.write(text.data(), static_cast<std::streamsize>(text.size()));
        csv.flush();
      }
    return n;
  }



  std::uint64_t
  HapticLoop::force_log_dropped() const noexcept
  {
    return impl->log_dropped.load();
  }



  void
  HapticLoop::write_force_log(const std::string &filename) const
  {
    std::ofstream out(filename);
    if (!out)
      throw std::runtime_error("cannot write '" + filename + "'");
    out << "t_s,x_m,y_m,z_m,fx_N,fy_N,fz_N\n";
    const std::size_t logged = drain_force_log(out);
    // A full disk shows only here: a cut log is an output error. What was
    // written is cut back to its last whole row, so that no row holds a
    // cut number, and the message says how many rows it keeps.
    out.close();
    if (!out)
      {
        const int   error = errno;
        std::string text;
        {
          std::ifstream      in(filename, std::ios::binary);
          std::ostringstream s;
          s << in.rdbuf();
          text = s.str();
        }
        const auto        end  = text.rfind('\n');
        const std::size_t keep = end == std::string::npos ? 0 : end + 1;
        std::error_code   ignored;
        std::filesystem::resize_file(filename, keep, ignored);
        const std::size_t rows =
          std::count(text.begin(), text.begin() + keep, '\n');
        throw std::runtime_error(
          "'" + filename + "' could not be written whole (" +
          std::strerror(error) + "): it keeps " +
          (rows > 0 ? "the first " + std::to_string(rows - 1) + " of " +
                        std::to_string(logged) + " rows, cut at a whole row" :
                      std::string("nothing")));
      }
  }
} // namespace palpate
