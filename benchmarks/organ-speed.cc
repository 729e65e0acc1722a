// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

// benchmarks/run organ-speed [--quick|--smoke] [--refinement 5,2.5] [--scaling]
//                            [--material nh,mr] [--lines L] [--no-stroke]
//                            [--csv FILE]
//
// Real organs at human speed. The shipped liver surface
// (meshes/liver-tetgen/liver2k-surface.obj, 25 cm) meshed by palpate's own
// mesher at about 1,500 and 4,000 nodes, touched by the indenter of
// parameters/liver-indenter.prm (a 1 cm sphere, the liver on its bed), in
// neo-Hookean (E = 15465 Pa, nu = 0.49) and incompressible Mooney-Rivlin
// (P1-P1), the recommended discretisation of benchmarks/run convergence.
//
// Part 1, the cost of a state on one core, lever by lever. The states are
// the ones a solver worker computes in a cloud: grid neighbours at 5 mm, on
// lines leaving a pressed state (the sphere 5 mm deep) along +x, -x, +y and
// -y, each computed from the previous one on its line (and, with
// extrapolation, from the two behind it), by one StateSolver per
// configuration, as a worker keeps one. Each configuration adds one lever
// to the one before; every configuration's forces are compared with the
// unchanged solver's (the first row), state by state.
//
// Part 2 (unless --no-stroke), the fastest straight stroke: whole
// interactions as `palpate scene.prm` runs them, with the best
// configuration, 2 solver threads and 2 MPI servers; speed doubled until a
// missing-data event, then bisected.
//
// --smoke (the test suite's): every part on the liver meshed at 8 mm
// near the probe, Mooney-Rivlin: part 1 with the unchanged solver and all
// the levers, one state per line; part 3 with the initial cloud within
// two grid steps; part 2 with one trial of the thread engine.

#include <palpate/app/interaction_run.h>
#include <palpate/base/environment.h>
#include <palpate/base/utilities.h>
#include <palpate/engine/mpi_engine.h>
#include <palpate/haptics/run_summary.h>
#include <palpate/hyperelastic/hyperelastic_system.h>
#include <palpate/hyperelastic/mumps_library.h>
#include <palpate/hyperelastic/state_solver.h>
#include <palpate/mesh/mesh.h>
#include <palpate/mesh/node_selection.h>
#include <palpate/scene/scene.h>

#include <dlfcn.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <numeric>
#include <sstream>
#include <vector>

#include "machine.h"
#include "ml_preconditioner.h"
#include "mpi_child.h"
#include "report_errors.h"

using namespace palpate;
using Utilities::Point3;

namespace
{
  using Clock = std::chrono::steady_clock;
  using Utilities::seconds_since;

  struct Options
  {
    bool quick = false;
    bool smoke = false;
    /** Refinement sizes near the probe (m): 2,012 nodes (the shipped
     * parameters/liver-indenter.prm) and 3,976 nodes. */
    std::vector<double>      sizes     = {0.004, 0.0025};
    std::vector<std::string> materials = {"nh", "mr"};
    unsigned int             lines     = 6; // states per line
    /** Only the first and the last lever, on a series of meshes: the
     * growth of the state time with the unknowns. */
    bool scaling = false;
    bool stroke  = true;
    /** Print every Newton iteration of the last lever's states. */
    bool trace = false;
    /** Maximum Krylov iterations for every lever (0: the scene's). */
    unsigned int krylov = 0;
    /** The levers to run, by number (0: unchanged, the reference);
     * empty: all. */
    std::vector<unsigned int> levers;
    std::string               csv;
    /** Cores for one state (part 1): assembly threads and BLAS threads in
     * the factorisation (the second level of parallelism). */
    unsigned int cores = 1;
    /** Part 1 with the scene's interpolation (Hermite: every state also
     * makes the probe's stiffness, from factors of its own) or, with
     * --interpolation trilinear, without derivatives. */
    std::string interpolation;
    /** The stroke's engine alone (--engine threads|mpi); empty: both
     * (--quick: threads). */
    std::string engine;
    /** Part 1's grid step (--step MM; 0: the scene's 5 mm). */
    double step = 0;
    /** The longest increment after the levers, in part 1 (--increment MM;
     * 0: as the levers leave it). */
    double increment = 0;
    /** Nonlinear solver / patch_factor_residual after the levers
     * (--patch-residual R; 0: as the levers leave it). */
    double patch_residual = 0;
  };

  /** A solver configuration: the scene's settings with some levers. */
  struct Lever
  {
    std::string name;
    std::string what;
    /** Changes the parameters. */
    std::function<void(Parameters::AllParameters &)> apply;
    /** Whether the solver gets the states behind on the line. */
    bool extrapolate = false;
  };

  struct Measured
  {
    std::string         lever;
    std::vector<double> ms, force_error;
    std::vector<Point3> forces, targets;
    std::vector<bool>   converged;
    unsigned int        unknowns = 0;
    double              newton = 0, krylov = 0, factorizations = 0;
    double              assembly_ms = 0, solve_ms = 0, line_search_ms = 0;
    unsigned int        failed = 0;
  };

  /** A lever's name as a RESULT value (one key=value token): spaces
   * become dashes. */
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
      return std::nan("");
    std::sort(v.begin(), v.end());
    return v.size() % 2 ? v[v.size() / 2] :
                          0.5 * (v[v.size() / 2 - 1] + v[v.size() / 2]);
  }

  Scene
  organ_scene(const double fine_size, const std::string &material)
  {
    Scene scene              = Scene::read(std::string(PALPATE_SOURCE_DIR) +
                              "/parameters/liver-indenter.prm");
    auto &p                  = scene.parameters;
    p.mesh.surface_fine_size = fine_size;
    p.mesh.surface_mesh_directory =
      std::string(PALPATE_BINARY_DIR) + "/organ-speed-meshes";
    p.nonlinear_solver.assembly_threads = 1;
    // The levers start from the reference path, whatever the scene ships
    // (since 2026-11-29 its on-line settings: condensed contact, contact
    // patches on a 10 mm grid, the study's tolerance): contact in the
    // factorised matrix, increments of 2.5 mm, tolerance 1e-8, Hermite on
    // the 5 mm grid, no store.
    p.nonlinear_solver.condensed_contact    = false;
    p.nonlinear_solver.max_increment_length = 0.0025;
    p.nonlinear_solver.residual_tolerance   = 1e-8;
    p.state_space.interpolation             = "tricubic Hermite";
    p.state_space.grid_spacing              = 0.005;
    p.state_space.store                     = "";
    if (material == "nh")
      {
        p.material_model.model_name = "Neo-Hookean";
        p.material_model.set("Neo-Hookean", "Young's modulus", 15465.);
        p.material_model.set("Neo-Hookean", "Poisson's ratio", 0.49);
      }
    return scene;
  }

  /**
   * The states of part 1 with one configuration: the pressed state
   * (untimed), then @p per_line states on each of four grid lines.
   */
  Measured
  measure(const Mesh               &mesh,
          const NodeSelection      &selection,
          Parameters::AllParameters p,
          const Lever              &lever,
          const unsigned int        per_line,
          const Measured           *reference,
          const bool                trace = false)
  {
    lever.apply(p);
    StateSolver solver(mesh, selection, p);
    // Grid steps of the scene's spacing (5 mm; --step), from 5 mm deep.
    const double h = p.state_space.grid_spacing;
    const Point3 pressed_at{{0, 0, -0.005}};
    const State  pressed = solver.solve(solver.rest_state(), pressed_at);
    Measured     m;
    m.lever    = lever.name;
    m.unknowns = solver.system().n_equations();
    if (!pressed.converged)
      {
        std::cerr << "organ-speed: the pressed state failed: "
                  << pressed.message << "\n";
        std::exit(1);
      }
    const Point3 directions[4] = {{{1, 0, 0}},
                                  {{-1, 0, 0}},
                                  {{0, 1, 0}},
                                  {{0, -1, 0}}};
    for (const Point3 &d : directions)
      {
        std::vector<State> line = {pressed};
        for (unsigned int k = 1; k <= per_line; ++k)
          {
            const Point3 target{{pressed_at[0] + k * h * d[0],
                                 pressed_at[1] + k * h * d[1],
                                 pressed_at[2] + k * h * d[2]}};
            const State *behind =
              lever.extrapolate && k >= 2 ? &line[k - 2] : nullptr;
            const State *behind2 =
              lever.extrapolate && k >= 3 ? &line[k - 3] : nullptr;
            const auto  start = Clock::now();
            const State s = solver.solve(line.back(), target, behind, behind2);
            m.ms.push_back(1e3 * seconds_since(start));
            m.forces.push_back(s.force);
            m.targets.push_back(target);
            m.converged.push_back(s.converged);
            if (trace)
              {
                std::cout << "    state " << m.ms.size() << " at ("
                          << 1e3 * target[0] << ", " << 1e3 * target[1] << ", "
                          << 1e3 * target[2] << ") mm: " << m.ms.back()
                          << " ms (stiffness " << 1e3 * s.stiffness_time
                          << ", patch " << 1e3 * s.contact_patch_time
                          << "), |f| " << Utilities::norm(s.force) << " N"
                          << (s.converged ? "" : ", failed: " + s.message)
                          << "\n";
                for (const auto &r : s.history)
                  std::cout
                    << "      inc " << r.increment << "  res "
                    << r.residual_before << " -> " << r.residual_after
                    << "  step " << r.step_length << "  "
                    << (r.factorized ? "factorised" : "GMRES ")
                    << (r.factorized ? "" : std::to_string(r.krylov_iterations))
                    << (r.accelerated ? " accelerated" : "") << "  asm "
                    << 1e3 * r.assembly_time << " solve " << 1e3 * r.solve_time
                    << " ls " << 1e3 * r.line_search_time << " ms\n";
              }
            if (!s.converged)
              {
                ++m.failed;
                break; // the rest of this line has no neighbour
              }
            m.newton += s.newton_iterations;
            m.factorizations += s.stiffness_factorizations;
            for (const auto &r : s.history)
              {
                m.krylov += r.krylov_iterations;
                m.factorizations += r.factorized;
                m.assembly_ms += 1e3 * r.assembly_time;
                m.solve_ms += 1e3 * r.solve_time;
                m.line_search_ms += 1e3 * r.line_search_time;
              }
            line.push_back(s);
          }
      }
    const double n = m.ms.size() - m.failed;
    m.newton /= n, m.krylov /= n, m.factorizations /= n;
    m.assembly_ms /= n, m.solve_ms /= n, m.line_search_ms /= n;
    // Against the unchanged solver, state by state: the same target
    // (a line stops at its first failure point, which need not be the same
    // for both), where both converged (a failure point has no force).
    // Relative to the force, or to 1 mN where it is less (a sphere
    // lifting off: both are round-off there).
    if (reference != nullptr)
      for (unsigned int i = 0; i < m.forces.size(); ++i)
        for (unsigned int j = 0; j < reference->forces.size(); ++j)
          if (reference->targets[j] == m.targets[i] && m.converged[i] &&
              reference->converged[j])
            {
              const double f = Utilities::norm(reference->forces[j]);
              m.force_error.push_back(
                Utilities::distance(m.forces[i], reference->forces[j]) /
                std::max(f, 1e-3));
              break;
            }
    return m;
  }

  /** The stroke's grid (--spacing, --hermite, --patch): 0 keeps the
   * scene's 5 mm; trilinear interpolation unless named (the rounds'
   * stroke). What accuracy costs in time: a coarser grid needs fewer
   * states per millimetre of stroke; the contact patch is accurate at
   * 10 mm (doc/benchmarks/contact-patch.md). */
  struct StrokeGrid
  {
    double spacing = 0; // m
    /** 0 trilinear, 1 tricubic Hermite, 2 contact patch. */
    unsigned int interpolation = 0;

    std::string
    interpolation_name() const
    {
      return interpolation == 1 ? "tricubic Hermite" :
             interpolation == 2 ? "contact patch" :
                                  "trilinear";
    }

    /** As the RESULT line names it. */
    std::string
    interpolation_key() const
    {
      return interpolation == 1 ? "hermite" :
             interpolation == 2 ? "contact_patch" :
                                  "trilinear";
    }
    /** Contact solver = condensed (--stroke-contact condensed, the
     * default) or in matrix (--stroke-contact matrix). */
    bool condensed = true;
    /** The longest increment (--increment MM; 0: a grid step). */
    double increment = 0;
  } stroke_grid;

  /** The stroke's settings: the best lever configuration, the engine. */
  Scene
  stroke_scene(const double       fine_size,
               const std::string &material,
               const std::string &engine)
  {
    Scene scene = organ_scene(fine_size, material);
    auto &p     = scene.parameters;
    if (stroke_grid.spacing > 0)
      p.state_space.grid_spacing = stroke_grid.spacing;
    // Named in the RESULT line, so set either way (the scene's own is
    // Hermite since 2026-11-27).
    p.state_space.interpolation             = stroke_grid.interpolation_name();
    p.nonlinear_solver.max_increment_length = stroke_grid.increment > 0 ?
                                                stroke_grid.increment :
                                                p.state_space.grid_spacing;
    p.nonlinear_solver.condensed_contact    = stroke_grid.condensed;
    // The accuracy study's residual tolerance (part 1's last lever).
    p.nonlinear_solver.residual_tolerance = 1e-3;
    p.engine.type                         = engine;
    p.engine.workers                      = 2;
    // Motion starts once the HIP's cell and its neighbours are computed
    // (the cloud two grid steps around rest: the HIP's cell and its
    // neighbours), not a 26 mm ball: what the engine must keep up with is the
    // stroke, not the start.
    p.scheduler.cloud_radius   = 2 * p.state_space.grid_spacing;
    p.state_space.store        = "";
    p.haptics.loop_rate        = 1000;
    p.haptics.trajectory.start = "after initial cloud";
    p.haptics.trajectory.initial_cloud_time_limit = 3600;
    p.effects.shape_output                        = false;
    p.effects.force_log                           = false;
    scene.validate();
    return scene;
  }

  struct Trial
  {
    double        speed   = 0; // m/s
    bool          passed  = false;
    std::uint64_t missing = 0, deadline_misses = 0, ticks = 0;
    double        state_ms = 0, cloud_seconds = 0, motion_seconds = 0;
    unsigned int  states = 0, failures = 0;
  };

  /** The stroke of parameters/liver-indenter.prm: 14 mm into the liver. */
  const double stroke_length = 0.014;

  Trial
  run_trial(const double       fine_size,
            const std::string &material,
            const std::string &engine,
            const double       speed)
  {
    if (engine == "mpi" && mpi_size() == 1)
      {
        std::ostringstream a;
        a << std::setprecision(17) << "--child " << fine_size << " " << material
          << " " << speed << " " << stroke_grid.spacing << " "
          << stroke_grid.interpolation << " " << stroke_grid.condensed << " "
          << stroke_grid.increment;
        const auto v = mpi_child::run(mpi_child::command(3, a.str()));
        Trial      t;
        t.speed           = speed;
        t.passed          = v.at("passed") == "1";
        t.missing         = std::stoull(v.at("missing"));
        t.deadline_misses = std::stoull(v.at("deadline_misses"));
        t.ticks           = std::stoull(v.at("ticks"));
        t.state_ms        = std::stod(v.at("state_ms"));
        t.cloud_seconds   = std::stod(v.at("cloud_seconds"));
        t.motion_seconds  = std::stod(v.at("motion_seconds"));
        t.states          = std::stoul(v.at("states"));
        t.failures        = std::stoul(v.at("failures"));
        return t;
      }
    Scene scene = stroke_scene(fine_size, material, engine);
    scene.parameters.haptics.trajectory.speed    = speed;
    scene.parameters.haptics.trajectory.duration = stroke_length / speed;
    std::ostringstream quiet;
    const RunSummary   s = run_interaction(quiet, scene);
    Trial              t;
    t.speed           = speed;
    t.missing         = s.missing_events;
    t.deadline_misses = s.deadline_misses;
    t.ticks           = s.ticks;
    t.state_ms        = s.median_state_ms;
    t.cloud_seconds   = s.motion_start;
    t.motion_seconds  = s.motion_duration;
    t.states          = s.states_computed;
    t.failures        = s.states_failed;
    t.passed = t.missing == 0 && s.initial_cloud_complete && !s.loop_truncated;
    return t;
  }

  struct Throughput
  {
    unsigned int states  = 0;
    double       seconds = 0;
    std::string  mumps;
  };

  /**
   * The thread engine's states per second with @p workers: the stroke
   * scene's initial cloud (every grid point within @p radius of rest),
   * timed until the motion may start. With @p private_copies false every
   * solver calls the one MUMPS linked into palpate under its lock (the
   * path before MumpsLibrary), as the reference in the same run.
   */
  Throughput
  thread_throughput(const double       fine_size,
                    const std::string &material,
                    const unsigned int workers,
                    const double       radius,
                    const bool         private_copies)
  {
    const unsigned int limit = MumpsLibrary::max_private_copies();
    MumpsLibrary::set_max_private_copies(private_copies ? limit : 0);
    Scene scene = stroke_scene(fine_size, material, "threads");
    scene.parameters.engine.workers              = workers;
    scene.parameters.scheduler.cloud_radius      = radius;
    scene.parameters.haptics.trajectory.speed    = 0.01;
    scene.parameters.haptics.trajectory.duration = 0.02;
    std::ostringstream quiet;
    const RunSummary   s = run_interaction(quiet, scene);
    Throughput         t;
    t.states  = s.states_computed;
    t.seconds = s.motion_start;
    t.mumps   = MumpsLibrary::description();
    MumpsLibrary::set_max_private_copies(limit);
    return t;
  }

  /** The largest passing speed: doubling or halving from @p start, then
   * bisection to 20 %; at most @p max_trials trials. */
  std::pair<Trial, Trial>
  search(const double       fine_size,
         const std::string &material,
         const std::string &engine,
         const double       start,
         const unsigned int max_trials)
  {
    Trial  best, last;
    double low = 0, high = 0, v = start;
    for (unsigned int trial = 0; trial < max_trials; ++trial)
      {
        const Trial t = run_trial(fine_size, material, engine, v);
        last          = t;
        std::cout << "    " << engine << " " << std::fixed
                  << std::setprecision(1) << 1e3 * v
                  << " mm/s: " << (t.passed ? "pass" : "FAIL") << ", "
                  << t.missing << " missing-data events, cloud "
                  << t.cloud_seconds << " s, " << t.states << " states ("
                  << t.failures << " failed), median " << t.state_ms
                  << " ms/state, deadline misses " << t.deadline_misses
                  << " of " << t.ticks << std::defaultfloat << std::endl;
        if (t.passed)
          low = v, best = t;
        else
          high = v;
        if (high == 0)
          v *= 2;
        else if (low == 0)
          {
            if (v < 0.0005)
              break;
            v /= 2;
          }
        else if (high / low > 1.2)
          v = std::sqrt(low * high);
        else
          break;
      }
    return {best, last};
  }

  /** An MPI trial under mpirun: rank 0 runs it and prints a CHILD line,
   * the other ranks serve. Arguments: fine_size material speed. */
  int
  child(const std::vector<std::string> &a)
  {
    const double fine_size    = std::stod(a[0]);
    stroke_grid.spacing       = std::stod(a[3]);
    stroke_grid.interpolation = std::stoul(a[4]);
    stroke_grid.condensed     = a.size() > 5 && a[5] == "1";
    stroke_grid.increment     = a.size() > 6 ? std::stod(a[6]) : 0.0;
    if (mpi_rank() > 0)
      {
        const Scene         scene = stroke_scene(fine_size, a[1], "mpi");
        const Mesh          mesh  = Mesh::create(scene);
        const NodeSelection nodes = NodeSelection::create(scene, mesh);
        return run_solver_server(scene, mesh, nodes);
      }
    const Trial t = run_trial(fine_size, a[1], "mpi", std::stod(a[2]));
    std::cout << "CHILD passed=" << t.passed << " missing=" << t.missing
              << " deadline_misses=" << t.deadline_misses
              << " ticks=" << t.ticks << " state_ms=" << t.state_ms
              << " cloud_seconds=" << t.cloud_seconds
              << " motion_seconds=" << t.motion_seconds
              << " states=" << t.states << " failures=" << t.failures
              << std::endl;
    return 0;
  }
} // namespace



static int
run_benchmark(int argc, char **argv)
{
  Environment env(argc, argv);
  if (argc == 9 && std::string(argv[1]) == "--child")
    return child(std::vector<std::string>(argv + 2, argv + argc));
  Options o;
  for (int i = 1; i < argc; ++i)
    {
      const std::string a    = argv[i];
      auto              list = [&](auto &out, auto convert) {
        out.clear();
        std::stringstream ss(argv[++i]);
        std::string       item;
        while (std::getline(ss, item, ','))
          out.push_back(convert(item));
      };
      if (a == "--quick")
        o.quick = true;
      else if (a == "--smoke")
        o.smoke = o.quick = true;
      else if (a == "--refinement" && i + 1 < argc)
        list(o.sizes, [](const std::string &s) { return 1e-3 * std::stod(s); });
      else if (a == "--material" && i + 1 < argc)
        list(o.materials, [](const std::string &s) { return s; });
      else if (a == "--lines" && i + 1 < argc)
        o.lines = whole_number(a, argv[++i], 1);
      else if (a == "--no-stroke")
        o.stroke = false;
      else if (a == "--trace")
        o.trace = true;
      else if (a == "--krylov" && i + 1 < argc)
        o.krylov = whole_number(a, argv[++i]);
      else if (a == "--levers" && i + 1 < argc)
        list(o.levers,
             [&a](const std::string &s) { return whole_number(a, s); });
      else if (a == "--scaling")
        {
          o.scaling   = true;
          o.stroke    = false;
          o.lines     = 2;
          o.sizes     = {0.008, 0.006, 0.004, 0.003, 0.0025};
          o.materials = {"mr"};
        }
      else if (a == "--csv" && i + 1 < argc)
        o.csv = argv[++i];
      else if (a == "--step" && i + 1 < argc)
        o.step = 1e-3 * std::stod(argv[++i]);
      else if (a == "--patch-residual" && i + 1 < argc)
        o.patch_residual = std::stod(argv[++i]);
      else if (a == "--increment" && i + 1 < argc)
        o.increment = stroke_grid.increment = 1e-3 * std::stod(argv[++i]);
      else if (a == "--engine" && i + 1 < argc)
        o.engine = argv[++i];
      else if (a == "--interpolation" && i + 1 < argc)
        o.interpolation = argv[++i];
      else if (a == "--spacing" && i + 1 < argc)
        stroke_grid.spacing = 1e-3 * std::stod(argv[++i]);
      else if (a == "--hermite")
        stroke_grid.interpolation = 1;
      else if (a == "--patch")
        stroke_grid.interpolation = 2;
      else if (a == "--stroke-contact" && i + 1 < argc)
        stroke_grid.condensed = std::string(argv[++i]) != "matrix";
      else if (a == "--cores" && i + 1 < argc)
        {
          o.cores  = whole_number(a, argv[++i], 1);
          o.stroke = false; // part 1 only: the stroke's workers use a core
        }
      else
        {
          std::cerr
            << "usage: benchmarks/run organ-speed [--quick|--smoke] "
               "[--refinement 5,2.5] [--scaling] [--csv FILE] [--material nh,mr] [--lines L] "
               "[--no-stroke] [--trace] [--krylov N] [--levers 0,4] "
               "[--cores K] [--interpolation NAME] [--step MM] [--increment MM] [--patch-residual R] [--spacing MM] [--hermite|--patch] [--engine threads|mpi] "
               "[--stroke-contact condensed|matrix]\n";
          return 2;
        }
    }
  if (o.quick)
    {
      o.lines     = 2;
      o.sizes     = {o.smoke ? 0.008 : 0.004};
      o.materials = {"mr"};
    }
  if (o.smoke)
    o.lines = 1;

  // Each lever changes one setting; configuration l applies levers 0..l.
  const std::vector<Lever> levers = {
    {"unchanged",
     "the shipped solver as a 501-node scene sets it: refactorise every "
     "Newton step, MUMPS in double, AMF ordering, increments of 2.5 mm",
     [](Parameters::AllParameters &p) {
       p.nonlinear_solver.set_reuse(false);
       p.nonlinear_solver.free_start = false;
       p.linear_solver.solver        = "MUMPS";
       p.linear_solver.ordering      = "AMF";
     },
     false},
    {"+reuse",
     "GMRES preconditioned by the kept factorisation",
     [](Parameters::AllParameters &p) { p.nonlinear_solver.set_reuse(true); },
     false},
    {"+metis",
     "METIS nested dissection",
     [](Parameters::AllParameters &p) { p.linear_solver.ordering = "METIS"; },
     false},
    {"+extrapolation",
     "the states behind on the line extrapolated",
     [](Parameters::AllParameters &) {},
     true},
    {"+one increment",
     "a grid step (5 mm) in one increment",
     [](Parameters::AllParameters &p) {
       p.nonlinear_solver.max_increment_length = p.state_space.grid_spacing;
     },
     false},
    {"+single precision",
     "single-precision factors as GMRES's preconditioner (MUMPS single)",
     [](Parameters::AllParameters &p) {
       p.linear_solver.solver = "MUMPS single";
     },
     false},
    {"+condensed contact",
     "the sphere's contact out of the factorised tangent, solved on the "
     "candidates' compliance (Contact solver = condensed)",
     [](Parameters::AllParameters &p) {
       p.nonlinear_solver.condensed_contact = true;
       p.nonlinear_solver.anderson_depth    = 0;
     },
     false},
    {"+Anderson",
     "Anderson acceleration of the quasi-Newton steps on kept factors "
     "(Anderson depth = 4)",
     [](Parameters::AllParameters &p) {
       p.nonlinear_solver.anderson_depth                  = 4;
       p.nonlinear_solver.patch_factor_residual           = 0;
       p.nonlinear_solver.anderson_across_contact_changes = false;
     },
     false},
    {"+free start",
     "a sphere that clears the body's free equilibrium (known from a state "
     "without contact force) leaves it there: no Newton steps",
     [](Parameters::AllParameters &p) { p.nonlinear_solver.free_start = true; },
     false},
    {"+patch in Newton",
     "with a contact patch: the Newton solve's factors made with the "
     "patch's Schur complement once the residual is below 1e-4 (the "
     "patch without a factorisation of its own)",
     [](Parameters::AllParameters &p) {
       p.nonlinear_solver.patch_factor_residual = 1e-4;
     },
     false},
    {"+study tolerance",
     "the accuracy study's residual tolerance (1e-3 instead of 1e-8): not "
     "a lever of the same equilibrium, its force difference is the "
     "solver's error",
     [](Parameters::AllParameters &p) {
       p.nonlinear_solver.residual_tolerance = 1e-3;
     },
     false},
    {"+history across contacts",
     "Anderson's history kept while the contact set changes, a step it "
     "fails retried plain before new factors",
     [](Parameters::AllParameters &p) {
       p.nonlinear_solver.anderson_across_contact_changes = true;
     },
     false},
    // Run only when --levers names it (it replaces the factorisation).
    {"AMG instead of MUMPS",
     "Trilinos ML (smoothed aggregation, ILU(0) smoother) as GMRES's "
     "preconditioner, 100 Krylov iterations before a new hierarchy",
     [](Parameters::AllParameters &p) {
       p.linear_solver.solver                   = "ML AMG";
       p.nonlinear_solver.max_krylov_iterations = 100;
     },
     false},
  };
  const unsigned int amg_lever = levers.size() - 1;
  // The smoke: the unchanged solver and every lever but AMG, which
  // replaces the factorisation.
  if (o.smoke && o.levers.empty())
    o.levers = {amg_lever - 1};
  // Configuration l: every lever up to l.
  const auto configuration = [&levers, &o](const unsigned int l) {
    Lever c = levers[l];
    c.apply = [&levers, l, &o](Parameters::AllParameters &p) {
      for (unsigned int i = 0; i <= l; ++i)
        levers[i].apply(p);
      if (o.increment > 0)
        p.nonlinear_solver.max_increment_length = o.increment;
      if (o.patch_residual > 0)
        p.nonlinear_solver.patch_factor_residual = o.patch_residual;
    };
    for (unsigned int i = 0; i <= l; ++i)
      c.extrapolate = c.extrapolate || levers[i].extrapolate;
    return c;
  };

  // One state on several cores: OpenBLAS's threads in the factorisation's
  // dense kernels (Environment set them to one per caller).
  if (o.cores > 1)
    if (const auto set = reinterpret_cast<void (*)(int)>(
          dlsym(RTLD_DEFAULT, "openblas_set_num_threads")))
      set(o.cores);

  std::ostringstream results;
  std::ofstream      csv;
  if (!o.csv.empty())
    {
      csv.open(o.csv);
      csv << "mesh,nodes,unknowns,material,lever,state_ms\n";
    }
  std::cout << "Organ speed ("
            << (o.smoke ? "smoke" :
                o.quick ? "quick" :
                          "full")
            << " run)\nmachine: " << machine() << "\n\n";
  for (const double size : o.sizes)
    for (const std::string &material : o.materials)
      {
        Scene scene = organ_scene(size, material);
        if (!o.interpolation.empty())
          scene.parameters.state_space.interpolation = o.interpolation;
        if (o.step > 0)
          scene.parameters.state_space.grid_spacing = o.step;
        if (o.krylov > 0)
          scene.parameters.nonlinear_solver.max_krylov_iterations = o.krylov;
        scene.parameters.nonlinear_solver.assembly_threads = o.cores;
        const Mesh          mesh = Mesh::create(scene);
        const NodeSelection sel  = NodeSelection::create(scene, mesh);
        std::cout << "liver " << mesh.n_vertices() << " nodes, "
                  << mesh.n_cells() << " tetrahedra, " << material << "\n";
        std::cout
          << "  lever                 state [ms] mean [ms]  Newton  Krylov  "
             "factor.  asm [ms]  solve [ms]  ls [ms]  max force err  "
             "failed\n";
        std::vector<Measured> all;
        for (unsigned int l = 0; l < levers.size(); ++l)
          {
            if (o.scaling && l > 0 && l + 1 < amg_lever)
              continue;
            const bool named =
              std::find(o.levers.begin(), o.levers.end(), l) != o.levers.end();
            if (!o.levers.empty() && l > 0 && !named)
              continue;
            if (l == amg_lever && !named)
              continue;
            const Lever lever = configuration(l);
            ml_lever::setups = ml_lever::applications = ml_lever::failures = 0;
            all.push_back(
              measure(mesh,
                      sel,
                      scene.parameters,
                      lever,
                      o.lines,
                      all.empty() ? nullptr : &all.front(),
                      o.trace &&
                        (o.levers.empty() ? l + 1 == amg_lever : named)));
            const Measured &m = all.back();
            if (l == amg_lever)
              std::cout << "  (ML: " << ml_lever::setups << " hierarchies, "
                        << ml_lever::applications << " V-cycles, "
                        << ml_lever::failures
                        << " failures; GMRES failing with it switched the "
                           "solver to MUMPS in double)\n";
            const double err =
              m.force_error.empty() ?
                0 :
                *std::max_element(m.force_error.begin(), m.force_error.end());
            std::cout << "  " << std::left << std::setw(20) << m.lever
                      << std::right << std::setw(12) << std::setprecision(4)
                      << median(m.ms) << std::setw(10)
                      << std::accumulate(m.ms.begin(), m.ms.end(), 0.0) /
                           std::max<std::size_t>(1, m.ms.size())
                      << std::setw(8) << std::setprecision(3) << m.newton
                      << std::setw(8) << m.krylov << std::setw(9)
                      << m.factorizations << std::setw(10) << m.assembly_ms
                      << std::setw(12) << m.solve_ms << std::setw(9)
                      << m.line_search_ms << std::setw(15) << err
                      << std::setw(8) << m.failed << std::endl;
          }
        const std::string name =
          "liver-" + Utilities::to_string(1e3 * size, 3) + "mm";
        for (const Measured &m : all)
          {
            const double err =
              m.force_error.empty() ?
                0 :
                *std::max_element(m.force_error.begin(), m.force_error.end());
            // The median over the states that press into the liver too:
            // where a line leaves the organ, states in the air (a free start
            // when that lever is on) would make the median theirs.
            std::vector<double> pressed;
            for (std::size_t i = 0; i < m.ms.size(); ++i)
              if (m.converged[i] && Utilities::norm(m.forces[i]) > 0)
                pressed.push_back(m.ms[i]);
            results << "RESULT organ-speed mesh=" << name
                    << " nodes=" << mesh.n_vertices()
                    << " material=" << material << " unknowns=" << m.unknowns
                    << " lever=" << dashed(m.lever)
                    << " state_ms=" << median(m.ms)
                    << " contact_state_ms=" << median(pressed)
                    << " contact_states=" << pressed.size() << " mean_ms="
                    << std::accumulate(m.ms.begin(), m.ms.end(), 0.0) /
                         std::max<std::size_t>(1, m.ms.size())
                    << " newton=" << m.newton << " krylov=" << m.krylov
                    << " factorizations=" << m.factorizations
                    << " states=" << m.ms.size() << " failed=" << m.failed
                    << " compared=" << m.force_error.size()
                    << " max_force_rel_err=" << err << "\n";
            if (csv)
              csv << name << "," << mesh.n_vertices() << "," << m.unknowns
                  << "," << material << "," << m.lever << "," << median(m.ms)
                  << "\n";
          }
        if (!o.stroke)
          continue;

        // Part 3: states per second of the thread engine, one worker and
        // two, each solver with a MUMPS of its own and (the reference)
        // all sharing the linked one. Three grid steps around rest: about
        // half the states press into the liver, up to 15 mm deep.
        if (o.engine != "mpi")
          std::cout << "  thread engine, the initial cloud within "
                    << (o.smoke ? 2e3 : 3e3) *
                         (stroke_grid.spacing > 0 ? stroke_grid.spacing : 0.005)
                    << " mm of rest:\n";
        for (const bool private_copies : {false, true})
          {
            if (o.engine == "mpi")
              break; // the thread engine's measure
            double one = 0;
            for (const unsigned int workers : {1u, 2u})
              {
                const double h =
                  stroke_grid.spacing > 0 ? stroke_grid.spacing : 0.005;
                const Throughput t = thread_throughput(size,
                                                       material,
                                                       workers,
                                                       (o.smoke ? 2 : 3) * h,
                                                       private_copies);
                const double rate  = t.seconds > 0 ? t.states / t.seconds : 0;
                if (workers == 1)
                  one = rate;
                std::cout << "    " << workers << " worker(s), MUMPS "
                          << (private_copies ? "per solver" : "shared") << ": "
                          << t.states << " states in " << std::fixed
                          << std::setprecision(1) << t.seconds << " s, "
                          << std::setprecision(2) << rate << " states/s"
                          << (workers == 2 && one > 0 ?
                                " (" + Utilities::to_string(rate / one, 3) +
                                  "x one worker)" :
                                std::string())
                          << std::defaultfloat << "\n      (" << t.mumps << ")"
                          << std::endl;
                results << "RESULT organ-speed mesh=" << name
                        << " nodes=" << mesh.n_vertices()
                        << " material=" << material
                        << " engine=threads workers=" << workers << " mumps="
                        << (private_copies ? "per_solver" : "shared")
                        << " states=" << t.states << " states_per_s=" << rate
                        << "\n";
              }
          }

        // Part 2: the stroke, with the last (all levers) configuration.
        const double state_ms = median(all.back().ms);
        std::cout << "  stroke: " << 1e3 * stroke_length
                  << " mm along (-0.8, 0, -0.6), 2 workers\n";
        for (const std::string &engine :
             !o.engine.empty() ? std::vector<std::string>{o.engine} :
             o.quick           ? std::vector<std::string>{"threads"} :
                                 std::vector<std::string>{"threads", "mpi"})
          {
            // --quick has two trials: it starts where two workers of this
            // state time can plausibly keep up (a grid step's cell ahead
            // needs about four new states, two per worker), so that its
            // line names a speed; the full search starts at a hand's speed.
            const double h =
              stroke_grid.spacing > 0 ? stroke_grid.spacing : 0.005;
            const double start =
              o.quick ? std::clamp(h / (4e-3 * state_ms), 0.0005, 0.028) :
              state_ms < 300 ? 0.028 :
                               0.004;
            const auto [best, last] = search(size,
                                             material,
                                             engine,
                                             start,
                                             o.smoke ? 1 :
                                             o.quick ? 2 :
                                                       6);
            const Trial &shown      = best.passed ? best : last;
            // The platform's own misses in as many ticks, with the
            // solvers' load beside it.
            const auto bare =
              bare_loop(std::max(1.0, 1e-3 * shown.ticks), 1000, 2);
            results << "RESULT organ-speed mesh=" << name
                    << " nodes=" << mesh.n_vertices()
                    << " material=" << material << " engine=" << engine
                    << " workers=2"
                    << " grid=" << stroke_grid.interpolation_key() << "_"
                    << 1e3 *
                         (stroke_grid.spacing > 0 ? stroke_grid.spacing : 0.005)
                    << "mm"
                    << " contact="
                    << (stroke_grid.condensed ? "condensed" : "matrix")
                    << " online=yes state_ms=" << state_ms
                    << " speed_mm_s=" << (best.passed ? 1e3 * best.speed : 0)
                    << " missing_data=" << shown.missing
                    << " deadline_misses=" << shown.deadline_misses
                    << " bare_loop_misses=" << bare.first
                    << " ticks=" << shown.ticks << "\n";
          }
      }
  std::cout << "\n" << results.str();
  return 0;
}



int
main(int argc, char **argv)
{
  return report_errors("organ-speed", run_benchmark, argc, argv);
}
