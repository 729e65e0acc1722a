// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

#ifndef palpate_haptics_haptic_loop_h
#define palpate_haptics_haptic_loop_h

#include <palpate/base/utilities.h>

#include <cstdint>
#include <iosfwd>
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
   * (periods, lateness, interpolation times) and its force log live in
   * arrays allocated before it starts: the loop itself never allocates.
   *
   * The motion starts when start_motion() is called (e.g. once the initial
   * cloud is computed); the loop ends when the device says the interaction
   * is over (Device::finished()), or when it is stopped (join()). Every
   * device runs in it alike, with the same priority, statistics, summary
   * and force log: a simulated trajectory for the run's time, and the live
   * view's mouse (TargetFollower) for as long as the view runs.
   */
  class HapticLoop
  {
  public:
    /**
     * For @p max_seconds: a loop that runs until it is stopped (the live
     * view). Its statistics cover the last continuous_window seconds
     * (they wrap), and its force log is a ring that drain_force_log()
     * empties while it runs.
     */
    static constexpr double continuous = 1e300;
    /** A continuous loop's statistics window (s). */
    static constexpr double continuous_window = 600;

    /**
     * @p rate in Hz; @p max_seconds bounds the whole run (waiting plus
     * motion) and sizes the statistics arrays and the force log, or is
     * continuous.
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

    /**
     * Hold the device: from the return of this call until release(), the
     * loop neither reads the device nor asks the interaction for a force
     * (it keeps time, and renders nothing new), so that another thread
     * may change the interaction's parameters or reset the device. Blocks
     * at most a tick. Not for the loop's own thread.
     */
    void
    hold();

    /** Let the held device go on (a no-op if it was not held). */
    void
    release() noexcept;

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

    /** Add the loop's statistics to @p summary (after join()). */
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

    /**
     * With a force log: write the rows logged since the last call to @p csv
     * (no header) in one write, then flush; returns how many. For a
     * continuous loop, while it runs (a thread other than the loop's): a
     * run that ends however it ends keeps what was drained.
     */
    std::size_t
    drain_force_log(std::ostream &csv) const;

    /** Ticks not logged because the force log's ring was full (a
     * continuous loop whose drain fell behind). */
    std::uint64_t
    force_log_dropped() const noexcept;

  private:
    struct Impl;
    std::unique_ptr<Impl> impl;
  };



  /** HapticLoop::hold() for a scope: released however the scope ends. */
  class HeldDevice
  {
  public:
    explicit HeldDevice(HapticLoop &loop)
      : loop(loop)
    {
      loop.hold();
    }

    ~HeldDevice()
    {
      loop.release();
    }

    HeldDevice(const HeldDevice &) = delete;
    HeldDevice &
    operator=(const HeldDevice &) = delete;

  private:
    HapticLoop &loop;
  };
} // namespace palpate

#endif
