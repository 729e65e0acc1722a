// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

// Every solver server dies (ranks 1 and 2 kill themselves with SIGKILL on
// their first task; mpirun --enable-recovery keeps the client alive).
// Issue 26: with a 0.1 s Task timeout both servers were lost during the
// initial cloud and the motion started anyway, on a cloud nobody computed
// any more. The engine must say so: lost_every_worker() is false while a
// server is left and true once the last is lost (the interaction then ends
// through its normal path, exit status 5), and the client still finishes
// cleanly.

#include <palpate/engine/hip_channel.h>
#include <palpate/engine/mpi_engine.h>
#include <palpate/state_space/state_cache.h>
#include <palpate/state_space/state_grid.h>

#include <chrono>
#include <thread>

#include "../tests.h"

int
main(int argc, char **argv)
{
  using Clock = std::chrono::steady_clock;
  palpate::Environment env(argc, argv);

  palpate::Scene scene       = shipped_scene("beam.prm");
  auto          &p           = scene.parameters;
  p.state_space.grid_spacing = 0.002;
  p.state_space.extent       = 0.006;
  p.scheduler.cloud_radius   = 0.0045;
  p.engine.type              = "mpi";
  p.engine.server_timeout    = 1;
  p.material_model.set("St.Venant-Kirchhoff", "Young's modulus", 1e6);
  const Body body(scene);
  if (palpate::mpi_rank() > 0)
    {
      palpate::ServerFaults faults;
      faults.die_after_tasks = 1;
      return palpate::run_solver_server(scene, body.mesh, body.nodes, faults);
    }

  initlog();
  const palpate::StateGrid grid(p.state_space.grid_spacing,
                                p.state_space.extent);
  palpate::StateCache      cache(grid, 64 << 20);
  palpate::HipChannel      hip;
  hip.write({{0.001, -0.0005, -0.0015}}, {{0, 0, 0}});
  {
    palpate::MpiEngine engine(p, grid, cache, hip);
    deallog << "before the start, every worker lost: "
            << (engine.lost_every_worker() ? "YES" : "no") << std::endl;
    engine.start();
    // Both die on their first task and are declared lost after the 1 s
    // Server timeout; wait at most a minute.
    bool         early = false; // said while one server was still there
    const auto   start = Clock::now();
    unsigned int lost  = 0;
    while (Clock::now() - start < std::chrono::minutes(1))
      {
        const bool all = engine.lost_every_worker();
        lost           = engine.statistics().lost_servers.size();
        if (all && lost < 2)
          early = true;
        if (all)
          break;
        std::this_thread::sleep_for(std::chrono::milliseconds(5));
      }
    deallog << "every worker lost within a minute: "
            << (engine.lost_every_worker() ? "yes" : "NO")
            << "; servers lost then: " << lost
            << "; said while one was left: " << (early ? "YES" : "no")
            << std::endl;
    engine.stop();
  }
  deallog << "client finished" << std::endl;
}
