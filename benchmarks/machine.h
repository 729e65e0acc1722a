// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

// What a benchmark prints about the machine it ran on.

#ifndef palpate_benchmarks_machine_h
#define palpate_benchmarks_machine_h

#include <palpate/base/environment.h>

#include <pthread.h>
#include <sched.h>
#include <sys/mman.h>
#include <sys/resource.h>

#include <algorithm>
#include <atomic>
#include <cstdint>
#include <cstdlib>
#include <ctime>
#include <fstream>
#include <string>
#include <thread>
#include <utility>
#include <vector>

/** The processor model, the number of cores and the BLAS kernels, e.g.
 * "AMD EPYC, 2 cores, OpenBLAS, Zen kernels". */
inline std::string
machine()
{
  std::ifstream cpuinfo("/proc/cpuinfo");
  std::string   line, model = "?";
  while (std::getline(cpuinfo, line))
    if (line.rfind("model name", 0) == 0)
      {
        model = line.substr(line.find(':') + 2);
        break;
      }
  const std::string &blas = palpate::Environment::blas();
  return model + ", " + std::to_string(std::thread::hardware_concurrency()) +
         " cores" + (blas.empty() ? "" : ", " + blas);
}

/**
 * The platform's own timer noise: a bare loop at @p rate (Hz) for
 * @p seconds with the haptic loop's settings (SCHED_FIFO 80, locked
 * memory, absolute deadlines on CLOCK_MONOTONIC) and nothing else to do.
 * Returns the deadlines it missed by more than 0.5 ms (the haptic loop's
 * criterion) and the latest wake-up (s): the machine's (a virtual
 * machine's host, interrupts), not palpate's. With @p load busy threads
 * at nice 10 (the solver workers' priority) beside it: the same machine
 * as an interaction sees it.
 */
inline std::pair<std::uint64_t, double>
bare_loop(const double seconds, const double rate, const unsigned int load = 0)
{
  std::uint64_t     misses = 0;
  double            late   = 0;
  std::atomic<bool> stop{false};
  // With @p load: that many threads at nice 10 streaming through 64 MiB
  // each, as solver workers keep the cores and the memory busy.
  std::vector<std::thread> workers;
  for (unsigned int w = 0; w < load; ++w)
    workers.emplace_back([&stop] {
      setpriority(PRIO_PROCESS, 0, 10);
      std::vector<double> a(8 << 20, 1.0);
      double              sum = 0;
      while (!stop.load(std::memory_order_relaxed))
        for (std::size_t i = 0; i < a.size(); i += 8)
          sum += a[i] *= 1.0000001;
      if (sum == 42)
        std::abort();
    });
  std::thread loop([&] {
    sched_param parameters{};
    parameters.sched_priority = 80;
    pthread_setschedparam(pthread_self(), SCHED_FIFO, &parameters);
    mlockall(MCL_CURRENT);
    timespec now;
    clock_gettime(CLOCK_MONOTONIC, &now);
    long long       deadline = now.tv_sec * 1000000000LL + now.tv_nsec;
    const long long period   = static_cast<long long>(1e9 / rate);
    for (long k = 0; k < static_cast<long>(rate * seconds); ++k)
      {
        deadline += period;
        const timespec next{static_cast<time_t>(deadline / 1000000000LL),
                            static_cast<long>(deadline % 1000000000LL)};
        clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &next, nullptr);
        clock_gettime(CLOCK_MONOTONIC, &now);
        const double l =
          1e-9 * (now.tv_sec * 1000000000LL + now.tv_nsec - deadline);
        misses += l > 0.5e-3;
        late = std::max(late, l);
      }
  });
  loop.join();
  stop = true;
  for (auto &w : workers)
    w.join();
  return {misses, late};
}

#endif
