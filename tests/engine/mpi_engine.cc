// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

// The MPI engine (1 client + 2 solver servers) against the threaded engine
// (2 solver threads) on the same fixed trajectory of the HIP on the beam
// scene (2 mm grid, 4.5 mm cloud): the HIP rests at three positions in
// turn and each engine computes until it is idle there.
// - Both compute the same grid points, and the same force at each (to
//   1e-6 relative: the Newton tolerance is 1e-8, and the two engines may
//   reach a point from different neighbours).
// - Lazy state transfer: no whole state reaches the client until its cache
//   is asked for one (as the shape output does); then exactly that one is
//   sent, and its displacement field equals the threaded engine's.
// - Some tasks start from a state that another server computed (the
//   transfer is counted), and nothing is lost.

#include <palpate/engine/hip_channel.h>
#include <palpate/engine/mpi_engine.h>
#include <palpate/engine/thread_engine.h>
#include <palpate/hyperelastic/state.h>
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

  const std::vector<Point3> path = {{{0, 0, 0}},
                                    {{0.003, 0, -0.002}},
                                    {{0.003, -0.003, -0.002}}};

} // namespace

int
main(int argc, char **argv)
{
  palpate::Environment env(argc, argv);

  palpate::Scene scene       = shipped_scene("beam.prm");
  auto          &p           = scene.parameters;
  p.state_space.grid_spacing = 0.002;
  p.state_space.extent       = 0.006;
  p.scheduler.cloud_radius   = 0.0045;
  p.engine.type              = "mpi";
  p.engine.workers           = 2;
  p.material_model.set("St.Venant-Kirchhoff", "Young's modulus", 1e6);
  const Body body(scene);
  if (palpate::mpi_rank() > 0)
    return palpate::run_solver_server(scene, body.mesh, body.nodes);

  initlog();
  const palpate::StateGrid grid(p.state_space.grid_spacing,
                                p.state_space.extent);
  const std::size_t        budget = 64 << 20;

  palpate::StateCache   threads_cache(grid, budget);
  palpate::HipChannel   threads_hip;
  palpate::ThreadEngine threads(
    body.mesh, body.nodes, p, grid, threads_cache, threads_hip);
  deallog << "threads: " << threads.n_workers() << " solver threads, idle at "
          << "every stop: "
          << (rest_until_idle(threads, threads_hip, grid, threads_cache, path) ?
                "yes" :
                "NO")
          << std::endl;

  palpate::StateCache mpi_cache(grid, budget);
  palpate::HipChannel mpi_hip;
  {
    palpate::MpiEngine mpi(p, grid, mpi_cache, mpi_hip);
    deallog << "mpi: " << mpi.n_workers() << " solver servers, idle at every "
            << "stop: "
            << (rest_until_idle(mpi, mpi_hip, grid, mpi_cache, path) ? "yes" :
                                                                       "NO")
            << std::endl;

    // The same points, the same forces.
    unsigned int both = 0, only_one = 0;
    double       largest = 0;
    for (unsigned int q = 0; q < grid.size(); ++q)
      {
        const bool a =
                     threads_cache.status(q) == palpate::PointStatus::available,
                   b = mpi_cache.status(q) == palpate::PointStatus::available;
        if (a != b)
          ++only_one;
        if (!a || !b)
          continue;
        ++both;
        Point3 fa, fb;
        threads_cache.read_force(q, threads_cache.generation(), fa);
        mpi_cache.read_force(q, mpi_cache.generation(), fb);
        const double scale = std::max(palpate::Utilities::norm(fa), 1e-3);
        largest =
          std::max(largest, palpate::Utilities::distance(fa, fb) / scale);
      }
    deallog << "points computed by both engines: " << both
            << ", by only one: " << only_one
            << "; forces agree to 1e-6: " << (largest < 1e-6 ? "yes" : "NO")
            << std::endl;

    // Lazy transfer: results carried forces only.
    auto stats = mpi.statistics();
    deallog << "whole states on the client: " << mpi_cache.memory().first
            << ", states sent to it: " << stats.states_to_client << std::endl;

    // The shape output asks for one: it arrives, and only it.
    const unsigned int wanted    = grid.linear({{2, -1, -1}});
    const bool         first_ask = mpi_cache.state(wanted) != nullptr;
    std::shared_ptr<const palpate::State> state;
    wait_until([&] { return (state = mpi_cache.state(wanted)) != nullptr; },
               generous_deadline,
               "the state asked for to arrive");
    stats = mpi.statistics();
    deallog << "asked for point " << wanted << ": held at first ask "
            << first_ask << ", arrived " << (state != nullptr)
            << ", states sent to the client now " << stats.states_to_client
            << std::endl;
    if (state)
      {
        const auto reference = threads_cache.state(wanted);
        double     diff = 0, size = 0;
        for (unsigned int i = 0; i < state->solution.size(); ++i)
          {
            diff =
              std::max(diff,
                       std::abs(state->solution[i] - reference->solution[i]));
            size = std::max(size, std::abs(reference->solution[i]));
          }
        deallog << "its displacement field equals the threaded engine's "
                << "(1e-6 relative): " << (diff < 1e-6 * size ? "yes" : "NO")
                << ", force " << palpate::Utilities::to_string(state->force, 4)
                << " N" << std::endl;
      }
    deallog << "computed " << stats.computed << ", failure points "
            << stats.failed << ", servers lost " << stats.lost_servers.size()
            << ", sources fetched from another server: "
            << (stats.fetched_sources > 0 ? "some" : "none")
            << ", messages counted: " << (stats.messages > 0 ? "yes" : "no")
            << std::endl;
  } // the servers are shut down here
  deallog << "servers shut down" << std::endl;
}
