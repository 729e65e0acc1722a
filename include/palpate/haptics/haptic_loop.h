// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

#ifndef palpate_haptics_haptic_loop_h
#define palpate_haptics_haptic_loop_h

#include <palpate/base/utilities.h>

#include <memory>
#include <string>

namespace palpate
{
  class Device;
  class Interaction;
  struct RunSummary;

  /**
   * The built-in haptic thread: at Haptics / Loop rate, with absolute
   * deadlines on the steady clock, it reads the device's position, asks the
   * Interaction for the force and renders it. It asks for real-time
   * priority (SCHED_FIFO) and reports whether it got it. Its statistics
   * (periods, lateness, interpolation times) live in arrays allocated
   * before it starts: the loop itself never allocates.
   *
   * The motion starts when start_motion() is called (e.g. once the initial
   * cloud is computed); the loop ends when the device says the interaction
   * is over (Device::finished()). Every device runs in it alike, with the
   * same priority, statistics, summary and force log.
   */
  class HapticLoop
  {
  public:
    /**
     * @p rate in Hz; @p max_seconds bounds the whole run (waiting plus
     * motion) and sizes the statistics arrays.
     */
    HapticLoop(Interaction &interaction,
               Device      &device,
               const double rate,
               const double max_seconds,
               const bool   force_log = false);

    ~HapticLoop();

    /** The most ticks a loop at @p rate bounded by @p max_seconds runs
     * (what a device's preallocated log must hold). */
    static std::size_t
    max_ticks(const double rate, const double max_seconds);

    /** Start the thread; the HIP rests until start_motion(). The motion
     * lasts until the device says so, at most @p motion_duration (s). */
    void
    start(const double motion_duration);

    /** Start the device's motion at the loop's next tick. */
    void
    start_motion() noexcept;

    /** Whether the motion is over (or the time bound reached). */
    bool
    finished() const noexcept;

    /**
     * The device's clock: seconds since the motion started (the force
     * log's time base), negative before it did. Any thread.
     */
    double
    motion_time() const noexcept;

    /** Stop (if still running) and wait for the thread. */
    void
    join();

    /** Add the loop's statistics to @p summary. */
    void
    add_to(RunSummary &summary) const;

    /**
     * With a force log: write it as CSV (t s, HIP position m, force N, a
     * row per tick of the motion; the wait before it is not logged). A
     * full disk cuts it back to its last whole row and throws, saying how
     * many rows it keeps.
     */
    void
    write_force_log(const std::string &filename) const;

  private:
    struct Impl;
    std::unique_ptr<Impl> impl;
  };
} // namespace palpate

#endif
