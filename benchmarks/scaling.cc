// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

// benchmarks/run scaling [--quick|--smoke] [--repeat N] [--reuse yes|no]
//
// How the engine's throughput (states per second) grows with a second
// solver: 1 and 2 solver threads (Engine / Type = threads) against 1 and 2
// MPI solver servers (Engine / Type = mpi, plus the client rank, all on
// this 2-core machine), on the same work: the initial cloud of
// parameters/paper-stvk.prm (liver501, St.Venant-Kirchhoff, h = 5 mm)
// around the rest position, radius 25 mm (15 mm with --quick). Each run is
// a whole interaction as `palpate scene.prm` runs it, in a fresh process;
// throughput = states finished (converged or failure points) in the
// initial cloud / the time from attach until the cloud was complete.
// The median of --repeat runs (3; 1 with --quick) is reported.
// --smoke (the test suite's): one run each with a cloud of radius 9 mm
// (the least that holds a cell), the same four engines and child
// processes in a few seconds.
// --reuse overrides the scene's Nonlinear solver / Reuse factorization
// (paper-stvk.prm: false, measured best for it), to compare.
//
// Why: MUMPS keeps global state, so solver threads take turns behind one
// mutex; processes do not share it. Target (issue 8): MPI
// throughput_ratio >= 1.8.

#include <palpate/app/interaction_run.h>
#include <palpate/base/environment.h>
#include <palpate/engine/mpi_engine.h>
#include <palpate/haptics/run_summary.h>
#include <palpate/mesh/mesh.h>
#include <palpate/mesh/node_selection.h>
#include <palpate/scene/scene.h>

#include <algorithm>
#include <iomanip>
#include <iostream>
#include <sstream>
#include <thread>
#include <vector>

#include "mpi_child.h"
#include "report_errors.h"

using namespace palpate;

namespace
{
  /** The scene of one configuration. */
  Scene
  scene_for(const std::string &engine,
            const unsigned int workers,
            const double       radius,
            const std::string &reuse)
  {
    Scene scene                = Scene::read(std::string(PALPATE_SOURCE_DIR) +
                              "/parameters/paper-stvk.prm");
    auto &p                    = scene.parameters;
    p.engine.type              = engine;
    p.engine.workers           = workers;
    p.scheduler.cloud_radius   = radius;
    p.haptics.trajectory.type  = "straight line";
    p.haptics.trajectory.start = "after initial cloud";
    // The motion only ends the run once the cloud is measured: short, but
    // 0.2 mm, over the 0.1 mm a trajectory must move (Scene::validate()).
    p.haptics.trajectory.speed    = 0.004;
    p.haptics.trajectory.duration = 0.05;
    p.effects.shape_output        = false;
    p.effects.force_log           = false;
    p.output.summary_formats      = {};
    if (reuse != "scene")
      p.nonlinear_solver.set_reuse(reuse == "yes");
    scene.validate();
    return scene;
  }

  /** One run (in a child process, under mpirun for the MPI engine). */
  int
  child(const std::string &engine,
        const unsigned int workers,
        const double       radius,
        const std::string &reuse)
  {
    const Scene scene = scene_for(engine, workers, radius, reuse);
    if (engine == "mpi" && mpi_rank() > 0)
      {
        const Mesh          mesh  = Mesh::create(scene);
        const NodeSelection nodes = NodeSelection::create(scene, mesh);
        return run_solver_server(scene, mesh, nodes);
      }
    std::ostringstream quiet;
    const RunSummary   s = run_interaction(quiet, scene);
    std::cout << "CHILD states=" << s.initial_cloud_states - 1 + s.states_failed
              << " seconds=" << s.motion_start
              << " state_ms=" << s.median_state_ms
              << " complete=" << s.initial_cloud_complete
              << " messages=" << s.messages << " bytes=" << s.bytes
              << " fetched=" << s.fetched_sources
              << " local=" << s.local_sources << std::endl;
    return 0;
  }

  struct Row
  {
    std::string  engine;
    unsigned int workers;
    double       states = 0, seconds = 0, state_ms = 0, per_second = 0;
    double       fetched = 0, local = 0, bytes_per_state = 0;
  };
} // namespace

static int
run_benchmark(int argc, char **argv)
{
  std::vector<std::string> args(argv + 1, argv + argc);
  if (args.size() == 5 && args[0] == "--child")
    {
      Environment env(argc, argv);
      return child(args[1], std::stoul(args[2]), std::stod(args[3]), args[4]);
    }

  bool         quick  = false;
  bool         smoke  = false;
  std::string  reuse  = "scene";
  unsigned int repeat = 3;
  for (unsigned int i = 0; i < args.size(); ++i)
    if (args[i] == "--quick")
      quick = true;
    else if (args[i] == "--smoke")
      smoke = true;
    else if (args[i] == "--reuse" && i + 1 < args.size() &&
             (args[i + 1] == "yes" || args[i + 1] == "no"))
      reuse = args[++i];
    else if (args[i] == "--repeat" && i + 1 < args.size())
      repeat = whole_number("--repeat", args[++i], 1);
    else
      {
        std::cerr << "usage: benchmarks/run scaling [--quick|--smoke] "
                     "[--repeat N] [--reuse yes|no]\n";
        return 2;
      }
  if (quick || smoke)
    repeat = 1;
  const double radius     = smoke ? 0.009 : quick ? 0.015 : 0.025;
  const bool   reuse_used = scene_for("threads", 1, radius, reuse)
                            .parameters.nonlinear_solver.reuse_factorization;

  std::cout << "Engine throughput with one and two solvers\n"
            << "  machine: " << std::thread::hardware_concurrency()
            << " cores; liver501 StVK, h = 5 mm, initial cloud of radius "
            << 1000 * radius << " mm around rest; median of " << repeat
            << " run" << (repeat > 1 ? "s" : "")
            << (smoke ? " [--smoke]" :
                quick ? " [--quick]" :
                        "")
            << (reuse == "scene" ? std::string() : " [--reuse " + reuse + "]")
            << "\n\n";

  std::vector<Row> rows;
  for (const std::string engine : {"threads", "mpi"})
    for (const unsigned int n : {1u, 2u})
      {
        std::vector<Row> runs;
        for (unsigned int r = 0; r < repeat; ++r)
          {
            std::ostringstream a;
            a << "--child " << engine << " " << n << " " << radius << " "
              << reuse;
            const auto v = mpi_child::run(
              mpi_child::command(engine == "mpi" ? n + 1 : 0, a.str()));
            Row row;
            row.engine     = engine;
            row.workers    = n;
            row.states     = std::stod(v.at("states"));
            row.seconds    = std::stod(v.at("seconds"));
            row.state_ms   = std::stod(v.at("state_ms"));
            row.per_second = row.states / row.seconds;
            row.fetched    = std::stod(v.at("fetched"));
            row.local      = std::stod(v.at("local"));
            row.bytes_per_state =
              std::stod(v.at("bytes")) / std::max(1.0, row.states);
            runs.push_back(row);
            std::cout << "  " << engine << ", " << n << " solver"
                      << (n > 1 ? "s" : "") << ": " << row.states
                      << " states in " << std::setprecision(3) << row.seconds
                      << " s, " << row.per_second << " states/s, median "
                      << row.state_ms << " ms per state" << std::endl;
          }
        std::sort(runs.begin(), runs.end(), [](const Row &a, const Row &b) {
          return a.per_second < b.per_second;
        });
        rows.push_back(runs[runs.size() / 2]);
      }

  const auto rate = [&](const std::string &e, const unsigned int n) {
    for (const auto &r : rows)
      if (r.engine == e && r.workers == n)
        return r.per_second;
    return 0.0;
  };
  std::cout << "\n  engine   solvers  states/s  state (ms)  ratio to 1   "
               "sources fetched / local  bytes/state\n";
  for (const auto &r : rows)
    std::cout << "  " << std::left << std::setw(9) << r.engine << std::right
              << std::setw(7) << r.workers << std::fixed << std::setw(10)
              << std::setprecision(1) << r.per_second << std::setw(12)
              << r.state_ms << std::setw(12) << std::setprecision(2)
              << r.per_second / rate(r.engine, 1) << std::setw(17)
              << std::setprecision(0) << r.fetched << " / " << std::left
              << std::setw(8) << r.local << std::right << std::setw(10)
              << r.bytes_per_state << "\n";
  std::cout << "\n  target: mpi ratio >= 1.8 with 2 servers\n\n";
  for (const std::string engine : {"mpi", "threads"})
    std::cout << "RESULT scaling engine=" << engine << " servers=2"
              << " throughput_ratio=" << std::setprecision(2)
              << rate(engine, 2) / rate(engine, 1)
              << " states_per_s_1=" << std::setprecision(1) << rate(engine, 1)
              << " states_per_s_2=" << rate(engine, 2)
              << " radius_mm=" << std::setprecision(0) << 1000 * radius
              << " reuse=" << (reuse_used ? "yes" : "no") << "\n";
  return 0;
}



int
main(int argc, char **argv)
{
  return report_errors("scaling", run_benchmark, argc, argv);
}
