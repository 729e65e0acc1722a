// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

#ifndef palpate_haptics_haptic_loop_h
#define palpate_haptics_haptic_loop_h

#include <palpate/base/utilities.h>

#include <memory>
#include <string>

namespace palpate
{
  class Interaction;
  class Trajectory;
  struct RunSummary;

  /**
   * A haptic device as the loop sees it: where the HIP is, and the force
   * to render there.
   */
  class Device
  {
  public:
    virtual ~Device() = default;

    /** The HIP's position (m, relative to the active node's rest
     * position) at time @p t (s) since its motion started (<= 0: at
     * rest). Real-time safe. */
    virtual Utilities::Point3
    position(const double t) noexcept = 0;

    /** Render @p force (N). Real-time safe. */
    virtual void
    render(const Utilities::Point3 &force) noexcept = 0;

    /** One line for reports. */
    virtual std::string
    description() const = 0;
  };

  /**
   * The paper's simulated device: the HIP follows a trajectory, and the
   * rendered forces go nowhere, or, with Effects / Force log, into a
   * preallocated log written as CSV after the run.
   */
  class SimulatedDevice : public Device
  {
  public:
    /** @p log_capacity ticks of force log (0: no log, no work). */
    SimulatedDevice(std::unique_ptr<Trajectory> trajectory,
                    const std::size_t           log_capacity);

    ~SimulatedDevice() override;

    Utilities::Point3
    position(const double t) noexcept override;

    void
    render(const Utilities::Point3 &force) noexcept override;

    std::string
    description() const override;

    /** The trajectory's length (s). */
    double
    duration() const;

    /** Write the force log (t s, position m, force N) as CSV. */
    void
    write_force_log(const std::string &filename) const;

  private:
    struct Impl;
    std::unique_ptr<Impl> impl;
  };

  /**
   * The built-in haptic thread: at Haptics / Loop rate, with absolute
   * deadlines on the steady clock, it reads the device's position, asks the
   * Interaction for the force and renders it. It asks for real-time
   * priority (SCHED_FIFO) and reports whether it got it. Its statistics
   * (periods, lateness, interpolation times) live in arrays allocated
   * before it starts: the loop itself never allocates.
   *
   * The motion starts when start_motion() is called (e.g. once the initial
   * cloud is computed); the loop ends when the motion is over.
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
               const double max_seconds);

    ~HapticLoop();

    /** The most ticks a loop at @p rate bounded by @p max_seconds runs
     * (what a device's preallocated log must hold). */
    static std::size_t
    max_ticks(const double rate, const double max_seconds);

    /** Start the thread; the HIP rests until start_motion(). */
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

  private:
    struct Impl;
    std::unique_ptr<Impl> impl;
  };
} // namespace palpate

#endif
