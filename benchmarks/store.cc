// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

// benchmarks/run store [--quick|--smoke]
//
// The HDF5 state store (issue 15) on the StVK liver scene (2 solver
// threads), for liver501 and liver2k:
// - time to the first force (the initial cloud complete) from nothing,
//   computing the cloud, and from a full store, loading it;
// - write rate: the cloud's states appended to a new store (each record
//   flushed, as palpate writes them), states/s;
// - read rate: every record read back and checked, states/s;
// - bytes per state in the file;
// - the haptic loop while the store is appended to: the scene's stroke run
//   on the full store (its new states appended by the writer thread), its
//   deadline misses and missing-data events, against the same run without
//   a store (liver501).
//
// --quick: liver501 only.
// --smoke (the test suite's): liver501, a cloud of radius 9 mm (the least
// that holds a cell) and a stroke of 0.1 s: every step above in a few
// seconds.

#include <palpate/app/interaction_run.h>
#include <palpate/base/environment.h>
#include <palpate/haptics/interaction.h>
#include <palpate/haptics/run_summary.h>
#include <palpate/mesh/mesh.h>
#include <palpate/mesh/node_selection.h>
#include <palpate/scene/scene.h>
#include <palpate/state_space/state_store.h>

#include <chrono>
#include <filesystem>
#include <iomanip>
#include <iostream>
#include <sstream>
#include <thread>

#include "machine.h"
#include "report_errors.h"

using namespace palpate;

namespace
{
  using Clock = std::chrono::steady_clock;

  using palpate::Utilities::seconds_since;

  /** Seconds from constructing an interaction to its initial cloud. */
  double
  first_force(const Scene &scene, std::string &report)
  {
    const auto  start = Clock::now();
    Interaction interaction(scene);
    interaction.attach();
    while (!interaction.initial_cloud_complete())
      std::this_thread::sleep_for(std::chrono::microseconds(200));
    const double t = seconds_since(start);
    interaction.detach();
    report = interaction.store_report();
    return t;
  }
} // namespace

static int
run_benchmark(int argc, char **argv)
{
  Environment env(argc, argv);
  bool        quick = false, smoke = false;
  for (int i = 1; i < argc; ++i)
    if (std::string(argv[i]) == "--quick")
      quick = true;
    else if (std::string(argv[i]) == "--smoke")
      smoke = quick = true;
    else
      {
        std::cerr << "usage: benchmarks/run store [--quick|--smoke]\n";
        return 2;
      }
  std::cout << "The HDF5 state store: paper-stvk, " << machine()
            << (smoke ? " [--smoke]" :
                quick ? " [--quick]" :
                        "")
            << "\n\n"
            << "| mesh | cloud states | first force from nothing (s) | from "
               "the store (s) | write (states/s) | read (states/s) | bytes "
               "per state |\n|---|---|---|---|---|---|---|\n";
  std::ostringstream results;
  for (const std::string &mesh :
       quick ? std::vector<std::string>{"liver501"} :
               std::vector<std::string>{"liver501", "liver2k"})
    {
      Scene scene = Scene::read(std::string(PALPATE_SOURCE_DIR) +
                                "/parameters/paper-stvk.prm");
      auto &p     = scene.parameters;
      if (mesh == "liver2k")
        p.mesh.file_name =
          std::string(PALPATE_SOURCE_DIR) + "/meshes/liver-tetgen/liver2k.msh";
      p.state_space.store = "bench-" + mesh + ".h5";
      if (smoke)
        {
          p.scheduler.cloud_radius      = 0.009;
          p.haptics.trajectory.duration = 0.1;
        }
      std::filesystem::remove(p.state_space.store);

      std::string  report;
      const double from_nothing = first_force(scene, report);
      const double from_store   = first_force(scene, report);

      // Write and read rates, on the states the store now holds.
      const Mesh             m       = Mesh::create(scene);
      const NodeSelection    nodes   = NodeSelection::create(scene, m);
      const StoreFingerprint fp      = StoreFingerprint::of(scene, m, nodes);
      unsigned int           damaged = 0;
      std::vector<std::pair<unsigned int, State>> states;
      {
        const StateStore full(p.state_space.store, fp);
        const auto       start = Clock::now();
        states                 = full.read_all(damaged);
        const double read_s    = seconds_since(start);
        const double bytes =
          std::filesystem::file_size(p.state_space.store) / double(full.size());
        const std::string copy = "bench-copy.h5";
        std::filesystem::remove(copy);
        double write_s = 0;
        {
          StateStore out(copy, fp);
          const auto w = Clock::now();
          for (const auto &[point, state] : states)
            out.append(point, state);
          write_s = seconds_since(w);
        }
        std::filesystem::remove(copy);
        const double write_rate = states.size() / write_s;
        const double read_rate  = states.size() / read_s;
        std::cout << "| " << mesh << " (" << m.n_vertices() << " nodes) | "
                  << states.size() << " | " << std::fixed
                  << std::setprecision(2) << from_nothing << " | "
                  << std::setprecision(3) << from_store << " | "
                  << std::setprecision(0) << write_rate << " | " << read_rate
                  << " | " << bytes << " |\n"
                  << std::defaultfloat;
        results << "RESULT store mesh=" << mesh << " nodes=" << m.n_vertices()
                << " states=" << states.size()
                << " write_states_s=" << write_rate
                << " read_states_s=" << read_rate
                << " bytes_per_state=" << bytes
                << " first_force_ms=" << 1000 * from_store
                << " first_force_from_nothing_ms=" << 1000 * from_nothing
                << " damaged=" << damaged << "\n";
      }
      if (mesh == "liver501")
        {
          // The stroke with the store (loading before, appending during)
          // and without, for the haptic loop's timing.
          std::ostringstream quiet;
          Scene              plain = scene;
          plain.parameters.state_space.store.clear();
          plain.parameters.output.summary_formats.clear();
          scene.parameters.output.summary_formats.clear();
          plain.parameters.output.directory =
            scene.parameters.output.directory = "bench-output";
          const RunSummary with               = run_interaction(quiet, scene);
          const RunSummary without            = run_interaction(quiet, plain);
          std::filesystem::remove_all("bench-output");
          std::cout << "\nThe stroke on liver501: with the store (loaded, "
                       "appended while the loop runs) "
                    << with.deadline_misses << " deadline misses, "
                    << with.missing_events
                    << " missing-data events, motion after "
                    << 1000 * with.motion_start << " ms; without a store "
                    << without.deadline_misses << " deadline misses, "
                    << without.missing_events
                    << " missing-data events, motion after "
                    << 1000 * without.motion_start << " ms\n";
          results
            << "RESULT store mesh=liver501 stroke=yes store_deadline_misses="
            << with.deadline_misses
            << " plain_deadline_misses=" << without.deadline_misses
            << " store_missing_events=" << with.missing_events
            << " store_motion_start_ms=" << 1000 * with.motion_start
            << " plain_motion_start_ms=" << 1000 * without.motion_start << "\n";
        }
      std::filesystem::remove(p.state_space.store);
    }
  std::cout << "\n" << results.str();
  return 0;
}



int
main(int argc, char **argv)
{
  return report_errors("store", run_benchmark, argc, argv);
}
