// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

#ifndef palpate_haptics_force_interpolation_h
#define palpate_haptics_force_interpolation_h

#include <palpate/base/utilities.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>

namespace palpate
{
  class StateCache;
  class StateGrid;

  /** Why the interpolation at a position found no force. */
  enum class MissingCause : std::uint8_t
  {
    /** Nothing missing: all 8 corners were there. */
    none = 0,
    /** Corners not computed yet: they will come. */
    not_computed = 1,
    /** A corner is a failure point: no equilibrium was found there. */
    failure_region = 2,
    /** The position is outside the state space (or not finite). */
    outside = 3
  };

  /** What the interpolation found for one position. */
  struct ForceSample
  {
    /** Whether the position is inside the grid. */
    bool inside = false;
    /** How many corners are failure points (only counted if incomplete). */
    unsigned int failed = 0;
    /** The position in its cell, each coordinate in [0, 1]. */
    std::array<double, 3> local = {};
    /** The corners' forces (valid if complete). */
    std::array<Utilities::Point3, 8> corner_forces = {};

    MissingCause
    cause() const noexcept
    {
      return complete   ? MissingCause::none :
             !inside    ? MissingCause::outside :
             failed > 0 ? MissingCause::failure_region :
                          MissingCause::not_computed;
    }

    /** Trilinear force (N); zero unless complete. */
    Utilities::Point3 force = {{0, 0, 0}};
    /** Whether all 8 corners were available. */
    bool complete = false;
    /** How many corners were available (0 outside the grid). */
    unsigned int hits = 0;
    /** The corners' grid numbers (valid if hits > 0 or complete). */
    std::array<unsigned int, 8> corners = {};
    /** The corners the interpolation reads (bit k: corners[k]): all 8, or
     * the 4 of the position's tetrahedron. The haptic loop counts them as
     * read, and as used once the sample is complete. */
    std::uint8_t read = 0xff;
    /** Whether the force is tricubic Hermite (Hermite asked for and every
     * corner had its stiffness); else trilinear. */
    bool hermite = false;
    /** The stiffness of the interpolated field at the position, K = -df/dx
     * (N/m, row-major; valid if complete): for a device that renders a
     * local model between ticks. */
    std::array<double, 9> stiffness = {};
  };

  /** One of the interpolations below: the force at a position from the
   * states in a cache. */
  using InterpolateFunction =
    ForceSample (*)(const StateGrid &,
                    const StateCache &,
                    const Utilities::Point3 &) noexcept;

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
   * The force at @p x, tricubic Hermite: the tensor product
   * of 1-D cubic Hermite interpolation: at each corner it takes the force,
   * its first derivatives (minus the corner's active-node stiffness) and
   * the cross derivatives d2f/dxdy, d2f/dxdz, d2f/dydz, d3f/dxdydz that
   * the cache keeps for every point from its neighbours' stiffnesses
   * (StateCache::read_cross_derivatives()). Every corner value depends on
   * the corner alone, so the force and its derivative are continuous
   * across cell faces (C1); with all neighbours computed it reproduces
   * any force field of total degree 3 exactly. A cell with a corner that
   * has no stiffness is interpolated trilinearly (sample.hermite false).
   * Real-time safe: 16 lock-free reads, about 300 flops, no allocation.
   */
  ForceSample
  interpolate_hermite(const StateGrid         &grid,
                      const StateCache        &cache,
                      const Utilities::Point3 &x) noexcept;

  /**
   * The force at @p x linear on the tetrahedron of its cell's Kuhn
   * triangulation that holds it (simplex_weights()), from the forces of
   * its 4 corners: complete once those are computed, whatever the cell's
   * other corners (sample.read names them). What the contact patch
   * interpolation starts from (its patches then give the force,
   * PatchContact) and falls back to where a corner's patch was dropped.
   * Real-time safe: 4 lock-free reads.
   */
  ForceSample
  interpolate_on_tetrahedron(const StateGrid         &grid,
                             const StateCache        &cache,
                             const Utilities::Point3 &x) noexcept;

  /**
   * The stiffness n . K n = -n . (df/dx) n (N/m) of the interpolated force
   * field of the complete sample @p s along the unit vector @p n: how fast
   * the force along n grows when the probe moves against n.
   */
  double
  directional_stiffness(const ForceSample       &s,
                        const Utilities::Point3 &n) noexcept;

  /**
   * A safe force where no force can be computed: beyond the last complete
   * cell, in a failure region (no equilibrium exists, or none was found)
   * or outside the state space. The hand must not fall through the tissue
   * there, so the force is held from the last complete sample (position
   * x0, force f0, stiffness k along n = f0/|f0|) and extended as a
   * one-dimensional spring:
   *
   *   f(x) = max(0, |f0| - k (x - x0) . n) n.
   *
   * It is a gradient field (of a potential of s = (x - x0) . n alone), so
   * moving around in it creates no energy: passive. Pushing on against n
   * raises the force at the last stiffness; backing out releases it to zero.
   * Real-time safe.
   */
  class ForceHold
  {
  public:
    /** Remember the complete sample @p s at @p x. */
    void
    update(const Utilities::Point3 &x, const ForceSample &s) noexcept
    {
      const double magnitude = Utilities::norm(s.force);
      has_force              = magnitude > 1e-12;
      if (!has_force)
        return;
      origin = x;
      size   = magnitude;
      for (unsigned int d = 0; d < 3; ++d)
        normal[d] = s.force[d] / magnitude;
      const double k = directional_stiffness(s, normal);
      stiffness      = std::isfinite(k) ? std::max(0.0, k) : 0.0;
    }

    /** Whether a force is held (the last complete force was not zero). */
    bool
    valid() const noexcept
    {
      return has_force;
    }

    /** The held force at @p x (N). */
    Utilities::Point3
    force(const Utilities::Point3 &x) const noexcept
    {
      if (!has_force)
        return {{0, 0, 0}};
      double s = 0;
      for (unsigned int d = 0; d < 3; ++d)
        s += (x[d] - origin[d]) * normal[d];
      const double g = std::max(0.0, size - stiffness * s);
      return {{g * normal[0], g * normal[1], g * normal[2]}};
    }

    /** The held field's stiffness matrix -df/dx at @p x (N/m, row-major):
     * k n n^T while the spring pushes, zero once released. */
    std::array<double, 9>
    stiffness_matrix(const Utilities::Point3 &x) const noexcept
    {
      std::array<double, 9> K = {};
      if (!has_force || Utilities::norm(force(x)) == 0)
        return K;
      for (unsigned int i = 0; i < 3; ++i)
        for (unsigned int j = 0; j < 3; ++j)
          K[3 * i + j] = stiffness * normal[i] * normal[j];
      return K;
    }

    /** The stiffness along the held direction (N/m). */
    double
    held_stiffness() const noexcept
    {
      return stiffness;
    }

    void
    reset() noexcept
    {
      has_force = false;
    }

  private:
    bool              has_force = false;
    Utilities::Point3 origin = {{0, 0, 0}}, normal = {{0, 0, 0}};
    double            size = 0, stiffness = 0;
  };

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
