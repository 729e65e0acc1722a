// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

// What the device receives: the ForceFilter (limit 2 N, at most 0.05 N
// change per tick) ramps toward complete samples, fades to zero when data
// is missing, replaces NaN and infinite samples by zero and clamps to the
// limit, without ever changing by more than 0.05 N per tick. Then the whole
// haptic-side chain (cache -> trilinear interpolation -> filter) along a
// 1 kHz path that crosses a cell with a failure point at a corner: the
// force fades to zero in the missing cell, never NaN, never a jump, and
// comes back to the interpolated value once the data is complete again.

#include <palpate/haptics/force_interpolation.h>
#include <palpate/hyperelastic/state.h>
#include <palpate/state_space/state_cache.h>
#include <palpate/state_space/state_grid.h>

#include <cmath>
#include <limits>

#include "../tests.h"

namespace
{
  using palpate::Utilities::Point3;

  /** Steps until the filter's output reaches @p target within 1e-12 N, with
   * the largest change per step and whether any output was non-finite or
   * above @p limit. */
  struct Ramp
  {
    unsigned int steps      = 0;
    double       max_change = 0;
    bool         finite = true, within_limit = true, any_rejected = false;
  };

  Ramp
  drive(palpate::ForceFilter &filter,
        const Point3         &sample,
        const bool            complete,
        const Point3         &target,
        const double          limit)
  {
    Ramp r;
    for (; r.steps < 1000; ++r.steps)
      {
        if (palpate::Utilities::distance(filter.force(), target) < 1e-12)
          break;
        const Point3 before = filter.force();
        bool         rejected;
        const Point3 f = filter.next(sample, complete, rejected);
        r.any_rejected = r.any_rejected || rejected;
        for (const double x : f)
          r.finite = r.finite && std::isfinite(x);
        r.within_limit =
          r.within_limit && palpate::Utilities::norm(f) <= limit + 1e-12;
        r.max_change =
          std::max(r.max_change, palpate::Utilities::distance(f, before));
      }
    return r;
  }

  void
  report(const std::string          &what,
         const Ramp                 &r,
         const palpate::ForceFilter &filter)
  {
    deallog << what << ": " << r.steps << " ticks, largest change "
            << r.max_change << " N, finite " << (r.finite ? "yes" : "NO")
            << ", within the limit " << (r.within_limit ? "yes" : "NO")
            << ", rejected " << (r.any_rejected ? "yes" : "no") << ", now ("
            << palpate::Utilities::to_string(filter.force(), 6) << ") N"
            << std::endl;
  }
} // namespace

int
main(int argc, char **argv)
{
  palpate::Environment env(argc, argv);
  initlog();

  const double         limit = 2, step = 0.05;
  palpate::ForceFilter filter(limit, step);
  const double         nan = std::numeric_limits<double>::quiet_NaN();
  const double         inf = std::numeric_limits<double>::infinity();

  // 1 N along x: 20 ticks of 0.05 N.
  report("ramp to (1, 0, 0)",
         drive(filter, {{1, 0, 0}}, true, {{1, 0, 0}}, limit),
         filter);
  // 5 N along y: clamped to 2 N; the change is a straight line from
  // (1, 0, 0) to (0, 2, 0), 2.236 N long: 45 ticks.
  report("toward (0, 5, 0), clamped",
         drive(filter, {{0, 5, 0}}, true, {{0, 2, 0}}, limit),
         filter);
  // Missing data: fades to zero at 0.05 N per tick, 40 ticks.
  report("missing data",
         drive(filter, {{0, 5, 0}}, false, {{0, 0, 0}}, limit),
         filter);
  // Back to 1 N, then NaN and infinite samples fade to zero like missing
  // data and are reported as rejected.
  drive(filter, {{0, 0, 1}}, true, {{0, 0, 1}}, limit);
  report("NaN sample",
         drive(filter, {{nan, 0, 1}}, true, {{0, 0, 0}}, limit),
         filter);
  drive(filter, {{0, 0, 1}}, true, {{0, 0, 1}}, limit);
  report("infinite sample",
         drive(filter, {{0, -inf, 0}}, true, {{0, 0, 0}}, limit),
         filter);

  // The chain along a path. A 5 mm grid, forces from a smooth field,
  // (1, 0, 0) a failure point: the cells with x in [0, 5] mm and
  // [5, 10] mm around y = z = 1 mm have it as a corner.
  const palpate::StateGrid grid(0.005, 0.02);
  palpate::StateCache      cache(grid, 1 << 20);
  const auto               field = [](const Point3 &x) {
    return Point3{
      {-40 * x[0] + 10 * x[1], 30 * x[1] * 100 * x[0], -50 * x[2] + 0.5}};
  };
  const unsigned int failure = grid.linear({{1, 0, 0}});
  for (unsigned int p = 0; p < grid.size(); ++p)
    if (p == failure)
      cache.publish_failure(p, cache.generation());
    else
      {
        auto s   = std::make_shared<palpate::State>();
        s->force = field(grid.position(p));
        cache.publish(p, s, cache.generation());
      }

  // The HIP moves from x = -10 mm to +20 mm at 20 mm/s, 1 kHz ticks.
  palpate::ForceFilter chain(8, step);
  unsigned int ticks = 0, missing = 0, first_missing = 0, last_missing = 0;
  double       max_change = 0, error_before = 0, error_after = 0, at_entry = 0;
  bool         finite = true, faded = false;
  for (; ticks <= 1500; ++ticks)
    {
      const Point3 x{{-0.01 + 0.02 * ticks * 1e-3, 0.001, 0.001}};
      const auto   sample = palpate::interpolate_force(grid, cache, x);
      const Point3 before = chain.force();
      bool         rejected;
      const Point3 f = chain.next(sample.force, sample.complete, rejected);
      for (const double v : f)
        finite = finite && std::isfinite(v);
      max_change =
        std::max(max_change, palpate::Utilities::distance(f, before));
      if (!sample.complete)
        {
          if (missing++ == 0)
            {
              first_missing = ticks;
              at_entry      = palpate::Utilities::norm(before);
            }
          last_missing = ticks;
          faded        = palpate::Utilities::norm(f) < 1e-12;
        }
      else if (missing == 0 && ticks > 100)
        error_before =
          std::max(error_before, palpate::Utilities::distance(f, field(x)));
      else if (missing > 0 && ticks > last_missing + 100)
        error_after =
          std::max(error_after, palpate::Utilities::distance(f, field(x)));
    }
  deallog << "path through the failure point's cells: " << ticks << " ticks, "
          << missing << " without complete data (ticks " << first_missing
          << " to " << last_missing << ")" << std::endl;
  deallog << "  force on entering " << at_entry
          << " N, faded to zero before leaving: " << (faded ? "yes" : "NO")
          << std::endl;
  deallog << "  finite: " << (finite ? "yes" : "NO")
          << ", largest change per tick " << max_change << " N (limit " << step
          << ")" << std::endl;
  deallog << "  equal to the (trilinear) field before and after the gap: "
          << (error_before < 1e-12 ? "exact" : "OFF") << ", "
          << (error_after < 1e-12 ? "exact" : "OFF") << std::endl;
}
