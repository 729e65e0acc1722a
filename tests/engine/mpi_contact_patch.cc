// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

// Interpolation = contact patch with the MPI engine (1 client + 2 solver
// servers): each result carries its state's contact patch, and the
// client's cache holds it for the haptic loop. On the beam pressed by a
// 1 cm sphere (2 mm grid, 3.5 mm cloud, the HIP resting at three
// positions), every point both engines computed has a patch on the
// client too, of the same nodes, with the same force and positions as
// the threaded engine's (1e-6 relative: the two engines may reach a point
// from different neighbours), and the same compliance to 1e-3: a state's
// patch comes from the factors its Newton solve makes once the relative
// residual is below 1e-4 (Nonlinear solver's patch_factor_residual), at an
// iterate that depends on the neighbour it started from (measured 1.4e-4
// apart). The rendered force between the states (PatchContact::blend at
// positions between the grid points) is the same from either cache to
// 1e-5 for the same reason (measured 8e-7).

#include <palpate/engine/hip_channel.h>
#include <palpate/engine/mpi_engine.h>
#include <palpate/engine/thread_engine.h>
#include <palpate/hyperelastic/contact_patch.h>
#include <palpate/hyperelastic/patch_contact.h>
#include <palpate/state_space/state_cache.h>
#include <palpate/state_space/state_grid.h>

#include <chrono>
#include <cmath>
#include <thread>

#include "../tests.h"

#include "rest_until_idle.h"

namespace
{
  using palpate::Utilities::Point3;

  const std::vector<Point3> path = {{{0, 0, -0.001}},
                                    {{0.002, 0, -0.003}},
                                    {{0.002, 0.002, -0.003}}};


  double
  relative(const std::vector<double> &a, const std::vector<double> &b)
  {
    if (a.size() != b.size())
      return 1;
    double d = 0, s = 0;
    for (unsigned int i = 0; i < a.size(); ++i)
      {
        d = std::max(d, std::abs(a[i] - b[i]));
        s = std::max(s, std::abs(b[i]));
      }
    return s > 0 ? d / s : d;
  }

  /** The force PatchContact renders at @p x from @p cache's patches of
   * the cell around it (zero if a corner has none). */
  Point3
  rendered(const palpate::StateCache &cache,
           const palpate::StateGrid  &grid,
           palpate::PatchContact     &contact,
           const Point3              &x)
  {
    std::array<const palpate::ContactPatch *, 8> corners;
    std::array<double, 8>                        weights;
    palpate::GridIndex                           lower;
    std::array<double, 3>                        t;
    if (!grid.locate(x, lower, t))
      return {{0, 0, 0}};
    const auto points = grid.corners(lower);
    cache.begin_patch_reads();
    for (unsigned int c = 0; c < 8; ++c)
      {
        corners[c] = cache.read_patch(points[c], cache.generation());
        if (corners[c] == nullptr)
          {
            cache.end_patch_reads();
            return {{0, 0, 0}};
          }
      }
    weights = palpate::simplex_weights(t);
    Point3 f;
    // Twenty ticks where the hand rests: the fixed-point iteration settles.
    for (unsigned int tick = 0; tick < 20; ++tick)
      contact.blend(corners, weights, x, f);
    cache.end_patch_reads();
    return f;
  }
} // namespace

int
main(int argc, char **argv)
{
  palpate::Environment env(argc, argv);

  palpate::Scene scene = shipped_scene("beam.prm");
  touch_beam_with_sphere(scene, 0.01);
  auto &p                              = scene.parameters;
  p.state_space.grid_spacing           = 0.002;
  p.state_space.extent                 = 0.006;
  p.state_space.interpolation          = "contact patch";
  p.scheduler.cloud_radius             = 0.0035;
  p.nonlinear_solver.condensed_contact = true;
  p.engine.type                        = "mpi";
  p.engine.workers                     = 2;
  const Body body(scene);
  if (palpate::mpi_rank() > 0)
    return palpate::run_solver_server(scene, body.mesh, body.nodes);

  initlog();
  const palpate::StateGrid grid(p.state_space.grid_spacing,
                                p.state_space.extent);
  const std::size_t        budget = 256 << 20;

  palpate::StateCache   threads_cache(grid, budget);
  palpate::HipChannel   threads_hip;
  palpate::ThreadEngine threads(
    body.mesh, body.nodes, p, grid, threads_cache, threads_hip);
  deallog << "threads: idle at every stop: "
          << (rest_until_idle(threads, threads_hip, grid, threads_cache, path) ?
                "yes" :
                "NO")
          << std::endl;

  palpate::StateCache mpi_cache(grid, budget);
  palpate::HipChannel mpi_hip;
  {
    palpate::MpiEngine mpi(p, grid, mpi_cache, mpi_hip);
    deallog << "mpi: idle at every stop: "
            << (rest_until_idle(mpi, mpi_hip, grid, mpi_cache, path) ? "yes" :
                                                                       "NO")
            << std::endl;

    unsigned int both = 0, with_patch = 0, same_nodes = 0, touching = 0;
    double       force = 0, position = 0, compliance = 0;
    threads_cache.begin_patch_reads();
    mpi_cache.begin_patch_reads();
    for (unsigned int q = 0; q < grid.size(); ++q)
      {
        if (threads_cache.status(q) != palpate::PointStatus::available ||
            mpi_cache.status(q) != palpate::PointStatus::available)
          continue;
        ++both;
        const auto *a = threads_cache.read_patch(q, threads_cache.generation());
        const auto *b = mpi_cache.read_patch(q, mpi_cache.generation());
        if (!a || !b)
          continue;
        ++with_patch;
        same_nodes += a->nodes == b->nodes;
        touching += palpate::Utilities::norm(a->force) > 0;
        force      = std::max(force,
                         palpate::Utilities::distance(a->force, b->force) /
                           std::max(palpate::Utilities::norm(a->force), 1e-3));
        position   = std::max(position, relative(b->position, a->position));
        compliance = std::max(compliance, relative(b->W, a->W));
      }
    mpi_cache.end_patch_reads();
    threads_cache.end_patch_reads();
    deallog << "points computed by both: " << both
            << ", with a patch on the client: " << with_patch
            << " (all: " << (with_patch == both ? "yes" : "NO")
            << "), the same nodes: " << (same_nodes == both ? "yes" : "NO")
            << ", touching: " << (touching > 0 ? "some" : "none") << std::endl;
    deallog << "forces and positions as the threaded engine's (1e-6): "
            << (force < 1e-6 && position < 1e-6 ? "yes" : "NO")
            << ", compliance (1e-3): " << (compliance < 1e-3 ? "yes" : "NO")
            << std::endl;

    palpate::PatchContact from_threads(1000, 200), from_mpi(1000, 200);
    double                rendered_difference = 0, largest = 0;
    for (const Point3 &x : {Point3{{0.001, 0.0005, -0.002}},
                            Point3{{0.0015, 0.001, -0.0025}},
                            Point3{{0.0005, 0.0015, -0.001}}})
      {
        const Point3 fa = rendered(threads_cache, grid, from_threads, x);
        const Point3 fb = rendered(mpi_cache, grid, from_mpi, x);
        largest         = std::max(largest, palpate::Utilities::norm(fa));
        rendered_difference =
          std::max(rendered_difference, palpate::Utilities::distance(fa, fb));
      }
    deallog << "rendered between the states: largest "
            << palpate::Utilities::to_string(largest, 2)
            << " N, the same from either cache (1e-5): "
            << (rendered_difference < 1e-5 * std::max(largest, 1e-3) ? "yes" :
                                                                       "NO")
            << std::endl;
  }
  deallog << "servers shut down" << std::endl;
}
