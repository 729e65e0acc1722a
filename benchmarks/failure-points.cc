// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

// benchmarks/run failure-points [--quick|--smoke] [--targets N] [--tip R_MM]
//                                [--cutbacks N]
//
// Where does the state space have no state, and why? On the shipped liver
// (parameters/paper-stvk.prm: liver501, 25 cm, active node 95), N random
// targets (default 1000) uniform in the 10 cm ball of the paper's state
// space - pushes and pulls in all directions - are solved from rest as the
// engine stages a state: increments of at most 1 cm, Newton with line
// search. For St.Venant-Kirchhoff, neo-Hookean and Mooney-Rivlin (P1-P1,
// exactly incompressible), each with the paper's point probe and with a
// rigid tip (Active node / Tip radius, default 25 mm: liver501's surface
// nodes are about 2 cm apart, so a 5-10 mm tip holds only the active node).
//
// Every failure is classified by a slow, robust reference path to the same
// target: increments of 2 mm, up to 4 cutbacks, 16 line-search steps,
// 50 Newton iterations. If the reference converges, the failure is
// solver-caused (a bug to remove); if not, no equilibrium was found along
// the path (the material collapses: an inverted element, or Newton finds
// no equilibrium).
//
// Prints the table beside the paper's 19.7 % (StVK) and 1.4 % (MR), writes
// failure-points.csv (every target and its outcome, for
// doc/images/failure_points.py) and ends with
//   RESULT failure-points material=... probe_mm=... failure_pct=...
//          solver_failure_pct=... avg_iters=...
// Configurations run two at a time, in separate processes (MUMPS cannot
// factorise in two threads of one process).
//
// --smoke (the test suite's): St.Venant-Kirchhoff only (point and tip),
// 3 targets: the same child processes and table in seconds.

#include <palpate/base/environment.h>
#include <palpate/hyperelastic/state_solver.h>
#include <palpate/mesh/mesh.h>
#include <palpate/mesh/node_selection.h>
#include <palpate/scene/scene.h>

#include <array>
#include <chrono>
#include <cmath>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <map>
#include <random>
#include <sstream>
#include <thread>

#include "machine.h"
#include "mpi_child.h"
#include "report_errors.h"

using namespace palpate;
using Utilities::Point3;

namespace
{
  struct Configuration
  {
    std::string material; // stvk, nh, mr
    double      tip_mm;
  };

  struct Outcome
  {
    Point3       target;
    bool         converged;
    bool         solver_caused; // failed, but the reference path converged
    std::string  status;        // of the engine path, or of the reference
    unsigned int increments, iterations;
    double       seconds;
  };

  Scene
  scene_for(const Configuration &c)
  {
    Scene scene =
      Scene::read(std::string(PALPATE_SOURCE_DIR) +
                  (c.material == "mr" ? "/parameters/paper-mooney-rivlin.prm" :
                                        "/parameters/paper-stvk.prm"));
    auto &p = scene.parameters;
    if (c.material == "nh")
      p.material_model.model_name = "Neo-Hookean";
    p.boundary_conditions.active_node.tip_radius = c.tip_mm / 1000;
    p.boundary_conditions.active_node.tip =
      c.tip_mm > 0 ? "glued nodes" : "point";
    p.nonlinear_solver.set_reuse(false);
    p.nonlinear_solver.max_increment_length = 0.01;
    return scene;
  }

  /** N targets uniform in the ball of radius 10 cm (the same for every
   * configuration). */
  std::vector<Point3>
  targets(const unsigned int n)
  {
    std::mt19937                           rng(20261123);
    std::uniform_real_distribution<double> u(-1, 1);
    std::vector<Point3>                    t;
    while (t.size() < n)
      {
        const Point3 x{{u(rng), u(rng), u(rng)}};
        if (Utilities::norm(x) <= 1)
          t.push_back({{0.1 * x[0], 0.1 * x[1], 0.1 * x[2]}});
      }
    return t;
  }

  /** Run one configuration; write its outcomes to @p file. */
  void
  run(const Configuration       &c,
      const std::vector<Point3> &t,
      const std::string         &file,
      const int                  cutbacks)
  {
    Scene scene = scene_for(c);
    if (cutbacks >= 0)
      scene.parameters.nonlinear_solver.max_cutbacks = cutbacks;
    const Mesh          mesh  = Mesh::create(scene);
    const NodeSelection nodes = NodeSelection::create(scene, mesh);
    StateSolver         solver(mesh, nodes, scene.parameters);
    auto                slow                    = scene.parameters;
    slow.nonlinear_solver.max_increment_length  = 0.002;
    slow.nonlinear_solver.max_cutbacks          = 4;
    slow.nonlinear_solver.max_line_search_steps = 16;
    slow.nonlinear_solver.max_newton_iterations = 50;
    StateSolver   reference(mesh, nodes, slow);
    const State   rest = solver.rest_state();
    std::ofstream out(file);
    out << nodes.tip_vertices.size() << "\n";
    for (const Point3 &x : t)
      {
        const auto  start = std::chrono::steady_clock::now();
        const State s     = solver.solve(rest, x);
        Outcome     o{x,
                  s.converged,
                  false,
                  to_string(s.status),
                  s.increments,
                  s.newton_iterations,
                  0};
        o.seconds = std::chrono::duration<double>(
                      std::chrono::steady_clock::now() - start)
                      .count();
        if (!s.converged)
          {
            const State r   = reference.solve(reference.rest_state(), x);
            o.solver_caused = r.converged;
            if (!r.converged)
              o.status = to_string(r.status);
          }
        out << std::setprecision(17) << x[0] << " " << x[1] << " " << x[2]
            << " " << o.converged << " " << o.solver_caused << " "
            << o.increments << " " << o.iterations << " " << o.seconds << " "
            << std::quoted(o.status) << "\n";
      }
  }

  std::vector<Outcome>
  read_outcomes(const std::string &file, unsigned int &tip_nodes)
  {
    std::ifstream        in(file);
    std::vector<Outcome> o;
    in >> tip_nodes;
    Outcome x;
    while (in >> x.target[0] >> x.target[1] >> x.target[2] >> x.converged >>
           x.solver_caused >> x.increments >> x.iterations >> x.seconds >>
           std::quoted(x.status))
      o.push_back(x);
    return o;
  }
} // namespace

static int
run_benchmark(int argc, char **argv)
{
  Environment  env(argc, argv);
  bool         quick    = false;
  bool         smoke    = false;
  unsigned int n        = 1000;
  double       tip      = 25;
  int          only     = -1; // --part K: run configuration K only
  int          cutbacks = -1; // the engine path's Maximum cutbacks
  std::string  out;
  for (int i = 1; i < argc; ++i)
    {
      const std::string a = argv[i];
      if (a == "--quick")
        quick = true;
      else if (a == "--smoke")
        smoke = true;
      else if (a == "--targets" && i + 1 < argc)
        n = whole_number(a, argv[++i], 1);
      else if (a == "--tip" && i + 1 < argc)
        tip = std::stod(argv[++i]);
      else if (a == "--cutbacks" && i + 1 < argc)
        cutbacks = std::stoi(argv[++i]);
      else if (a == "--part" && i + 1 < argc)
        only = std::stoi(argv[++i]);
      else if (a == "--out" && i + 1 < argc)
        out = argv[++i];
      else
        {
          std::cerr << "usage: benchmarks/run failure-points [--quick|--smoke] "
                       "[--targets N] [--tip R_MM] [--cutbacks N]\n";
          return 2;
        }
    }
  if (quick)
    n = 25;
  if (smoke)
    n = 3;

  std::vector<Configuration> configurations = {
    {"stvk", 0}, {"stvk", tip}, {"nh", 0}, {"nh", tip}, {"mr", 0}, {"mr", tip}};
  // The first two, so that a part's number (--part K) names the same
  // configuration in the child.
  if (smoke && only < 0)
    configurations.resize(2);
  const std::vector<Point3> t = targets(n);
  if (only >= 0)
    {
      run(configurations.at(only), t, out, cutbacks);
      return 0;
    }
  std::cout << "failure-points: " << n
            << " random targets in the 10 cm ball on liver501, from rest "
               "(increments <= 1 cm, "
            << (cutbacks >= 0 ?
                  std::to_string(cutbacks) :
                  std::to_string(scene_for(configurations[0])
                                   .parameters.nonlinear_solver.max_cutbacks))
            << " cutbacks)\nmachine: " << machine() << "\n\n";

  // Two configurations at a time, each in its own process (this program
  // again, with --part K --out FILE).
  const std::string stem =
    "/tmp/palpate-failure-points-" + std::to_string(::getpid()) + "-";
  const auto t0 = std::chrono::steady_clock::now();
  mpi_child::clean_environment();
  const auto part = [&](const unsigned int k) {
    const std::string command =
      mpi_child::self() + " --part " + std::to_string(k) + " --targets " +
      std::to_string(n) + " --tip " + Utilities::to_string(tip, 6) +
      " --cutbacks " + std::to_string(cutbacks) + " --out " + stem +
      std::to_string(k) + " 2>&1";
    if (FILE *pipe = popen(command.c_str(), "r"))
      {
        std::array<char, 4096> buffer;
        while (fread(buffer.data(), 1, buffer.size(), pipe) > 0)
          ;
        pclose(pipe);
      }
  };
  for (unsigned int k = 0; k < configurations.size(); k += 2)
    {
      std::thread second(part, k + 1);
      part(k);
      second.join();
    }

  const char *paper[] = {"19.7 %", "", "", "", "1.4 %", ""};
  std::cout << "| material | probe | tip nodes | failure points | of which "
               "solver-caused | no equilibrium found (reference status) | "
               "paper | iterations per increment | ms per target |\n"
            << "|---|---|---|---|---|---|---|---|---|\n";
  std::ofstream      csv("failure-points.csv");
  std::ostringstream results;
  csv << "material,probe_mm,x,y,z,outcome\n";
  for (unsigned int k = 0; k < configurations.size(); ++k)
    {
      const auto  &c         = configurations[k];
      unsigned int tip_nodes = 0;
      const auto   o = read_outcomes(stem + std::to_string(k), tip_nodes);
      std::remove((stem + std::to_string(k)).c_str());
      if (o.size() != t.size())
        {
          std::cerr << "failure-points: configuration " << c.material << " "
                    << c.tip_mm << " mm did not finish\n";
          return 1;
        }
      unsigned int failed = 0, solver = 0, increments = 0, iterations = 0;
      double       seconds = 0;
      std::map<std::string, unsigned int> why;
      for (const Outcome &x : o)
        {
          failed += !x.converged;
          solver += x.solver_caused;
          if (!x.converged && !x.solver_caused)
            ++why[x.status];
          if (x.converged)
            {
              increments += x.increments;
              iterations += x.iterations;
            }
          seconds += x.seconds;
          csv << c.material << "," << c.tip_mm << "," << x.target[0] << ","
              << x.target[1] << "," << x.target[2] << ","
              << (x.converged     ? "converged" :
                  x.solver_caused ? "solver" :
                                    "no-equilibrium")
              << "\n";
        }
      const double failure_pct = 100.0 * failed / o.size();
      const double solver_pct  = 100.0 * solver / o.size();
      const double avg_iters =
        increments > 0 ? double(iterations) / increments : 0;
      std::string reasons;
      for (const auto &[status, count] : why)
        reasons +=
          (reasons.empty() ? "" : ", ") + std::to_string(count) + " " + status;
      std::cout << "| " << c.material << " | "
                << (c.tip_mm > 0 ?
                      "tip " + Utilities::to_string(c.tip_mm, 3) + " mm" :
                      std::string("point"))
                << " | " << 1 + tip_nodes << " | "
                << Utilities::to_string(failure_pct, 3) << " % | "
                << Utilities::to_string(solver_pct, 3) << " % | "
                << (reasons.empty() ? std::string("-") : reasons) << " | "
                << paper[k] << " | " << Utilities::to_string(avg_iters, 3)
                << " | " << Utilities::to_string(1000 * seconds / o.size(), 3)
                << " |\n";
      results << "RESULT failure-points material=" << c.material
              << " probe_mm=" << c.tip_mm
              << " failure_pct=" << Utilities::to_string(failure_pct, 3)
              << " solver_failure_pct=" << Utilities::to_string(solver_pct, 3)
              << " avg_iters=" << Utilities::to_string(avg_iters, 3) << "\n";
    }
  std::cout << "\n"
            << "wall time " << std::fixed << std::setprecision(0)
            << std::chrono::duration<double>(std::chrono::steady_clock::now() -
                                             t0)
                 .count()
            << " s; every target and its outcome: failure-points.csv (map: "
               "/usr/bin/python3 doc/images/failure_points.py "
               "failure-points.csv)\n\n"
            << results.str();
  return 0;
}



int
main(int argc, char **argv)
{
  return report_errors("failure-points", run_benchmark, argc, argv);
}
