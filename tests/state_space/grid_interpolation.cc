// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

// The state grid and the force interpolation: index <-> position round
// trips; locating points (inside, on faces, on the outer boundary, outside,
// NaN); trilinear interpolation from the cache is exact for a trilinear
// force field, continuous across cell faces, and reports missing corners,
// failure points and generations that changed.

#include <palpate/haptics/force_interpolation.h>
#include <palpate/hyperelastic/contact_patch.h>
#include <palpate/hyperelastic/state.h>
#include <palpate/state_space/state_cache.h>
#include <palpate/state_space/state_grid.h>

#include <cmath>
#include <limits>
#include <random>

#include "../tests.h"

namespace
{
  using palpate::Utilities::Point3;

  /** A trilinear field: every monomial up to xyz. */
  Point3
  field(const Point3 &x)
  {
    const double a = x[0] * 100, b = x[1] * 100, c = x[2] * 100;
    return {{1 + 2 * a - b + 0.5 * c + 0.3 * a * b - 0.2 * b * c + 0.7 * c * a +
               0.1 * a * b * c,
             -0.5 + a * b * c,
             3 * c - a * c}};
  }

  void
  fill(const palpate::StateGrid &grid, palpate::StateCache &cache)
  {
    for (unsigned int p = 0; p < grid.size(); ++p)
      {
        auto s   = std::make_shared<palpate::State>();
        s->force = field(grid.position(p));
        cache.publish(p, s, cache.generation());
      }
  }
} // namespace

int
main(int argc, char **argv)
{
  palpate::Environment env(argc, argv);
  initlog();

  const palpate::StateGrid grid(0.005, 0.02);
  deallog << "grid: h = " << grid.spacing() << " m, half width "
          << grid.half_width() << ", " << grid.size() << " points" << std::endl;

  bool round_trip = true;
  for (unsigned int p = 0; p < grid.size(); ++p)
    round_trip = round_trip && grid.linear(grid.index(p)) == p &&
                 grid.nearest(grid.position(p)) == grid.index(p);
  deallog << "index <-> position round trips: " << (round_trip ? "yes" : "NO")
          << std::endl;

  palpate::GridIndex    lower;
  std::array<double, 3> local;
  for (const Point3 &x :
       std::vector<Point3>{{{0.0012, -0.0031, 0.007}},
                           {{0.005, 0.005, 0.005}},
                           {{0.02, -0.02, 0.0}},
                           {{0.0201, 0, 0}},
                           {{std::numeric_limits<double>::quiet_NaN(), 0, 0}}})
    {
      const bool inside = grid.locate(x, lower, local);
      deallog << "locate (" << palpate::Utilities::to_string(x, 4) << "): ";
      if (inside)
        deallog << "cell (" << lower[0] << ", " << lower[1] << ", " << lower[2]
                << "), local (" << local[0] << ", " << local[1] << ", "
                << local[2] << ")" << std::endl;
      else
        deallog << "outside" << std::endl;
    }

  palpate::StateCache cache(grid, 1 << 20);
  fill(grid, cache);
  std::mt19937                           random(3);
  std::uniform_real_distribution<double> u(-0.0199, 0.0199);
  double                                 worst = 0;
  for (unsigned int k = 0; k < 2000; ++k)
    {
      const Point3 x = {{u(random), u(random), u(random)}};
      const auto   s = palpate::interpolate_force(grid, cache, x);
      if (!s.complete)
        worst = 1e300;
      else
        worst =
          std::max(worst, palpate::Utilities::distance(s.force, field(x)));
    }
  deallog
    << "trilinear field reproduced at 2000 random points, error < 1e-12 N: "
    << (worst < 1e-12 ? "yes" : "NO") << std::endl;

  // Continuity across a face: just before and after x = 0.005.
  const Point3 before{{0.005 - 1e-12, 0.0013, -0.0041}},
    after{{0.005 + 1e-12, 0.0013, -0.0041}};
  const auto a = palpate::interpolate_force(grid, cache, before);
  const auto b = palpate::interpolate_force(grid, cache, after);
  deallog << "across a cell face the cells differ ("
          << (a.corners != b.corners ? "yes" : "NO")
          << ") and the force is continuous, jump < 1e-9 N: "
          << (palpate::Utilities::distance(a.force, b.force) < 1e-9 ? "yes" :
                                                                      "NO")
          << std::endl;

  // A failure point among the corners: incomplete, zero force.
  const unsigned int corner = a.corners[3];
  cache.publish_failure(corner, cache.generation());
  const auto c = palpate::interpolate_force(grid, cache, before);
  deallog << "with a failure point at a corner: complete " << c.complete << ", "
          << c.hits << " of 8 corners, force "
          << palpate::Utilities::norm(c.force) << " N" << std::endl;

  // A new generation: nothing is available, and late results of the old
  // generation are discarded.
  const auto old = cache.generation();
  cache.invalidate();
  auto late   = std::make_shared<palpate::State>();
  late->force = {{1, 2, 3}};
  cache.publish(corner, late, old);
  const auto counts = cache.counts();
  const auto d      = palpate::interpolate_force(grid, cache, before);
  deallog << "after invalidate(): " << counts.first << " available, "
          << counts.second
          << " failed, a late result of the old generation ignored ("
          << (cache.status(corner) == palpate::PointStatus::missing ? "yes" :
                                                                      "NO")
          << "), interpolation complete " << d.complete << std::endl;

  // The memory budget keeps the states near the focus.
  palpate::StateCache small(grid, 40 * sizeof(palpate::State));
  small.set_focus({{0, 0, 0}});
  fill(grid, small);
  const auto memory = small.memory();
  deallog << "budget of 40 states: " << memory.first << " held, "
          << small.n_evicted() << " dropped, nearest kept ("
          << (small.has_state(grid.linear({{0, 0, 1}})) ? "yes" : "NO")
          << "), forces still available (" << small.counts().first << ")"
          << std::endl;

  // Contact patches count in the budget and go with their states.
  auto patch = std::make_shared<palpate::ContactPatch>();
  patch->H.resize(90 * 90);
  patch->W.resize(30 * 30);
  const std::size_t   per_state = sizeof(palpate::State) + patch->memory();
  palpate::StateCache with_patches(grid, 10 * per_state);
  with_patches.set_focus({{0, 0, 0}});
  for (unsigned int p = 0; p < grid.size(); ++p)
    {
      auto s           = std::make_shared<palpate::State>();
      s->force         = field(grid.position(p));
      s->contact_patch = patch;
      with_patches.publish(p, s, with_patches.generation());
    }
  const auto   held_patches = with_patches.memory();
  unsigned int readable = 0, readable_held = 0;
  with_patches.begin_patch_reads();
  for (unsigned int p = 0; p < grid.size(); ++p)
    if (with_patches.read_patch(p, with_patches.generation()))
      {
        ++readable;
        readable_held += with_patches.has_state(p);
      }
  with_patches.end_patch_reads();
  deallog << "budget of 10 states with patches: " << held_patches.first
          << " held, within the budget ("
          << (held_patches.second <= 10 * per_state ? "yes" : "NO") << "), "
          << readable << " patches readable, all of held states ("
          << (readable == readable_held ? "yes" : "NO") << ")" << std::endl;

  // The tetrahedron's weights (simplex_weights()): at most 4 corners, a
  // partition of unity that reproduces linear functions (barycentric), 1 at
  // their own corner, and continuous across the tetrahedra's faces (a
  // point on the face x = y seen from both sides).
  {
    std::mt19937                           random(7);
    std::uniform_real_distribution<double> u(0, 1);
    bool   partition = true, linear = true, at_most_4 = true, corner = true;
    double jump = 0;
    for (unsigned int k = 0; k < 8; ++k)
      {
        const auto w = palpate::simplex_weights(
          {{double(k & 1), double((k >> 1) & 1), double((k >> 2) & 1)}});
        corner = corner && w[k] == 1;
      }
    for (unsigned int t = 0; t < 1000; ++t)
      {
        const std::array<double, 3> s    = {{u(random), u(random), u(random)}};
        const auto                  w    = palpate::simplex_weights(s);
        double                      sum  = 0;
        std::array<double, 3>       x    = {{0, 0, 0}};
        unsigned int                used = 0;
        for (unsigned int k = 0; k < 8; ++k)
          {
            sum += w[k];
            used += w[k] != 0;
            partition = partition && w[k] >= 0;
            for (unsigned int d = 0; d < 3; ++d)
              x[d] += w[k] * ((k >> d) & 1);
          }
        partition = partition && std::abs(sum - 1) < 1e-14;
        at_most_4 = at_most_4 && used <= 4;
        for (unsigned int d = 0; d < 3; ++d)
          linear = linear && std::abs(x[d] - s[d]) < 1e-14;
        const std::array<double, 3> below = {{s[0], s[0] - 1e-12, s[2]}},
                                    above = {{s[0], s[0] + 1e-12, s[2]}};
        const auto wb                     = palpate::simplex_weights(below),
                   wa                     = palpate::simplex_weights(above);
        for (unsigned int k = 0; k < 8; ++k)
          jump = std::max(jump, std::abs(wb[k] - wa[k]));
      }
    deallog << "tetrahedron weights: non-negative, sum 1 ("
            << (partition ? "yes" : "NO") << "), at most 4 corners ("
            << (at_most_4 ? "yes" : "NO") << "), linear functions exact ("
            << (linear ? "yes" : "NO") << "), 1 at their corner ("
            << (corner ? "yes" : "NO")
            << "), continuous across faces, jump < 1e-11: "
            << (jump < 1e-11 ? "yes" : "NO") << std::endl;
  }

  // The force on the HIP's tetrahedron (interpolate_on_tetrahedron()):
  // exact for a linear field, with its gradient; complete with its 4
  // corners alone.
  {
    auto linear_field = [](const Point3 &x) {
      return Point3{{3 * x[0] - 2 * x[1] + 0.1, x[1] + 5 * x[2], -4 * x[0]}};
    };
    const Point3          x = {{0.0012, -0.0031, 0.0071}};
    palpate::GridIndex    cell;
    std::array<double, 3> at;
    grid.locate(x, cell, at);
    const auto          corners = grid.corners(cell);
    const auto          path    = palpate::simplex_corners(at);
    palpate::StateCache only(grid, 1 << 20);
    for (const unsigned int k : path)
      {
        auto s   = std::make_shared<palpate::State>();
        s->force = linear_field(grid.position(corners[k]));
        only.publish(corners[k], s, only.generation());
      }
    const auto   t       = palpate::interpolate_on_tetrahedron(grid, only, x);
    const Point3 f       = linear_field(x);
    const double K[9]    = {-3, 2, 0, 0, -1, -5, 4, 0, 0};
    double       k_error = 0;
    for (unsigned int e = 0; e < 9; ++e)
      k_error = std::max(k_error, std::abs(t.stiffness[e] - K[e]));
    const auto full = palpate::interpolate_force(grid, only, x);
    // Without one of the 4: not complete, not computed.
    palpate::StateCache three(grid, 1 << 20);
    for (unsigned int k = 1; k < 4; ++k)
      three.publish(corners[path[k]],
                    only.state(corners[path[k]]),
                    three.generation());
    const auto missing = palpate::interpolate_on_tetrahedron(grid, three, x);
    deallog << "on the tetrahedron, 4 corners of 8 computed: complete ("
            << (t.complete ? "yes" : "NO")
            << "; trilinear needs all 8: " << (full.complete ? "NO" : "yes")
            << "), a linear field exact to 1e-12 ("
            << (palpate::Utilities::distance(t.force, f) < 1e-12 ? "yes" : "NO")
            << "), its stiffness too (" << (k_error < 1e-9 ? "yes" : "NO")
            << "); one of the 4 missing: complete "
            << (missing.complete ? "yes" : "no") << ", not computed ("
            << (missing.cause() == palpate::MissingCause::not_computed ? "yes" :
                                                                         "NO")
            << ")" << std::endl;
  }
}
