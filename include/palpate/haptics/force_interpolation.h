// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

#ifndef palpate_haptics_force_interpolation_h
#define palpate_haptics_force_interpolation_h

#include <palpate/base/utilities.h>

#include <algorithm>
#include <array>
#include <cmath>

namespace palpate
{
  class StateCache;
  class StateGrid;

  /** What the interpolation found for one position. */
  struct ForceSample
  {
    /** Trilinear force (N); zero unless complete. */
    Utilities::Point3 force = {{0, 0, 0}};
    /** Whether all 8 corners were available. */
    bool complete = false;
    /** How many corners were available (0 outside the grid). */
    unsigned int hits = 0;
    /** The corners' grid numbers (valid if hits > 0 or complete). */
    std::array<unsigned int, 8> corners = {};
  };

  /**
   * The force at @p x: trilinear interpolation of the cached forces at the
   * 8 corners of its cell, if all are available. Real-time safe: lock-free
   * cache reads, no allocation.
   */
  ForceSample
  interpolate_force(const StateGrid         &grid,
                    const StateCache        &cache,
                    const Utilities::Point3 &x) noexcept;

  /**
   * What turns interpolated forces into forces a device may render: a
   * missing sample fades to zero; a NaN or infinite sample is replaced by
   * zero; the magnitude is clamped to the device's limit; and the force
   * changes by at most a given amount per step, so there is never a jump.
   * Real-time safe.
   */
  class ForceFilter
  {
  public:
    /** @p force_limit and @p max_change in N. */
    ForceFilter(const double force_limit, const double max_change)
      : limit(force_limit)
      , step(max_change)
    {}

    /**
     * The next force to render for the sample @p target (used only if
     * @p complete). Sets @p rejected if the sample was not finite.
     */
    Utilities::Point3
    next(Utilities::Point3 target, const bool complete, bool &rejected) noexcept
    {
      rejected = false;
      if (!complete)
        target = {{0, 0, 0}};
      for (const double f : target)
        rejected = rejected || !std::isfinite(f);
      if (rejected)
        target = {{0, 0, 0}};
      const double magnitude = Utilities::norm(target);
      if (magnitude > limit)
        for (double &f : target)
          f *= limit / magnitude;
      Utilities::Point3 change;
      for (unsigned int d = 0; d < 3; ++d)
        change[d] = target[d] - current[d];
      const double size = Utilities::norm(change);
      if (size > step)
        for (double &c : change)
          c *= step / size;
      for (unsigned int d = 0; d < 3; ++d)
        current[d] += change[d];
      last_change = std::min(size, step);
      return current;
    }

    /** The force rendered last (N). */
    const Utilities::Point3 &
    force() const noexcept
    {
      return current;
    }

    /** The size of the last change (N). */
    double
    change() const noexcept
    {
      return last_change;
    }

  private:
    double            limit, step, last_change = 0;
    Utilities::Point3 current = {{0, 0, 0}};
  };
} // namespace palpate

#endif
