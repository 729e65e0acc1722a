// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

// The state store with the MPI engine (mpirun -np 3: a client, 2 solver
// servers), on the small beam. The whole states live on the servers; the
// client's store asks for them and they are sent lazily. An interaction that
// computes its initial cloud and detaches must store every state and failure
// point it finished, including those that were still on a server when it
// detached (the store used to miss the last ones: they were asked for, and
// arrived after the last append). The file then holds as many intact
// records.

#include <palpate/engine/mpi_engine.h>
#include <palpate/haptics/interaction.h>
#include <palpate/state_space/state_cache.h>
#include <palpate/state_space/state_store.h>

#include <chrono>
#include <filesystem>
#include <thread>

#include "../tests.h"

int
main(int argc, char **argv)
{
  palpate::Environment env(argc, argv);
  palpate::Scene       scene         = small_beam_scene();
  scene.parameters.engine.type       = "mpi";
  scene.parameters.state_space.store = "state_store_mpi.h5";
  std::filesystem::remove("state_store_mpi.h5");
  if (palpate::mpi_rank() > 0)
    {
      const Body body(scene);
      return palpate::run_solver_server(scene, body.mesh, body.nodes);
    }
  initlog();

  std::pair<unsigned int, unsigned int> finished;
  unsigned int                          stored = 0;
  {
    palpate::Interaction interaction(scene);
    interaction.attach();
    const auto start = std::chrono::steady_clock::now();
    while (!interaction.initial_cloud_complete() &&
           std::chrono::steady_clock::now() - start < std::chrono::seconds(120))
      std::this_thread::sleep_for(std::chrono::milliseconds(10));
    interaction.detach();
    finished = interaction.cache().counts();
    stored   = interaction.stored_points();
  }
  deallog << "states and failure points finished: " << ok(finished.first > 20)
          << ", every one stored: "
          << ok(stored == finished.first + finished.second) << std::endl;

  // The file: as many intact records, none damaged.
  const Body                body(scene);
  const palpate::StateStore store(scene.parameters.state_space.store,
                                  palpate::StoreFingerprint::of(scene,
                                                                body.mesh,
                                                                body.nodes));
  unsigned int              damaged = 0;
  const auto                records = store.read_all(damaged);
  unsigned int              states = 0, failures = 0;
  for (const auto &record : records)
    (record.second.converged ? states : failures) += 1;
  deallog << "the file holds them all: "
          << ok(states == finished.first && failures == finished.second &&
                damaged == 0)
          << std::endl;
}
