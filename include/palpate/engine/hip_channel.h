// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

#ifndef palpate_engine_hip_channel_h
#define palpate_engine_hip_channel_h

#include <palpate/base/utilities.h>

#include <atomic>
#include <cstdint>

namespace palpate
{
  /**
   * Where the haptic interaction point is and where it is going: written by
   * the real-time side at every tick, read by the scheduler and the shape
   * interpolator. One writer, any number of readers, a sequence lock: the
   * writer never waits, readers retry (they are not real-time).
   */
  class HipChannel
  {
  public:
    /** Publish position (m) and velocity (m/s). Real-time safe. */
    void
    write(const Utilities::Point3 &position,
          const Utilities::Point3 &velocity) noexcept
    {
      const std::uint32_t s = sequence.load(std::memory_order_relaxed);
      sequence.store(s + 1, std::memory_order_relaxed);
      std::atomic_thread_fence(std::memory_order_release);
      for (unsigned int d = 0; d < 3; ++d)
        {
          p[d].store(position[d], std::memory_order_relaxed);
          v[d].store(velocity[d], std::memory_order_relaxed);
        }
      sequence.store(s + 2, std::memory_order_release);
    }

    /** The latest position and velocity. */
    void
    read(Utilities::Point3 &position,
         Utilities::Point3 &velocity) const noexcept
    {
      while (true)
        {
          const std::uint32_t s1 = sequence.load(std::memory_order_acquire);
          if (s1 & 1)
            continue;
          for (unsigned int d = 0; d < 3; ++d)
            {
              position[d] = p[d].load(std::memory_order_relaxed);
              velocity[d] = v[d].load(std::memory_order_relaxed);
            }
          std::atomic_thread_fence(std::memory_order_acquire);
          if (sequence.load(std::memory_order_relaxed) == s1)
            return;
        }
    }

  private:
    std::atomic<std::uint32_t> sequence{0};
    std::atomic<double>        p[3] = {}, v[3] = {};
  };
} // namespace palpate

#endif
