// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

// Tricubic Hermite force interpolation (State space / Interpolation =
// tricubic Hermite), from corner forces and stiffnesses published in the
// cache as the engine publishes them:
// - it reproduces a force field of total degree 3 exactly (to 1e-12 of
//   its size) in every cell whose neighbours are computed, and the
//   interpolated stiffness equals -df/dx; trilinear does not;
// - it is C1 across cell faces: force and stiffness on either side of a
//   face agree as the distance to the face goes to zero, also where
//   neighbours are missing (one-sided cross derivatives) - trilinear's
//   stiffness jumps;
// - on a smooth non-polynomial field its error falls 16x when h halves
//   (fourth order), trilinear's 4x;
// - a corner without a stiffness falls back to trilinear.

#include <palpate/haptics/force_interpolation.h>
#include <palpate/hyperelastic/state.h>
#include <palpate/state_space/state_cache.h>
#include <palpate/state_space/state_grid.h>

#include <cmath>
#include <functional>
#include <random>

#include "../tests.h"

namespace
{
  using palpate::Utilities::Point3;
  using Field = std::function<void(const Point3 &, Point3 &, double[9])>;

  /** The two interpolations compared. */
  enum class Scheme
  {
    hermite,
    trilinear
  };

  /** The force at @p x by @p scheme. */
  palpate::ForceSample
  interpolate(const palpate::StateGrid  &grid,
              const palpate::StateCache &cache,
              const Point3              &x,
              const Scheme               scheme)
  {
    return scheme == Scheme::hermite ?
             palpate::interpolate_hermite(grid, cache, x) :
             palpate::interpolate_force(grid, cache, x);
  }

  /** A force field of total degree 3 (every monomial, random
   * coefficients), and its stiffness K = -df/dx, in units of 1 cm. */
  Field
  cubic(const unsigned int seed)
  {
    std::mt19937                           rng(seed);
    std::uniform_real_distribution<double> u(-1, 1);
    // Exponents (a, b, c) with a + b + c <= 3: 20 monomials.
    std::vector<std::array<int, 3>> e;
    for (int a = 0; a <= 3; ++a)
      for (int b = 0; a + b <= 3; ++b)
        for (int c = 0; a + b + c <= 3; ++c)
          e.push_back({{a, b, c}});
    std::vector<std::array<double, 3>> coefficients(e.size());
    for (auto &c : coefficients)
      c = {{u(rng), u(rng), u(rng)}};
    return [e, coefficients](const Point3 &x, Point3 &f, double K[9]) {
      const double s[3] = {x[0] * 100, x[1] * 100, x[2] * 100};
      f                 = {{0, 0, 0}};
      std::fill(K, K + 9, 0.0);
      for (unsigned int m = 0; m < e.size(); ++m)
        {
          double v = 1, d[3] = {1, 1, 1};
          for (unsigned int a = 0; a < 3; ++a)
            {
              v *= std::pow(s[a], e[m][a]);
              for (unsigned int j = 0; j < 3; ++j)
                d[j] *= (a == j) ?
                          (e[m][a] > 0 ? e[m][a] * std::pow(s[a], e[m][a] - 1) :
                                         0.0) :
                          std::pow(s[a], e[m][a]);
            }
          for (unsigned int i = 0; i < 3; ++i)
            {
              f[i] += coefficients[m][i] * v;
              for (unsigned int j = 0; j < 3; ++j)
                K[3 * i + j] -= coefficients[m][i] * d[j] * 100;
            }
        }
    };
  }

  /** A smooth field that no polynomial matches. */
  void
  smooth(const Point3 &x, Point3 &f, double K[9])
  {
    const double a = 60 * x[0], b = 45 * x[1], c = 75 * x[2];
    f                    = {{std::sin(a) * std::cos(b) + c,
                             std::exp(0.5 * b) * std::sin(c),
                             std::cos(a + b + c)}};
    const double g[3][3] = {{60 * std::cos(a) * std::cos(b),
                             -45 * std::sin(a) * std::sin(b),
                             75},
                            {0,
                             22.5 * std::exp(0.5 * b) * std::sin(c),
                             75 * std::exp(0.5 * b) * std::cos(c)},
                            {-60 * std::sin(a + b + c),
                             -45 * std::sin(a + b + c),
                             -75 * std::sin(a + b + c)}};
    for (unsigned int i = 0; i < 3; ++i)
      for (unsigned int j = 0; j < 3; ++j)
        K[3 * i + j] = -g[i][j];
  }

  /** Publish @p field at every grid point (those @p skip says no to are
   * left missing; @p with_stiffness says who gets a stiffness). */
  void
  fill(const palpate::StateGrid                &grid,
       palpate::StateCache                     &cache,
       const Field                             &field,
       const std::function<bool(unsigned int)> &skip           = nullptr,
       const std::function<bool(unsigned int)> &with_stiffness = nullptr)
  {
    for (unsigned int p = 0; p < grid.size(); ++p)
      {
        if (skip && skip(p))
          continue;
        auto   s = std::make_shared<palpate::State>();
        double K[9];
        field(grid.position(p), s->force, K);
        std::copy(K, K + 9, s->stiffness.begin());
        s->has_stiffness = !with_stiffness || with_stiffness(p);
        cache.publish(p, s, cache.generation());
      }
  }

  /** Largest error of force (relative to the largest force) and of
   * stiffness (relative to the largest stiffness) at @p n random points
   * within @p radius of the origin. */
  std::pair<double, double>
  errors(const palpate::StateGrid  &grid,
         const palpate::StateCache &cache,
         const Field               &field,
         const Scheme               scheme,
         const double               radius,
         const unsigned int         n = 2000)
  {
    std::mt19937                           rng(7);
    std::uniform_real_distribution<double> u(-radius, radius);
    double                                 ef = 0, ek = 0, fmax = 0, kmax = 0;
    for (unsigned int t = 0; t < n; ++t)
      {
        const Point3 x = {{u(rng), u(rng), u(rng)}};
        Point3       f;
        double       K[9];
        field(x, f, K);
        const auto s = interpolate(grid, cache, x, scheme);
        if (!s.complete)
          return {-1, -1};
        for (unsigned int i = 0; i < 3; ++i)
          {
            ef   = std::max(ef, std::abs(s.force[i] - f[i]));
            fmax = std::max(fmax, std::abs(f[i]));
          }
        for (unsigned int i = 0; i < 9; ++i)
          {
            ek   = std::max(ek, std::abs(s.stiffness[i] - K[i]));
            kmax = std::max(kmax, std::abs(K[i]));
          }
      }
    return {ef / fmax, ek / kmax};
  }

  /** Largest jump of force and stiffness across the faces x = 0, y = 5 mm
   * and z = -5 mm at 200 random points each, @p d either side of the face
   * (relative to the largest force / stiffness seen). */
  std::pair<double, double>
  jumps(const palpate::StateGrid  &grid,
        const palpate::StateCache &cache,
        const Scheme               scheme,
        const double               d)
  {
    std::mt19937                           rng(11);
    std::uniform_real_distribution<double> u(-0.009, 0.009);
    double                                 jf = 0, jk = 0, fmax = 0, kmax = 0;
    for (unsigned int axis = 0; axis < 3; ++axis)
      for (unsigned int t = 0; t < 200; ++t)
        {
          Point3 a = {{u(rng), u(rng), u(rng)}};
          a[axis]  = axis == 0 ? 0.0 : axis == 1 ? 0.005 : -0.005;
          Point3 b = a;
          a[axis] -= d;
          b[axis] += d;
          const auto sa = interpolate(grid, cache, a, scheme);
          const auto sb = interpolate(grid, cache, b, scheme);
          if (!sa.complete || !sb.complete)
            return {-1, -1};
          for (unsigned int i = 0; i < 3; ++i)
            {
              jf   = std::max(jf, std::abs(sa.force[i] - sb.force[i]));
              fmax = std::max(fmax, std::abs(sa.force[i]));
            }
          for (unsigned int i = 0; i < 9; ++i)
            {
              jk   = std::max(jk, std::abs(sa.stiffness[i] - sb.stiffness[i]));
              kmax = std::max(kmax, std::abs(sa.stiffness[i]));
            }
        }
    return {jf / fmax, jk / kmax};
  }

  std::string
  name(const Scheme scheme)
  {
    return scheme == Scheme::hermite ? "Hermite  " : "trilinear";
  }
} // namespace

int
main(int argc, char **argv)
{
  palpate::Environment env(argc, argv);
  initlog();

  // Cubic fields: 5 mm grid of +-20 mm; points within 14 mm have all
  // neighbours of their cells.
  for (const unsigned int seed : {1u, 2u, 3u})
    {
      const palpate::StateGrid grid(0.005, 0.02);
      palpate::StateCache      cache(grid, 1 << 30);
      const Field              field = cubic(seed);
      fill(grid, cache, field);
      for (const auto scheme : {Scheme::hermite, Scheme::trilinear})
        {
          const auto [ef, ek] = errors(grid, cache, field, scheme, 0.014);
          deallog << "cubic field " << seed << ", " << name(scheme)
                  << ": exact to 1e-12: force " << ok(ef >= 0 && ef < 1e-12)
                  << ", stiffness " << ok(ek >= 0 && ek < 1e-12) << std::endl;
        }
    }

  // C1 across faces, on the smooth field; with every point computed, and
  // with neighbours missing around the faces (every third point beyond
  // the 2x2x2 cells around the origin's faces is left out).
  for (const bool holes : {false, true})
    {
      const palpate::StateGrid grid(0.005, 0.02);
      palpate::StateCache      cache(grid, 1 << 30);
      fill(grid, cache, smooth, [&](const unsigned int p) {
        const auto g = grid.index(p);
        const bool near =
          std::abs(g[0]) <= 2 && std::abs(g[1]) <= 2 && std::abs(g[2]) <= 2;
        return holes && !near && p % 3 == 0;
      });
      for (const auto scheme : {Scheme::hermite, Scheme::trilinear})
        {
          const auto [f1, k1] = jumps(grid, cache, scheme, 1e-7);
          const auto [f2, k2] = jumps(grid, cache, scheme, 1e-9);
          deallog << (holes ? "with missing neighbours, " : "") << name(scheme)
                  << ": force continuous " << ok(f2 >= 0 && f2 < 1e-6)
                  << ", stiffness continuous (jump -> 0 with the distance) "
                  << ok(k2 >= 0 && k2 < 1e-6 && k2 < 0.1 * k1 + 1e-12)
                  << std::endl;
        }
    }

  // Order of accuracy on the smooth field: h = 5, 2.5, 1.25 mm.
  for (const auto scheme : {Scheme::hermite, Scheme::trilinear})
    {
      std::vector<double> e;
      for (const double h : {0.005, 0.0025, 0.00125})
        {
          const palpate::StateGrid grid(h, 0.02);
          palpate::StateCache      cache(grid, 1 << 30);
          fill(grid, cache, smooth);
          e.push_back(errors(grid, cache, smooth, scheme, 0.012).first);
        }
      const double rate = std::log2(e[1] / e[2]);
      deallog << name(scheme) << ": force error falls as h^"
              << (scheme == Scheme::hermite ?
                    (rate > 3.5 ? "4" : "? (" + std::to_string(rate) + ")") :
                    (rate > 1.7 && rate < 2.3 ?
                       "2" :
                       "? (" + std::to_string(rate) + ")"))
              << "; error at h = 5 mm below trilinear's at 2.5 mm: ";
      if (scheme == Scheme::hermite)
        {
          const palpate::StateGrid grid(0.0025, 0.02);
          palpate::StateCache      cache(grid, 1 << 30);
          fill(grid, cache, smooth);
          const double trilinear =
            errors(grid, cache, smooth, Scheme::trilinear, 0.012).first;
          deallog << ok(e[0] < trilinear) << std::endl;
        }
      else
        deallog << "-" << std::endl;
    }

  // A corner without a stiffness: trilinear there.
  {
    const palpate::StateGrid grid(0.005, 0.02);
    palpate::StateCache      cache(grid, 1 << 30);
    const unsigned int       origin = grid.linear({{0, 0, 0}});
    fill(grid, cache, smooth, nullptr, [&](const unsigned int p) {
      return p != origin;
    });
    const auto a =
      palpate::interpolate_hermite(grid, cache, {{0.001, 0.002, 0.003}});
    const auto b =
      palpate::interpolate_hermite(grid, cache, {{0.006, 0.002, 0.003}});
    deallog << "a cell with a corner without stiffness is trilinear: "
            << ok(a.complete && !a.hermite)
            << "; its neighbour is Hermite: " << ok(b.complete && b.hermite)
            << std::endl;
  }
}
