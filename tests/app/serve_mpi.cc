// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

// palpate serve with the MPI engine (issue 16: "any engine, MPI included"),
// rank 0 serving and ranks 1-2 solver servers, on the small beam:
// - a target sent over HTTP is reached, and the force /frame shows is the
//   state's force at that grid point (1e-9), the state coming from a server
//   (lazy transfer);
// - the shape is shown: the cell's 8 whole states are fetched from the
//   servers in one round;
// - the load names 2 workers (the servers);
// - a material change is refused with the reason (the MPI engine cannot
//   change parameters during an interaction), the servers keep serving;
// - stopping releases the servers (the run ends).

#include <palpate/app/serve.h>
#include <palpate/engine/mpi_engine.h>
#include <palpate/haptics/interaction.h>
#include <palpate/state_space/state_cache.h>
#include <palpate/state_space/state_grid.h>

#include <httplib.h>

#include <chrono>
#include <thread>

#include "../tests.h"

int
main(int argc, char **argv)
{
  palpate::Environment env(argc, argv);
  palpate::Scene       scene   = small_beam_scene();
  scene.parameters.engine.type = "mpi";
  if (palpate::mpi_rank() > 0)
    {
      const Body body(scene);
      return palpate::run_solver_server(scene, body.mesh, body.nodes);
    }
  initlog();

  palpate::LiveServer server(scene, "127.0.0.1", 0, 0.05);
  httplib::Client     client("127.0.0.1", server.port());
  client.set_default_headers(
    {{palpate::LiveServer::token_header, server.token()}});
  client.set_read_timeout(10, 0);
  wait_until([&] { return server.interaction().initial_cloud_complete(); },
             120,
             "the initial cloud",
             std::chrono::milliseconds(20));

  const auto &grid   = server.interaction().grid();
  const auto  point  = grid.linear({{0, -1, 0}});
  const auto  target = grid.position(point);
  client.Post("/hip",
              palpate::Utilities::to_string(target, 17),
              palpate::LiveServer::command_type);
  // Until the probe is at the target, rendering the state's force there,
  // with the shape shown: the state (fetched from its server if the client
  // does not hold it yet) and the shape's states can come after the probe.
  palpate::Utilities::Point3            hip, force;
  std::string                           frame;
  std::shared_ptr<const palpate::State> state;
  const auto                            renders_state = [&] {
    return state && palpate::Utilities::distance(force, state->force) <
                      1e-9 * palpate::Utilities::norm(state->force);
  };
  wait_until(
    [&] {
      server.last(hip, force);
      const auto f = client.Get("/frame");
      frame        = f ? f->body : "";
      state        = server.interaction().cache().state(point);
      return palpate::Utilities::distance(hip, target) < 1e-12 &&
             frame.find("\"shape\":true") != std::string::npos &&
             renders_state();
    },
    generous_deadline,
    "the probe at the target, rendering the state's force, shape shown",
    std::chrono::milliseconds(20));
  deallog << "target reached: "
          << ok(palpate::Utilities::distance(hip, target) < 1e-12)
          << ", the force rendered is the state's (1e-9): "
          << ok(renders_state()) << ", shape shown: "
          << ok(frame.find("\"shape\":true") != std::string::npos)
          << ", load of 2 workers: "
          << ok(frame.find("\"load\":{\"workers\":2,") != std::string::npos)
          << std::endl;

  const auto refused = client.Post("/material",
                                   "Young's modulus=2e5",
                                   palpate::LiveServer::command_type);
  const auto after   = client.Get("/frame");
  deallog << "a material change refused with the reason: "
          << ok(refused && refused->status == 400 &&
                refused->body.find("Engine / Type = mpi") != std::string::npos)
          << ", still serving: " << ok(after && after->status == 200)
          << std::endl;
  server.stop();
  deallog << "stopped" << std::endl;
}
