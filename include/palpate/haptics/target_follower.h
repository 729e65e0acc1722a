// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

#ifndef palpate_haptics_target_follower_h
#define palpate_haptics_target_follower_h

#include <palpate/haptics/device.h>

#include <atomic>
#include <string>

namespace palpate
{
  /**
   * A device whose HIP follows a target another thread sets: the live
   * view's mouse (palpate serve), or a host program that sends where the
   * hand wants to be. Each tick it moves toward the target as a hand moves
   * a device: at most @p max_speed, speeding up and slowing down at most at
   * max_acceleration (the mouse's jumps smoothed: the velocity the
   * scheduler looks ahead with has no jumps), and stops on the target. It
   * runs until it is stopped (finished() is never true): the HapticLoop
   * that runs it is continuous (HapticLoop::continuous).
   *
   * set_target() and the readers (hip(), force(), target()) are for any
   * thread; position() and render() are the loop's (real-time: atomics
   * only). reset() puts the HIP back to rest and must be called while the
   * loop holds (HapticLoop::hold()).
   */
  class TargetFollower : public Device
  {
  public:
    /** How fast it speeds up and slows down (m/s^2): from rest to 5 cm/s
     * in 50 ms, a stop from it within 1.25 mm. */
    static constexpr double max_acceleration = 1.0;

    /** @p rate: the loop's (Hz), its step is one tick; @p max_speed in
     * m/s. */
    TargetFollower(const double rate, const double max_speed);

    Utilities::Point3
    position(const double t) noexcept override;

    void
    render(const Utilities::Point3 &force) noexcept override;

    /** Never: it follows its target until the loop is stopped. */
    bool
    finished(const double t) const noexcept override;

    /** Unbounded (infinity): run it in a continuous HapticLoop. */
    double
    max_duration() const override;

    std::string
    description() const override;

    /** Where the HIP should go (m, relative to rest). Any thread. */
    void
    set_target(const Utilities::Point3 &target) noexcept;

    Utilities::Point3
    target() const noexcept;

    /** The HIP and the force of the last tick. Any thread. */
    Utilities::Point3
    hip() const noexcept;
    Utilities::Point3
    force() const noexcept;

    /** Target, HIP and velocity back to rest (while the loop holds). */
    void
    reset() noexcept;

  private:
    const double        dt, max_speed;
    Utilities::Point3   x{{0, 0, 0}}, v{{0, 0, 0}}; // the loop's
    std::atomic<double> target_[3], hip_[3], force_[3];
  };
} // namespace palpate

#endif
