// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

// State space / Interpolation = contact patch on the beam (2.5 mm
// neo-Hookean elements) touched by a 1 cm sphere, 5 mm grid: the states'
// patches solved by PatchContact as the haptic loop does, tick by tick.
// - At a grid point the force is the state's (1e-9 relative).
// - Above the surface it is exactly zero.
// - Along a line through contact onset (between grid lines) it is
//   continuous tick to tick and grows monotonically with depth.
// - Inside cells it is within 5 % of direct solves there (of
//   max(|f|, 0.05 N), the benchmark's measure).
// - A closed loop of the sphere in the tissue does next to no net work.
// - The ticks allocate nothing (operator new is counted).

#include <palpate/hyperelastic/contact_patch.h>
#include <palpate/hyperelastic/patch_contact.h>
#include <palpate/hyperelastic/state_solver.h>
#include <palpate/state_space/state_cache.h>
#include <palpate/state_space/state_grid.h>

#include <atomic>
#include <cmath>
#include <cstdlib>
#include <map>
#include <new>

#include "../tests.h"

namespace
{
  std::atomic<bool>          counting{false};
  std::atomic<unsigned long> allocations{0};
} // namespace

void *
operator new(std::size_t size)
{
  if (counting.load(std::memory_order_relaxed))
    allocations.fetch_add(1, std::memory_order_relaxed);
  if (void *p = std::malloc(size ? size : 1))
    return p;
  throw std::bad_alloc();
}

void
operator delete(void *p) noexcept
{
  std::free(p);
}

void
operator delete(void *p, std::size_t) noexcept
{
  std::free(p);
}

namespace
{
  using palpate::Utilities::Point3;

  /** The grid's states around rest and the rendered force from them. */
  struct Patches
  {
    Patches(const palpate::Scene &scene)
      : body(scene)
      , solver(body.mesh, body.nodes, scene.parameters)
      , direct(body.mesh, body.nodes, scene.parameters)
      , grid(scene.parameters.state_space.grid_spacing, 0.02)
      , cache(grid, std::size_t(1) << 32)
      , contact(body.mesh.n_vertices(), 256)
      , rest(direct.rest_state())
    {
      // x and y within a cell of rest either way, z from 5 mm deep to
      // 5 mm above: each state from its nearest computed neighbour, as
      // an engine worker computes it.
      std::vector<unsigned int> points;
      for (int i = -1; i <= 1; ++i)
        for (int j = -1; j <= 1; ++j)
          for (int k = -1; k <= 1; ++k)
            points.push_back(grid.linear({{i, j, k}}));
      std::sort(points.begin(), points.end(), [&](unsigned a, unsigned b) {
        return palpate::Utilities::norm(grid.position(a)) <
               palpate::Utilities::norm(grid.position(b));
      });
      const palpate::State start = solver.rest_state();
      for (const unsigned int q : points)
        {
          const palpate::State *from = &start;
          double best = palpate::Utilities::norm(grid.position(q));
          for (const auto &[r, s] : states)
            if (const double d = palpate::Utilities::distance(grid.position(r),
                                                              grid.position(q));
                d < best)
              best = d, from = s.get();
          auto s = std::make_shared<palpate::State>(
            solver.solve(*from, grid.position(q)));
          if (s->converged && s->contact_patch)
            {
              cache.publish(q, s, cache.generation());
              states[q] = s;
            }
        }
    }

    /** One tick at @p x: the blend of the cell's patches (false if a
     * corner is missing). */
    bool
    tick(const Point3 &x, Point3 &f)
    {
      palpate::GridIndex    lower;
      std::array<double, 3> local;
      if (!grid.locate(x, lower, local))
        return false;
      const auto corners = grid.corners(lower);
      std::array<const palpate::ContactPatch *, 8> patches;
      counting = true;
      cache.begin_patch_reads();
      bool all = true;
      for (unsigned int c = 0; c < 8; ++c)
        all = all &&
              (patches[c] = cache.read_patch(corners[c], cache.generation()));
      if (all)
        contact.blend(patches, palpate::simplex_weights(local), x, f);
      cache.end_patch_reads();
      counting = false;
      return all;
    }

    Body                  body;
    palpate::StateSolver  solver, direct;
    palpate::StateGrid    grid;
    palpate::StateCache   cache;
    palpate::PatchContact contact;
    palpate::State        rest;
    std::map<unsigned int, std::shared_ptr<const palpate::State>> states;
  };

  Point3
  between(const Point3 &a, const Point3 &b, const double t)
  {
    return {{a[0] + t * (b[0] - a[0]),
             a[1] + t * (b[1] - a[1]),
             a[2] + t * (b[2] - a[2])}};
  }
} // namespace



int
main(int argc, char **argv)
{
  palpate::Environment env(argc, argv);
  initlog();

  palpate::Scene scene = shipped_scene("beam.prm");
  touch_beam_with_sphere(scene, 0.01);
  beam_with_contact_patches(scene);
  auto &p = scene.parameters;
  p.material_model.set("Neo-Hookean", "Young's modulus", 1e5);
  p.material_model.set("Neo-Hookean", "Poisson's ratio", 0.3);
  p.state_space.grid_spacing            = 0.005;
  p.nonlinear_solver.residual_tolerance = 1e-10;
  Patches patches(scene);
  deallog << "states with a patch: " << patches.states.size() << " of 27"
          << std::endl;

  // At the grid points, each patch alone (a solver that has not seen it).
  {
    double worst = 0;
    for (const auto &[q, s] : patches.states)
      {
        palpate::PatchContact fresh(patches.body.mesh.n_vertices(), 256);
        Point3                f;
        fresh.force(*s->contact_patch, patches.grid.position(q), f);
        if (palpate::Utilities::norm(s->force) > 0)
          worst = std::max(worst,
                           palpate::Utilities::distance(f, s->force) /
                             palpate::Utilities::norm(s->force));
        else
          worst = std::max(worst, palpate::Utilities::norm(f));
      }
    deallog << "at the grid points the state's force to 1e-9: "
            << (worst <= 1e-9 ? "yes" : "NO") << std::endl;
  }

  // Held still at each grid point in the tissue for a second of ticks:
  // the step must be stable where the model is (the nodes must not slide
  // round the sphere), so the force stays the state's.
  {
    double drift = 0;
    for (const auto &[q, s] : patches.states)
      {
        palpate::PatchContact held(patches.body.mesh.n_vertices(), 256);
        Point3                f;
        for (unsigned int t = 0; t < 1000; ++t)
          held.force(*s->contact_patch, patches.grid.position(q), f);
        drift = std::max(drift,
                         palpate::Utilities::distance(f, s->force) /
                           std::max(palpate::Utilities::norm(s->force), 0.05));
      }
    deallog << "held 1000 ticks at each grid point, the state's force to "
               "1e-6: "
            << (drift <= 1e-6 ? "yes" : "NO") << std::endl;
  }

  // Above the surface, on a line between grid lines.
  {
    unsigned int nonzero = 0, ticks = 0;
    for (double z = 0.0045; z >= 0.0005; z -= 0.0001, ++ticks)
      {
        Point3 f;
        patches.tick({{0.0013, 0.0007, z}}, f);
        nonzero += f[0] != 0 || f[1] != 0 || f[2] != 0;
      }
    deallog << "above the surface (" << ticks
            << " ticks): the force exactly zero: "
            << (nonzero == 0 ? "yes" : "NO") << std::endl;
  }

  // Through onset to 6 mm deep in 0.02 mm ticks: continuous, monotone.
  {
    Point3       last = {{0, 0, 0}}, f;
    double       jump = 0, largest = 0, decrease = 0, onset = 1;
    const Point3 from    = {{0.0013, 0.0007, 0.0005}},
                 to      = {{0.0013, 0.0007, -0.0045}};
    const unsigned int n = 250;
    for (unsigned int t = 0; t <= n; ++t)
      {
        const Point3 x = between(from, to, double(t) / n);
        patches.tick(x, f);
        jump     = std::max(jump, palpate::Utilities::distance(f, last));
        decrease = std::max(decrease, last[2] - f[2]);
        largest  = std::max(largest, palpate::Utilities::norm(f));
        if (f[2] > 0 && onset > 0.5)
          onset = x[2];
        last = f;
      }
    deallog << "through onset: touches at z = "
            << palpate::Utilities::to_string(1e3 * onset, 1)
            << " mm, largest force "
            << palpate::Utilities::to_string(largest, 2)
            << " N; largest change per tick below 1 % of it: "
            << (jump < 0.01 * largest ? "yes" : "NO")
            << ", the push never decreases with depth: "
            << (decrease <= 1e-9 * largest ? "yes" : "NO") << std::endl;
  }

  // Inside cells against direct solves: approached by ticks along a line.
  {
    const std::vector<Point3> at    = {{{0.0013, 0.0007, -0.002}},
                                       {{0.0025, -0.0012, -0.0035}},
                                       {{-0.0018, 0.0011, -0.0042}},
                                       {{-0.0031, -0.0024, -0.0027}},
                                       {{0.0004, 0.0036, -0.0046}}};
    double                    worst = 0;
    for (const Point3 &x : at)
      {
        const palpate::State d = patches.direct.solve(patches.rest, x);
        Point3               f;
        for (unsigned int t = 0; t <= 200; ++t)
          patches.tick(between({{0, 0, 0}}, x, std::min(1.0, t / 150.0)), f);
        worst = std::max(worst,
                         100 * palpate::Utilities::distance(f, d.force) /
                           std::max(palpate::Utilities::norm(d.force), 0.05));
      }
    // Each corner's model corrected by its stiffening at the other
    // corners (PatchContact::blend()): 1.0 % here; the models alone 3.6 %.
    deallog << "inside cells, against direct solves within 2 %: "
            << (worst <= 2 ? "yes" : "NO") << std::endl;
  }

  // A closed loop in the tissue: a circle of 2.5 mm radius in the x-z
  // plane around 3 mm deep, 2000 ticks.
  {
    const unsigned int n    = 2000;
    double             work = 0, total = 0;
    Point3             x0 = {{0.0025, 0.0007, -0.003}}, f0;
    for (unsigned int t = 0; t < 50; ++t)
      patches.tick(x0, f0);
    for (unsigned int t = 1; t <= n; ++t)
      {
        const double a  = 2 * M_PI * t / n;
        const Point3 x1 = {
          {0.0025 * std::cos(a), 0.0007, -0.003 + 0.0025 * std::sin(a)}};
        Point3 f1;
        patches.tick(x1, f1);
        for (unsigned int d = 0; d < 3; ++d)
          {
            const double w = 0.5 * (f0[d] + f1[d]) * (x1[d] - x0[d]);
            work += w;
            total += std::abs(w);
          }
        x0 = x1;
        f0 = f1;
      }
    deallog << "a closed loop: net work below 2 % of the work done: "
            << (std::abs(work) < 0.02 * total ? "yes" : "NO") << std::endl;
  }

  deallog << "allocations in the ticks: " << allocations.load() << std::endl;
}
