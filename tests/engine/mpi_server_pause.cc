// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

// A solver server freezes mid-run and comes back (rank 2 stops its own
// process with SIGSTOP on its second task, as a machine that froze would;
// issue 26). The client declares it lost after Engine / Server timeout (1 s
// here), plans its work again and finishes the cloud with the survivor, as
// for a dead server. What this test adds: the server that comes back must
// end too. The test resumes it (SIGCONT from rank 0) once the client has
// declared it lost, however long that took; it finds the shutdown the
// client sent it then and exits, and so mpirun returns; before, it waited
// for a client that no longer talked to it and mpirun never returned (the
// test then hits the harness's time limit).

#include <palpate/engine/hip_channel.h>
#include <palpate/engine/mpi_engine.h>
#include <palpate/haptics/force_interpolation.h>
#include <palpate/state_space/state_cache.h>
#include <palpate/state_space/state_grid.h>

#include <mpi.h>
#include <signal.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <thread>
#include <vector>

#include "../tests.h"

int
main(int argc, char **argv)
{
  using palpate::Utilities::Point3;
  using Clock = std::chrono::steady_clock;
  palpate::Environment env(argc, argv);

  palpate::Scene scene    = small_beam_scene();
  auto          &p        = scene.parameters;
  p.engine.type           = "mpi";
  p.engine.server_timeout = 1;
  p.material_model.set("St.Venant-Kirchhoff", "Young's modulus", 1e6);
  const Body body(scene);
  // Rank 0 resumes the frozen server: it needs its process id (every rank
  // runs on this machine).
  int pid = getpid(), ranks = 0;
  MPI_Comm_size(MPI_COMM_WORLD, &ranks);
  std::vector<int> pids(ranks);
  MPI_Gather(&pid, 1, MPI_INT, pids.data(), 1, MPI_INT, 0, MPI_COMM_WORLD);
  if (palpate::mpi_rank() > 0)
    {
      palpate::ServerFaults faults;
      if (palpate::mpi_rank() == 2)
        faults.pause_after_tasks = 2; // until rank 0 resumes it
      return palpate::run_solver_server(scene, body.mesh, body.nodes, faults);
    }

  initlog();
  const palpate::StateGrid grid(p.state_space.grid_spacing,
                                p.state_space.extent);
  palpate::StateCache      cache(grid, 64 << 20);
  palpate::HipChannel      hip;
  const Point3             x{{0.001, -0.0005, -0.0015}};
  hip.write(x, {{0, 0, 0}});
  {
    palpate::MpiEngine engine(p, grid, cache, hip);
    engine.start();
    const auto start    = Clock::now();
    bool       finished = false, resumed = false;
    while (Clock::now() - start < std::chrono::minutes(3))
      {
        // Server 2 comes back once it is lost, while the survivor works.
        if (!resumed && !engine.statistics().lost_servers.empty())
          resumed = kill(pids[2], SIGCONT) == 0;
        if (engine.idle())
          {
            finished = true;
            break;
          }
        std::this_thread::sleep_for(std::chrono::milliseconds(1));
      }
    // Never declared lost (the output says so): resumed all the same, so
    // that it can end and mpirun return.
    if (!resumed)
      kill(pids[2], SIGCONT);
    engine.stop();
    const auto stats = engine.statistics();
    deallog << "engine idle (cloud done) within 3 minutes: "
            << (finished ? "yes" : "NO") << std::endl;
    deallog << "servers lost: " << stats.lost_servers.size() << std::endl;
    for (const auto &why : stats.lost_servers)
      deallog << "  names server 2: "
              << (why.find("solver server 2 lost") == 0 ? "yes" : "NO")
              << std::endl;
    unsigned int in_cloud = 0, available = 0;
    for (unsigned int q = 0; q < grid.size(); ++q)
      if (palpate::Utilities::distance(grid.position(q), x) <=
          p.scheduler.cloud_radius)
        {
          ++in_cloud;
          available += cache.status(q) == palpate::PointStatus::available;
        }
    deallog << "cloud points available: " << available << " of " << in_cloud
            << std::endl;
  }
  deallog << "client finished" << std::endl;
}
