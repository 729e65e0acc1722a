// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

#include <palpate/haptics/target_follower.h>

#include <cmath>
#include <limits>

namespace palpate
{
  TargetFollower::TargetFollower(const double rate, const double max_speed)
    : dt(1.0 / rate)
    , max_speed(max_speed)
  {
    for (unsigned int k = 0; k < 3; ++k)
      {
        target_[k].store(0);
        hip_[k].store(0);
        force_[k].store(0);
      }
  }



  Utilities::Point3
  TargetFollower::position(const double) noexcept
  {
    const double      dv_max = max_acceleration * dt;
    Utilities::Point3 d;
    for (unsigned int k = 0; k < 3; ++k)
      d[k] = target_[k].load(std::memory_order_relaxed) - x[k];
    const double n = Utilities::norm(d);
    // Toward the target at the speed from which it can still stop there
    // (at most max_speed); the velocity changes by at most dv_max per
    // tick.
    const double reach =
      std::min(max_speed, std::sqrt(2 * max_acceleration * n));
    Utilities::Point3 dv;
    for (unsigned int k = 0; k < 3; ++k)
      dv[k] = (n > 0 ? reach * d[k] / n : 0.0) - v[k];
    const double change = Utilities::norm(dv);
    for (unsigned int k = 0; k < 3; ++k)
      v[k] += change > dv_max ? dv[k] * dv_max / change : dv[k];
    // Within this tick's step, slow (as the approach leaves it: at most
    // 2 mm/s at 1 kHz) and heading for it: on the target, at rest. Moving
    // away or fast, as when the target came back toward the probe, it
    // brakes at max_acceleration instead.
    const double speed   = Utilities::norm(v);
    double       heading = 0;
    for (unsigned int k = 0; k < 3; ++k)
      heading += v[k] * d[k];
    if (speed * dt >= n && speed <= 2 * dv_max * (1 + 1e-9) &&
        (n == 0 || heading > 0))
      for (unsigned int k = 0; k < 3; ++k)
        {
          x[k] += d[k];
          v[k] = 0;
        }
    else
      for (unsigned int k = 0; k < 3; ++k)
        x[k] += v[k] * dt;
    for (unsigned int k = 0; k < 3; ++k)
      hip_[k].store(x[k], std::memory_order_relaxed);
    return x;
  }



  void
  TargetFollower::render(const Utilities::Point3 &force) noexcept
  {
    for (unsigned int k = 0; k < 3; ++k)
      force_[k].store(force[k], std::memory_order_relaxed);
  }



  bool
  TargetFollower::finished(const double) const noexcept
  {
    return false;
  }



  double
  TargetFollower::max_duration() const
  {
    return std::numeric_limits<double>::infinity();
  }



  std::string
  TargetFollower::description() const
  {
    return "a target follower (the live view's mouse), at most " +
           Utilities::to_string(1000 * max_speed, 4) + " mm/s";
  }



  void
  TargetFollower::set_target(const Utilities::Point3 &target) noexcept
  {
    for (unsigned int k = 0; k < 3; ++k)
      target_[k].store(target[k], std::memory_order_relaxed);
  }



  Utilities::Point3
  TargetFollower::target() const noexcept
  {
    return {{target_[0].load(), target_[1].load(), target_[2].load()}};
  }



  Utilities::Point3
  TargetFollower::hip() const noexcept
  {
    return {{hip_[0].load(), hip_[1].load(), hip_[2].load()}};
  }



  Utilities::Point3
  TargetFollower::force() const noexcept
  {
    return {{force_[0].load(), force_[1].load(), force_[2].load()}};
  }



  void
  TargetFollower::reset() noexcept
  {
    set_target({{0, 0, 0}});
    x = {{0, 0, 0}};
    v = {{0, 0, 0}};
    for (unsigned int k = 0; k < 3; ++k)
      hip_[k].store(0);
  }
} // namespace palpate
