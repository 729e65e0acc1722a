// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

// benchmarks/run newton [--quick|--smoke] [--material stvk|nh|mr] [--element
// p1p1|taylor-hood]
//                       [--targets N]
//                       [--spacing H] [--radius R] [--seed S] [--no-studies]
//
// The paper's Table 1, measured on the liver of parameters/paper-stvk.prm
// (liver501, 25 cm, 11 fixed nodes, active node 95; see that file):
//
// 1. A scaffold of states on a regular grid of active-node positions
//    (spacing H, default 1 cm) within a ball of radius R (default 10 cm,
//    the paper's largest displacement), computed breadth-first from the
//    rest state, each from an axis neighbour that converged (incremental
//    staging + Newton, as in the paper).
// 2. N random targets (default 200) uniform in the ball, each reached from
//    the nearest converged grid state.
// 3. Over the targets: median assembly, solve and line-search time per
//    Newton iteration, average and maximum Newton iterations per state,
//    and the percentage of failure points.
//
// Studies (unless --no-studies): where the time goes with each direct
// solver and ordering, the symbolic analysis that is done once, assembly
// threads, and what accuracy (the residual tolerance) costs in time.
//
// --smoke (the test suite's): every part above on a 2 cm grid within
// 2 cm, 3 targets, the engine's path within 5 mm (seconds).

#include <palpate/base/environment.h>
#include <palpate/hyperelastic/hyperelastic_system.h>
#include <palpate/hyperelastic/linear_solver.h>
#include <palpate/hyperelastic/state_solver.h>
#include <palpate/mesh/mesh.h>
#include <palpate/mesh/node_selection.h>
#include <palpate/scene/scene.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <deque>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <map>
#include <random>
#include <sstream>

#include "report_errors.h"

using namespace palpate;
using Utilities::Point3;

namespace
{
  struct Options
  {
    bool         quick    = false;
    bool         smoke    = false;
    std::string  material = "stvk";
    std::string  element  = "p1p1";
    double       spacing  = 0.01;
    double       radius   = 0.1;
    unsigned int targets  = 200;
    unsigned int seed     = 1;
    bool         studies  = true;
    /** liver501 (the paper's size) or liver2k (2059 nodes, 10223 tets,
     * the size of the paper authors' second liver), same organ and
     * coordinates. */
    std::string mesh = "liver501";
    /** Only the cost-growth study. */
    bool growth = false;
  };

  /** A solver's name as a RESULT value: spaces become dashes. */
  std::string
  dashed(std::string name)
  {
    std::replace(name.begin(), name.end(), ' ', '-');
    return name;
  }

  double
  median(std::vector<double> v)
  {
    if (v.empty())
      return 0;
    std::sort(v.begin(), v.end());
    return v.size() % 2 ? v[v.size() / 2] :
                          0.5 * (v[v.size() / 2 - 1] + v[v.size() / 2]);
  }

  /** Newton statistics of a set of state computations. */
  struct Statistics
  {
    unsigned int                        states = 0, failures = 0;
    std::map<std::string, unsigned int> reasons;    // failure status -> count
    std::vector<double>                 iterations; // per converged state
    std::vector<double> assembly, solve, line_search, total; // per iteration, s
    std::vector<double> state_time; // per converged state, s
    // Newton steps that factorised the tangent, and GMRES iterations of
    // the steps that did not (Reuse factorization).
    unsigned int steps = 0, factorized = 0, krylov = 0;

    void
    add(const State &s)
    {
      ++states;
      if (!s.converged)
        {
          ++failures;
          ++reasons[to_string(s.status)];
        }
      else
        {
          iterations.push_back(s.newton_iterations);
          state_time.push_back(s.wall_time);
        }
      for (const auto &h : s.history)
        {
          assembly.push_back(h.assembly_time);
          solve.push_back(h.solve_time);
          line_search.push_back(h.line_search_time);
          total.push_back(h.assembly_time + h.solve_time + h.line_search_time);
          ++steps;
          factorized += h.factorized;
          krylov += h.factorized ? 0 : h.krylov_iterations;
        }
    }

    double
    average_iterations() const
    {
      double s = 0;
      for (const double i : iterations)
        s += i;
      return iterations.empty() ? 0 : s / iterations.size();
    }

    double
    max_iterations() const
    {
      return iterations.empty() ?
               0 :
               *std::max_element(iterations.begin(), iterations.end());
    }

    double
    failure_percentage() const
    {
      return states ? 100.0 * failures / states : 0;
    }
  };

  /** The body, its grid scaffold of states, and the random targets. */
  class Study
  {
  public:
    Study(const Options &options)
      : options(options)
      , scene(make_scene(options))
      , mesh(Mesh::create(scene))
      , nodes(NodeSelection::create(scene, mesh))
    {}

    static Scene
    make_scene(const Options &o)
    {
      const bool blob  = o.mesh.rfind("blob", 0) == 0;
      Scene      scene = Scene::read(std::string(PALPATE_SOURCE_DIR) +
                                (blob ? "/parameters/default.prm" :
                                      o.material == "mr" ?
                                             "/parameters/paper-mooney-rivlin.prm" :
                                             "/parameters/paper-stvk.prm"));
      if (o.material == "nh")
        scene.parameters.material_model.model_name = "Neo-Hookean";
      if (blob)
        {
          // The organ-like blob of the default scene at resolution r
          // ("blobR"): (3 (r + 1) + 1)^3 nodes.
          scene.parameters.mesh.blob_refinements = std::stoi(o.mesh.substr(4));
          if (o.material == "mr")
            scene.parameters.material_model.model_name = "Mooney-Rivlin";
        }
      else if (o.mesh != "liver501")
        {
          auto &file = scene.parameters.mesh.file_name;
          file.replace(file.rfind("liver501"), 8, o.mesh);
        }
      if (o.material == "mr")
        scene.parameters.material_model.set("Mooney-Rivlin",
                                            "Element",
                                            o.element == "taylor-hood" ?
                                              "Taylor-Hood" :
                                              "P1-P1");
      // Each transition is one grid step or less: one increment.
      scene.parameters.nonlinear_solver.max_increment_length = o.spacing;
      return scene;
    }

    /** Breadth-first over the grid from the rest state; with
     * @p use_behind, each solve also gets the state behind its source on
     * the same grid line, where it was computed (second-order start). */
    Statistics
    build_scaffold(StateSolver &solver,
                   const bool   use_behind  = false,
                   const bool   third_order = false)
    {
      Statistics statistics;
      const int  n =
        static_cast<int>(std::floor(options.radius / options.spacing + 1e-9));
      const State                    rest = solver.rest_state();
      std::deque<std::array<int, 3>> queue;
      grid[{{0, 0, 0}}] = rest;
      queue.push_back({{0, 0, 0}});
      std::map<std::array<int, 3>, bool> visited{{{{0, 0, 0}}, true}};
      while (!queue.empty())
        {
          const auto p = queue.front();
          queue.pop_front();
          for (unsigned int axis = 0; axis < 3; ++axis)
            for (const int sign : {-1, 1})
              {
                auto q = p;
                q[axis] += sign;
                if (std::abs(q[axis]) > n || visited[q] ||
                    norm(position(q)) > options.radius + 1e-12)
                  continue;
                visited[q]  = true;
                auto behind = p, behind2 = p;
                behind[axis] -= sign;
                behind2[axis] -= 2 * sign;
                const auto b  = grid.find(behind);
                const auto b2 = grid.find(behind2);
                State      state =
                  solver.solve(grid[p],
                               position(q),
                               use_behind && b != grid.end() ? &b->second :
                                                               nullptr,
                               use_behind && third_order && b2 != grid.end() ?
                                 &b2->second :
                                 nullptr);
                statistics.add(state);
                if (state.converged)
                  {
                    state.history.clear();
                    grid[q] = std::move(state);
                    queue.push_back(q);
                  }
              }
        }
      return statistics;
    }

    /** Random targets in the ball, each with its nearest grid state. */
    std::vector<std::pair<Point3, const State *>>
    targets(const unsigned int count) const
    {
      std::mt19937                           random(options.seed);
      std::uniform_real_distribution<double> u(-options.radius, options.radius);
      std::vector<std::pair<Point3, const State *>> result;
      while (result.size() < count)
        {
          const Point3 t = {{u(random), u(random), u(random)}};
          if (norm(t) > options.radius)
            continue;
          const State *nearest = nullptr;
          double       best    = 1e300;
          for (const auto &[index, state] : grid)
            if (const double d = Utilities::distance(position(index), t);
                d < best)
              best = d, nearest = &state;
          result.emplace_back(t, nearest);
        }
      return result;
    }

    Point3
    position(const std::array<int, 3> &i) const
    {
      return {{i[0] * options.spacing,
               i[1] * options.spacing,
               i[2] * options.spacing}};
    }

    static double
    norm(const Point3 &p)
    {
      return Utilities::norm(p);
    }

    const Options                      &options;
    Scene                               scene;
    Mesh                                mesh;
    NodeSelection                       nodes;
    std::map<std::array<int, 3>, State> grid;
  };

  std::string
  ms(const double seconds, const int precision = 3)
  {
    std::ostringstream s;
    s << std::setprecision(precision) << 1000 * seconds;
    return s.str();
  }

  std::string
  blas_in_use()
  {
    std::ifstream maps("/proc/self/maps");
    std::string   line;
    while (std::getline(maps, line))
      {
        if (line.find("openblas") != std::string::npos)
          return "OpenBLAS";
        if (line.find("libblas.so") != std::string::npos &&
            line.find("/blas/") != std::string::npos)
          return "reference BLAS";
      }
    return "unknown BLAS";
  }
} // namespace



namespace
{
  /**
   * How the cost of a state grows with the mesh: the engine's path (the
   * cloud of radius 10 mm around rest, 5 mm grid, breadth-first from
   * neighbours, one solver) on the organ-like blob at four resolutions
   * and on liver501 and liver2k, with the plain solver (a factorisation
   * per Newton step, tangent predictor) and with palpate's levers
   * (factorisation reuse and the second-order start). The exponent p of
   * state time ~ unknowns^p is the least-squares slope on log-log axes.
   * Writes newton-growth.csv for doc/images/newton_growth.py.
   */
  int
  growth_study(const Options &o)
  {
    std::vector<std::string> meshes = {
      "blob1", "blob2", "blob3", "blob4", "liver501", "liver2k"};
    if (o.quick)
      meshes = {"blob1", "blob2", "blob3", "liver501"};
    std::cout << "Cost growth: state time against unknowns, "
              << (o.material == "mr" ? "Mooney-Rivlin P1-P1" :
                                       "St.Venant-Kirchhoff")
              << ", the engine's path (cloud of " << (o.quick ? 5 : 10)
              << " mm around rest, 5 mm grid, one solver)\n"
              << "  mesh        nodes  unknowns  plain (ms)  levers (ms)  "
                 "speed-up\n";
    std::ofstream csv("newton-growth.csv");
    csv << "mesh,nodes,unknowns,plain_ms,levers_ms\n";
    std::vector<double>      logn, logp, logl;
    std::vector<std::string> lines;
    for (const auto &m : meshes)
      {
        Options e             = o;
        e.mesh                = m;
        e.spacing             = 0.005;
        e.radius              = o.quick ? 0.005 : 0.01;
        double       ms_of[2] = {0, 0};
        unsigned int unknowns = 0, nodes = 0;
        for (const bool levers : {false, true})
          {
            Study       path(e);
            StateSolver s(path.mesh, path.nodes, path.scene.parameters);
            s.settings().reuse_factorization = levers;
            const Statistics st              = path.build_scaffold(s, levers);
            ms_of[levers]                    = 1000 * median(st.state_time);
            unknowns                         = s.system().n_equations();
            nodes                            = path.mesh.n_vertices();
          }
        std::cout << "  " << std::left << std::setw(10) << m << std::right
                  << std::setw(7) << nodes << std::setw(10) << unknowns
                  << std::setw(12) << std::setprecision(3) << ms_of[0]
                  << std::setw(13) << ms_of[1] << std::setw(10)
                  << ms_of[0] / ms_of[1] << std::endl;
        csv << m << "," << nodes << "," << unknowns << "," << ms_of[0] << ","
            << ms_of[1] << "\n";
        logn.push_back(std::log(unknowns));
        logp.push_back(std::log(ms_of[0]));
        logl.push_back(std::log(ms_of[1]));
        std::ostringstream r;
        r << std::setprecision(3) << "RESULT newton study=growth material="
          << (o.material == "mr" ? "mooney-rivlin" : o.material)
          << " mesh=" << m << " unknowns=" << unknowns
          << " plain_state_ms=" << ms_of[0] << " levers_state_ms=" << ms_of[1];
        lines.push_back(r.str());
      }
    const auto slope = [&](const std::vector<double> &y) {
      double mx = 0, my = 0;
      for (unsigned int i = 0; i < y.size(); ++i)
        mx += logn[i] / y.size(), my += y[i] / y.size();
      double sxy = 0, sxx = 0;
      for (unsigned int i = 0; i < y.size(); ++i)
        sxy += (logn[i] - mx) * (y[i] - my),
          sxx += (logn[i] - mx) * (logn[i] - mx);
      return sxy / sxx;
    };
    std::cout << "  exponent (state time ~ unknowns^p): plain p = "
              << std::setprecision(3) << slope(logp)
              << ", with the levers p = " << slope(logl)
              << "\n  wrote newton-growth.csv (plot: "
              << "/usr/bin/python3 doc/images/newton_growth.py "
                 "newton-growth.csv doc/images/newton-growth.png)\n\n";
    for (const auto &l : lines)
      std::cout << l << "\n";
    std::cout << "RESULT newton study=growth-exponent material="
              << (o.material == "mr" ? "mooney-rivlin" : o.material)
              << " plain_exponent=" << std::setprecision(3) << slope(logp)
              << " levers_exponent=" << slope(logl) << "\n";
    return 0;
  }
} // namespace

static int
run_benchmark(int argc, char **argv)
{
  Environment environment(argc, argv);
  Options     o;
  for (int i = 1; i < argc; ++i)
    {
      const std::string a = argv[i];
      if (a == "--quick")
        o.quick = true;
      else if (a == "--smoke")
        o.smoke = true;
      else if (a == "--material" && i + 1 < argc)
        o.material = argv[++i];
      else if (a == "--element" && i + 1 < argc)
        o.element = argv[++i];
      else if (a == "--targets" && i + 1 < argc)
        o.targets = whole_number(a, argv[++i], 1);
      else if (a == "--spacing" && i + 1 < argc)
        o.spacing = std::stod(argv[++i]);
      else if (a == "--radius" && i + 1 < argc)
        o.radius = std::stod(argv[++i]);
      else if (a == "--seed" && i + 1 < argc)
        o.seed = std::stoi(argv[++i]);
      else if (a == "--growth")
        o.growth = true;
      else if (a == "--mesh" && i + 1 < argc)
        o.mesh = argv[++i];
      else if (a == "--no-studies")
        o.studies = false;
      else
        {
          std::cerr << "benchmarks/run newton: unknown option " << a
                    << "\nusage: benchmarks/run newton [--quick|--smoke] "
                       "[--material stvk|nh|mr] [--element p1p1|taylor-hood] "
                       "[--targets N] [--spacing H] [--radius R] [--seed S] "
                       "[--no-studies] [--mesh liver501|liver2k] [--growth]\n";
          return 2;
        }
    }
  // --quick: a minute or less. A liver2k state costs 10x a liver501 one,
  // so its quick run has fewer targets and a smaller cloud.
  if (o.quick)
    o.spacing = 0.02, o.radius = 0.06,
    o.targets = o.mesh == "liver2k" ? 10 : 50;
  // The studies replay solvers as slow as KLU (0.5 s per liver2k
  // factorisation): they alone would take two minutes.
  if (o.quick && o.mesh == "liver2k")
    o.studies = false;
  if (o.smoke)
    o.spacing = 0.02, o.radius = 0.02, o.targets = 3;
  if (o.mesh != "liver501" && o.mesh != "liver2k")
    {
      std::cerr << "benchmarks/run newton: --mesh is liver501 or liver2k\n";
      return 2;
    }
  if (o.growth)
    return growth_study(o);
  if ((o.material != "stvk" && o.material != "nh" && o.material != "mr") ||
      (o.element != "p1p1" && o.element != "taylor-hood"))
    {
      std::cerr
        << "benchmarks/run newton: --material is stvk, nh or mr; --element "
           "(for mr) is p1p1 or taylor-hood\n";
      return 2;
    }

  std::vector<std::string> results;
  Study                    study(o);
  const auto              &p = study.scene.parameters;
  StateSolver              solver(study.mesh, study.nodes, p);
  const std::string        mesh_name = o.mesh;
  const std::string        material =
    o.material == "stvk" ?
             "St.Venant-Kirchhoff" :
           o.material == "nh" ?
             "neo-Hookean" :
             std::string("Mooney-Rivlin ") +
        (o.element == "taylor-hood" ? "Taylor-Hood" : "P1-P1");
  // The paper's Table 1, per material (Mooney-Rivlin: its P1-P1 column).
  const bool paper_stvk = o.material == "stvk", paper_mr = o.material == "mr";
  const auto paper = [&](const char *stvk, const char *mr) {
    return std::string(paper_stvk ? stvk : paper_mr ? mr : "-");
  };

  std::cout << "Newton benchmark: the paper's Table 1 on " << mesh_name << " ("
            << study.mesh.n_vertices() << " nodes, " << study.mesh.n_cells()
            << " tetrahedra), " << material << ", "
            << solver.system().n_equations() << " equations\n"
            << "  linear solver " << solver.linear_solver_name() << ", "
            << blas_in_use() << ", " << p.nonlinear_solver.assembly_threads
            << " assembly thread(s)\n"
            << "  grid spacing " << 100 * o.spacing << " cm within "
            << 100 * o.radius << " cm, " << o.targets
            << " random targets, seed " << o.seed << "\n\n";

  const auto   t0       = std::chrono::steady_clock::now();
  const auto   scaffold = study.build_scaffold(solver);
  const double scaffold_seconds =
    std::chrono::duration<double>(std::chrono::steady_clock::now() - t0)
      .count();
  std::cout << "Scaffold: " << scaffold.states << " grid states in "
            << std::setprecision(3) << scaffold_seconds << " s, "
            << scaffold.failure_percentage() << " % failure points, "
            << scaffold.average_iterations()
            << " Newton iterations on average\n\n";

  const auto targets = study.targets(o.targets);
  Statistics main;
  double     far = 0; // targets more than one grid step from their start
  for (const auto &[target, from] : targets)
    {
      main.add(solver.solve(*from, target));
      if (Utilities::distance(from->active_displacement, target) > o.spacing)
        ++far;
    }

  std::cout << "Table 1: per Newton iteration (medians) and per state, "
            << o.targets << " random targets from their nearest grid state\n"
            << std::left << std::setw(34) << "" << std::setw(26)
            << "paper (Xeon 5160, GetFEM)"
            << "palpate (this machine, 1 core)\n"
            << std::setw(34) << "assembly time per iteration" << std::setw(26)
            << paper("210 ms", "510 ms") << ms(median(main.assembly)) << " ms\n"
            << std::setw(34) << "solution time per iteration" << std::setw(26)
            << paper("30 ms", "110 ms") << ms(median(main.solve)) << " ms\n"
            << std::setw(34) << "line search time per iteration"
            << std::setw(26) << paper("50 ms", "140 ms")
            << ms(median(main.line_search)) << " ms\n"
            << std::setw(34) << "total per iteration" << std::setw(26)
            << paper("290 ms", "760 ms") << ms(median(main.total)) << " ms\n"
            << std::setw(34) << "average Newton iterations" << std::setw(26)
            << paper("2.4", "4.2") << std::setprecision(3)
            << main.average_iterations() << "\n"
            << std::setw(34) << "maximum Newton iterations" << std::setw(26)
            << paper("10", "14") << main.max_iterations() << "\n"
            << std::setw(34) << "failure points" << std::setw(26)
            << paper("19.7 %", "1.4 %") << main.failure_percentage() << " %\n"
            << std::setw(34) << "time per converged state" << std::setw(26)
            << "-" << ms(median(main.state_time)) << " ms (median)\n"
            << std::right;
  std::cout << "Newton steps that factorised the tangent: " << main.factorized
            << " of " << main.steps << "; the others took "
            << (main.steps > main.factorized ?
                  double(main.krylov) / (main.steps - main.factorized) :
                  0.0)
            << " GMRES iterations on average (Nonlinear solver / Reuse "
               "factorization = "
            << (p.nonlinear_solver.reuse_factorization ? "true" : "false")
            << ")\n";
  std::cout << "Failure points by reason:";
  for (const auto &[reason, count] : main.reasons)
    std::cout << " " << reason << " " << count;
  std::cout << "; " << 100 * far / targets.size()
            << " % of the targets are more than one grid step from the nearest "
               "converged grid state\n\n";
  {
    std::ostringstream r;
    r << std::setprecision(3) << "RESULT newton material="
      << (o.material == "mr" ? "mooney-rivlin element=" + o.element :
                               o.material)
      << " mesh=" << mesh_name << " assembly_ms=" << ms(median(main.assembly))
      << " solve_ms=" << ms(median(main.solve))
      << " linesearch_ms=" << ms(median(main.line_search))
      << " iteration_ms=" << ms(median(main.total))
      << " avg_iters=" << main.average_iterations()
      << " max_iters=" << main.max_iterations()
      << " failure_pct=" << main.failure_percentage()
      << " state_ms=" << ms(median(main.state_time));
    results.push_back(r.str());
  }

  // The engine's path: the cloud around rest on the engine's 5 mm grid,
  // breadth-first, each state from a converged neighbour, by one solver
  // that keeps its factorisation from state to state, as a worker does.
  // Once with a factorisation at every Newton step, once reusing kept
  // factorisations (GMRES); the forces must agree to 1e-6.
  {
    Options e = o;
    e.spacing = 0.005;
    e.radius  = o.smoke             ? 0.005 :
                !o.quick            ? 0.025 :
                o.mesh == "liver2k" ? 0.01 :
                                      0.015;
    std::cout << "The engine's path: the " << 1000 * e.radius
              << " mm cloud around rest, 5 mm grid, breadth-first from "
                 "neighbours, one solver\n"
              << "  reuse  behind  states  state (ms)  Newton its  "
                 "factorisations  GMRES its   (per state, medians and "
                 "averages)\n";
    std::map<std::pair<bool, bool>, std::map<std::array<int, 3>, State>> grids;
    for (const bool behind : {false, true})
      for (const bool reuse : {false, true})
        {
          Study       path(e);
          StateSolver s(path.mesh, path.nodes, path.scene.parameters);
          s.settings().reuse_factorization = reuse;
          const Statistics st    = path.build_scaffold(s, behind, behind);
          grids[{reuse, behind}] = path.grid;
          const double n         = std::max(1u, st.states);
          std::cout << "  " << std::left << std::setw(7)
                    << (reuse ? "yes" : "no") << std::setw(8)
                    << (behind ? "yes" : "no") << std::right << std::setw(6)
                    << st.states << std::setw(12) << ms(median(st.state_time))
                    << std::setw(12) << std::setprecision(3)
                    << st.average_iterations() << std::setw(16)
                    << st.factorized / n << std::setw(11) << st.krylov / n
                    << "\n";
          std::ostringstream r;
          r << std::setprecision(3) << "RESULT newton study=reuse material="
            << (o.material == "mr" ? "mooney-rivlin element=" + o.element :
                                     o.material)
            << " mesh=" << mesh_name << " reuse=" << (reuse ? "yes" : "no")
            << " behind=" << (behind ? "yes" : "no")
            << " state_ms=" << ms(median(st.state_time))
            << " avg_iters=" << st.average_iterations()
            << " factorizations_per_state=" << st.factorized / n
            << " gmres_per_state=" << st.krylov / n
            << " failure_pct=" << st.failure_percentage();
          results.push_back(r.str());
        }
    double       largest  = 0;
    unsigned int compared = 0, differ = 0, only_one = 0;
    const auto  &plain = grids[{false, false}];
    for (const auto &[variant, g] : grids)
      {
        if (variant == std::make_pair(false, false))
          continue;
        for (const auto &[index, a] : plain)
          if (const auto b = g.find(index); b != g.end())
            {
              ++compared;
              const double d = Utilities::distance(a.force, b->second.force) /
                               std::max(Utilities::norm(a.force), 1e-3);
              largest = std::max(largest, d);
              differ += d > 1e-6;
            }
          else
            ++only_one;
        for (const auto &[index, b] : g)
          only_one += plain.count(index) == 0;
      }
    std::cout << "  forces of the variants against the plain solver, "
              << compared << " states: largest relative difference "
              << std::setprecision(2) << largest << " ("
              << (differ == 0 ? "all within 1e-6" :
                                std::to_string(differ) + " beyond 1e-6")
              << "); states only one of a pair computed: " << only_one
              << "\n\n";
    std::ostringstream r;
    r << "RESULT newton study=reuse-check compared=" << compared
      << " max_force_rel_diff=" << std::setprecision(2) << largest
      << " beyond_1e-6=" << differ;
    results.push_back(r.str());
  }

  if (o.studies)
    {
      // A fixed subset of the transitions, replayed with other settings.
      const unsigned int subset =
        std::min<unsigned int>(o.quick ? 15 : 40, targets.size());

      std::cout
        << "Where the time goes: direct solvers and orderings (" << subset
        << " transitions; medians per Newton iteration)\n"
        << "  solver                                     analysis   solve   iteration\n";
      // Every registered solver (LinearSolverRegistry) with METIS, and
      // MUMPS with its other orderings.
      std::vector<std::pair<std::string, std::string>> solvers;
      for (const auto &plugin : LinearSolverRegistry::plugins())
        {
          solvers.emplace_back(plugin.name, "METIS");
          if (plugin.name == "MUMPS")
            for (const std::string ordering : {"AMD", "AMF", "PORD"})
              solvers.emplace_back(plugin.name, ordering);
        }
      for (const auto &[name, ordering] : solvers)
        {
          auto variant                   = p;
          variant.linear_solver.solver   = name;
          variant.linear_solver.ordering = ordering;
          StateSolver other(study.mesh, study.nodes, variant);
          // The symbolic analysis alone, timed on a fresh solver: what every
          // iteration would cost on top if it were not reused.
          auto       fresh = LinearSolver::create(name, ordering);
          const auto a0    = std::chrono::steady_clock::now();
          fresh->analyze(other.system().sparsity());
          const double analysis =
            std::chrono::duration<double>(std::chrono::steady_clock::now() - a0)
              .count();
          Statistics s;
          for (unsigned int i = 0; i < subset; ++i)
            s.add(other.solve(*targets[i].second, targets[i].first));
          std::cout << "  " << std::left << std::setw(42)
                    << other.linear_solver_name() << std::right << std::setw(6)
                    << ms(analysis) << " ms" << std::setw(6)
                    << ms(median(s.solve)) << " ms" << std::setw(7)
                    << ms(median(s.total)) << " ms\n";
          std::ostringstream r;
          r << "RESULT newton study=linear-solver solver=" << dashed(name)
            << " ordering=" << ordering << " analysis_ms=" << ms(analysis)
            << " solve_ms=" << ms(median(s.solve))
            << " iteration_ms=" << ms(median(s.total));
          results.push_back(r.str());
        }

      std::cout << "\nAssembly threads (" << subset
                << " transitions; medians per iteration)\n";
      for (const unsigned int threads : {1u, 2u})
        {
          auto variant                              = p;
          variant.nonlinear_solver.assembly_threads = threads;
          StateSolver other(study.mesh, study.nodes, variant);
          Statistics  s;
          for (unsigned int i = 0; i < subset; ++i)
            s.add(other.solve(*targets[i].second, targets[i].first));
          std::cout << "  " << threads << " thread(s): assembly "
                    << ms(median(s.assembly)) << " ms, line search "
                    << ms(median(s.line_search)) << " ms, iteration "
                    << ms(median(s.total)) << " ms\n";
          std::ostringstream r;
          r << "RESULT newton study=assembly-threads threads=" << threads
            << " assembly_ms=" << ms(median(s.assembly))
            << " iteration_ms=" << ms(median(s.total));
          results.push_back(r.str());
        }

      std::cout << "\nAdaptive staging: an increment that fails is halved and "
                   "retried (all "
                << targets.size() << " targets)\n";
      for (const unsigned int cutbacks : {0u, 2u, 4u})
        {
          auto variant                          = p;
          variant.nonlinear_solver.max_cutbacks = cutbacks;
          StateSolver other(study.mesh, study.nodes, variant);
          Statistics  s;
          for (const auto &[target, from] : targets)
            s.add(other.solve(*from, target));
          std::cout << "  " << cutbacks << " cutbacks: failure points "
                    << std::setprecision(3) << s.failure_percentage()
                    << " %, average iterations " << s.average_iterations()
                    << ", state time " << ms(median(s.state_time))
                    << " ms (median)\n";
          std::ostringstream r;
          r << std::setprecision(3)
            << "RESULT newton study=cutbacks cutbacks=" << cutbacks
            << " failure_pct=" << s.failure_percentage()
            << " avg_iters=" << s.average_iterations()
            << " state_ms=" << ms(median(s.state_time));
          results.push_back(r.str());
        }

      std::cout
        << "\nWhat accuracy costs (" << subset
        << " transitions): residual tolerance vs Newton iterations, time per state, and\n"
        << "the force error against a 1e-12 reference\n"
        << "  tolerance   avg iterations   state time   max force error\n";
      std::vector<Point3> reference;
      {
        auto variant                                = p;
        variant.nonlinear_solver.residual_tolerance = 1e-12;
        StateSolver tight(study.mesh, study.nodes, variant);
        for (unsigned int i = 0; i < subset; ++i)
          {
            const State s = tight.solve(*targets[i].second, targets[i].first);
            reference.push_back(s.converged ? s.force : Point3{{0, 0, 0}});
          }
      }
      for (const double tolerance : {1e-3, 1e-4, 1e-6, 1e-8, 1e-10})
        {
          auto variant                                = p;
          variant.nonlinear_solver.residual_tolerance = tolerance;
          StateSolver other(study.mesh, study.nodes, variant);
          Statistics  s;
          double      worst = 0;
          for (unsigned int i = 0; i < subset; ++i)
            {
              const State state =
                other.solve(*targets[i].second, targets[i].first);
              s.add(state);
              if (state.converged && Utilities::norm(reference[i]) > 0)
                worst =
                  std::max(worst,
                           Utilities::distance(state.force, reference[i]));
            }
          std::cout << "  " << std::setw(9) << tolerance << std::setw(17)
                    << std::setprecision(3) << s.average_iterations()
                    << std::setw(10) << ms(median(s.state_time)) << " ms"
                    << std::setw(12) << std::setprecision(2) << worst << " N\n";
          std::ostringstream r;
          r << std::setprecision(3)
            << "RESULT newton study=tolerance tolerance=" << tolerance
            << " avg_iters=" << s.average_iterations()
            << " state_ms=" << ms(median(s.state_time))
            << " max_force_error_N=" << std::setprecision(2) << worst;
          results.push_back(r.str());
        }
      std::cout << "\n";
    }

  for (const auto &r : results)
    std::cout << r << "\n";
  return 0;
}



int
main(int argc, char **argv)
{
  return report_errors("newton", run_benchmark, argc, argv);
}
