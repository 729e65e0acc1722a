// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

// benchmarks/run convergence [--quick|--smoke] [--csv FILE]
//
// Does the indenter's force belong to the tissue or to the mesh? For each
// case and discretisation, the force of the same push on meshes of the
// same body at several resolutions, its Richardson extrapolation (the
// force on an infinitely fine mesh, and the observed order), each
// level's error against it, and what a state costs.
//
// - case=hertz (verification): a neo-Hookean block (E = 10 kPa, nu = 0.3),
//   a sphere of 1 cm radius pressed 0.1 mm in (contact radius 1 mm), as a
//   quarter block of 10 cm (HertzBlock) whose mesh is refined by
//   splitting every element alike. The reference is Hertz's
//   F = 4/3 E/(1 - nu^2) R^(1/2) d^(3/2); err_pct is against it.
// - case=liver: parameters/liver-indenter.prm (the INRIA liver on its bed,
//   a sphere of 1 cm radius pressed 1 cm in), its surface meshed by Gmsh
//   with elements of 14 mm away from the probe and of the level's
//   Refinement size within 25 mm of it. err_pct is against the
//   extrapolated force of the best-converged discretisation.
//
// state_ms: the engine's path on one core: a state computed from its
// neighbour on the grid (5 mm away, the pressed state moved across the
// surface), extrapolating from the state behind that neighbour on the
// same grid line, as a solver worker does.
//
// RESULT convergence case=hertz|liver discretization=NAME nodes=N
//   force_N=F extrapolated_N=X err_pct=E state_ms=T
// RESULT convergence case=liver recommended=yes ... err_pct=E state_ms=T
//
// --smoke (the test suite's): one level of each case, the coarsest (the
// Hertz block unsplit, the liver at 8 mm, Mooney-Rivlin P1-P1): the
// forces, no extrapolation.

#include <palpate/base/environment.h>
#include <palpate/hyperelastic/hertz.h>
#include <palpate/hyperelastic/hyperelastic_system.h>
#include <palpate/hyperelastic/state_solver.h>
#include <palpate/mesh/mesh.h>
#include <palpate/mesh/node_selection.h>
#include <palpate/scene/scene.h>

#include <chrono>
#include <cmath>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <sstream>
#include <string>
#include <vector>

#include "machine.h"
#include "report_errors.h"

using namespace palpate;
using Utilities::Point3;

namespace
{
  using Clock = std::chrono::steady_clock;

  using palpate::Utilities::seconds_since;

  /** One mesh level of one discretisation. */
  struct Level
  {
    double       h;     // the refinement parameter (m)
    unsigned int nodes; // mesh nodes
    unsigned int unknowns;
    double       force;    // |f| (N)
    double       state_ms; // from a neighbour
    unsigned int newton;   // Newton iterations of that state
    bool         converged;
  };

  /**
   * Richardson extrapolation F(h) = F0 + C h^p through the three finest
   * levels (any ratios: p solves the ratio equation by bisection). Returns
   * {F0, p}; p = 0 when the three are not monotone (no asymptotic
   * behaviour to extrapolate), and F0 is then the finest force.
   */
  std::pair<double, double>
  richardson(const std::vector<Level> &levels)
  {
    const unsigned int n = levels.size();
    if (n < 3)
      return {levels.back().force, 0};
    const Level &a = levels[n - 3], &b = levels[n - 2], &c = levels[n - 1];
    const double d1 = a.force - b.force, d2 = b.force - c.force;
    if (!(d1 * d2 > 0))
      return {c.force, 0};
    // (a - b)/(b - c) = (ha^p - hb^p)/(hb^p - hc^p) =: g(p), increasing.
    const auto g = [&](const double p) {
      return (std::pow(a.h, p) - std::pow(b.h, p)) /
             (std::pow(b.h, p) - std::pow(c.h, p));
    };
    const double target = d1 / d2;
    double       lo = 0.05, hi = 8;
    if (!(g(lo) < target && g(hi) > target))
      return {c.force, 0};
    for (unsigned int i = 0; i < 100; ++i)
      {
        const double mid            = 0.5 * (lo + hi);
        (g(mid) < target ? lo : hi) = mid;
      }
    const double p  = 0.5 * (lo + hi);
    const double C  = d2 / (std::pow(b.h, p) - std::pow(c.h, p));
    const double F0 = c.force - C * std::pow(c.h, p);
    return {F0, p};
  }

  /**
   * The force at @p push from rest, and the cost of the engine's next
   * state: the pressed state moved along @p across, computed as a solver
   * worker computes a grid neighbour: from the pressed state, with the
   * state one step behind it on the same grid line to extrapolate from
   * (StateSolver::solve's behind). The state behind is computed first,
   * untimed, as the engine computed it earlier.
   */
  Level
  measure(const Mesh                      &mesh,
          const NodeSelection             &nodes,
          const Parameters::AllParameters &p,
          const double                     h,
          const Point3                    &push,
          const Point3                    &across,
          const bool                       quarter)
  {
    StateSolver solver(mesh, nodes, p);
    const State pressed = solver.solve(solver.rest_state(), push);
    Level       level;
    level.h         = h;
    level.nodes     = mesh.n_vertices();
    level.unknowns  = solver.system().n_equations();
    level.converged = pressed.converged;
    level.force =
      quarter ? 4 * std::abs(pressed.force[2]) : Utilities::norm(pressed.force);
    const Point3 next = {
      {push[0] + across[0], push[1] + across[1], push[2] + across[2]}};
    const Point3 back = {
      {push[0] - across[0], push[1] - across[1], push[2] - across[2]}};
    const State behind = solver.solve(pressed, back);
    const auto  start  = Clock::now();
    const State moved =
      solver.solve(pressed, next, behind.converged ? &behind : nullptr);
    level.state_ms  = 1e3 * seconds_since(start);
    level.newton    = moved.newton_iterations;
    level.converged = level.converged && moved.converged;
    return level;
  }

  struct Series
  {
    std::string        case_name, discretization;
    std::vector<Level> levels;
    double             extrapolated = 0, order = 0;
  };

  void
  print_series(const Series &s, const double reference)
  {
    std::cout << "  " << s.discretization << ": extrapolated "
              << std::setprecision(5) << s.extrapolated << " N"
              << (s.order > 0 ?
                    ", observed order " + Utilities::to_string(s.order, 3) :
                  s.levels.size() < 3 ?
                    std::string(" (fewer than 3 levels: the finest force)") :
                    std::string(" (the 3 finest not monotone: the finest "
                                "force)"))
              << "\n";
    std::cout << "    h [mm]    nodes  unknowns    force [N]   err [%]  "
                 "state [ms]  Newton\n";
    for (const auto &l : s.levels)
      std::cout << std::setw(10) << std::setprecision(3) << 1e3 * l.h
                << std::setw(9) << l.nodes << std::setw(10) << l.unknowns
                << std::setw(13) << std::setprecision(5) << l.force
                << std::setw(10) << std::setprecision(3)
                << 100 * (l.force - reference) / reference << std::setw(12)
                << std::setprecision(4) << l.state_ms << std::setw(8)
                << l.newton << (l.converged ? "" : "  FAILED") << "\n";
  }
} // namespace



static int
run_benchmark(int argc, char **argv)
{
  Environment env(argc, argv);
  bool        quick = false, smoke = false;
  std::string csv_name;
  for (int i = 1; i < argc; ++i)
    {
      const std::string a = argv[i];
      if (a == "--quick")
        quick = true;
      else if (a == "--smoke")
        smoke = true;
      else if (a == "--csv" && i + 1 < argc)
        csv_name = argv[++i];
      else
        {
          std::cerr << "usage: benchmarks/run convergence [--quick|--smoke] "
                       "[--csv FILE]\n";
          return 2;
        }
    }
  const std::string source = PALPATE_SOURCE_DIR;
  std::cout << "Convergence of the indenter's force ("
            << (smoke ? "smoke" :
                quick ? "quick" :
                        "full")
            << " run)\nmachine: " << machine() << "\n\n";
  std::vector<Series> all;

  // --- Hertz.
  {
    Scene        scene = Scene::read(source + "/parameters/beam.prm");
    auto        &p     = scene.parameters;
    const double E = 1e4, nu = 0.3, R = 0.01, d = 1e-4, a = std::sqrt(R * d);
    p.material_model.model_name = "Neo-Hookean";
    p.material_model.set("Neo-Hookean", "Young's modulus", E);
    p.material_model.set("Neo-Hookean", "Poisson's ratio", nu);
    p.nonlinear_solver.assembly_threads = 1;
    const double hertz                  = hertz_force(E, nu, R, d);
    std::cout << "case hertz: neo-Hookean block E = 10 kPa, nu = 0.3, sphere "
                 "R = 1 cm pressed 0.1 mm (a = 1 mm); Hertz: "
              << std::setprecision(5) << hertz << " N\n";
    struct Discretisation
    {
      std::string               name;
      unsigned int              degree;
      std::vector<unsigned int> splits;
    };
    const std::vector<Discretisation> discretisations =
      smoke ? std::vector<Discretisation>{{"P1", 1, {1}}} :
      quick ? std::vector<Discretisation>{{"P1", 1, {1, 2}}} :
              std::vector<Discretisation>{{"P1", 1, {1, 2, 3}}, {"P2", 2, {1}}};
    for (const auto &disc : discretisations)
      {
        Series s{"hertz", disc.name, {}};
        p.discretization.polynomial_degree = disc.degree;
        for (const unsigned int split : disc.splits)
          {
            const HertzBlock block(p, R, a, 0.1, a / 2, split);
            s.levels.push_back(measure(*block.mesh,
                                       block.nodes,
                                       block.parameters,
                                       a / 2 / split,
                                       {{0, 0, -d}},
                                       {{0.1 * a, 0, 0}},
                                       true));
          }
        const auto [F0, order] = richardson(s.levels);
        s.extrapolated         = F0;
        s.order                = order;
        print_series(s, hertz);
        all.push_back(s);
      }
    std::cout << "\n";
    for (const auto &s : all)
      std::cout << "RESULT convergence case=hertz discretization="
                << s.discretization << " nodes=" << s.levels.back().nodes
                << " force_N=" << s.levels.back().force
                << " extrapolated_N=" << s.extrapolated << " hertz_N=" << hertz
                << " err_pct=" << 100 * (s.levels.back().force - hertz) / hertz
                << " order=" << s.order
                << " state_ms=" << s.levels.back().state_ms << "\n";
    std::cout << "\n";
  }

  // --- The liver.
  const unsigned int first_liver = all.size();
  {
    Scene base = Scene::read(source + "/parameters/liver-indenter.prm");
    base.parameters.mesh.surface_mesh_directory =
      std::string(PALPATE_BINARY_DIR) + "/convergence-meshes";
    base.parameters.nonlinear_solver.assembly_threads = 1;
    // The discretisation's error, not the solver's: the tolerance of the
    // solver's own tests (the scene ships the study's 1e-3).
    base.parameters.nonlinear_solver.residual_tolerance = 1e-8;
    struct Discretisation
    {
      std::string         name, model, element;
      std::vector<double> sizes; // Refinement size (m)
    };
    const std::vector<Discretisation> discretisations =
      smoke ?
        std::vector<Discretisation>{
          {"MR-P1P1", "Mooney-Rivlin", "P1-P1", {0.008}}} :
      quick ?
        std::vector<Discretisation>{
          {"MR-P1P1", "Mooney-Rivlin", "P1-P1", {0.006, 0.004, 0.003}}} :
        std::vector<Discretisation>{{"MR-P1P1",
                                     "Mooney-Rivlin",
                                     "P1-P1",
                                     {0.008, 0.006, 0.004, 0.003, 0.002}},
                                    {"MR-TaylorHood",
                                     "Mooney-Rivlin",
                                     "Taylor-Hood",
                                     {0.008, 0.006, 0.004}}};
    std::cout << "case liver: " << base.file()
              << " (Mooney-Rivlin, sphere R = 1 cm pressed 1 cm along -z)\n";
    for (const auto &disc : discretisations)
      {
        Series s{"liver", disc.name, {}};
        for (const double size : disc.sizes)
          {
            Scene scene                                = base;
            scene.parameters.mesh.surface_fine_size    = size;
            scene.parameters.material_model.model_name = disc.model;
            scene.parameters.material_model.set(disc.model,
                                                "Element",
                                                disc.element);
            const Mesh          mesh  = Mesh::create(scene);
            const NodeSelection nodes = NodeSelection::create(scene, mesh);
            const Point3 push = scene.parameters.boundary_conditions.active_node
                                  .prescribed_displacement;
            s.levels.push_back(measure(mesh,
                                       nodes,
                                       scene.parameters,
                                       size,
                                       push,
                                       {{-0.005, 0, 0}},
                                       false));
          }
        const auto [F0, order] = richardson(s.levels);
        s.extrapolated         = F0;
        s.order                = order;
        all.push_back(s);
      }
    // The reference: the extrapolation of the series with an observed
    // order, the finest one's otherwise.
    double reference = all.back().extrapolated;
    for (unsigned int i = first_liver; i < all.size(); ++i)
      if (all[i].order > 0)
        {
          reference = all[i].extrapolated;
          break;
        }
    for (unsigned int i = first_liver; i < all.size(); ++i)
      print_series(all[i], reference);
    std::cout << "  reference (extrapolated): " << reference << " N\n\n";

    // Recommended: the cheapest level within 3.5 % (half the force JND).
    const Series *best_series = nullptr;
    const Level  *best        = nullptr;
    for (unsigned int i = first_liver; i < all.size(); ++i)
      {
        const auto &s = all[i];
        std::cout << "RESULT convergence case=liver discretization="
                  << s.discretization << " nodes=" << s.levels.back().nodes
                  << " force_N=" << s.levels.back().force
                  << " extrapolated_N=" << reference << " err_pct="
                  << 100 * (s.levels.back().force - reference) / reference
                  << " order=" << s.order
                  << " state_ms=" << s.levels.back().state_ms << "\n";
        for (const auto &l : s.levels)
          if (l.converged &&
              std::abs(l.force - reference) <= 0.035 * reference &&
              (best == nullptr || l.state_ms < best->state_ms))
            best = &l, best_series = &s;
      }
    if (best != nullptr)
      std::cout << "RESULT convergence case=liver recommended=yes "
                   "discretization="
                << best_series->discretization
                << " refinement_mm=" << 1e3 * best->h
                << " nodes=" << best->nodes << " force_N=" << best->force
                << " extrapolated_N=" << reference
                << " err_pct=" << 100 * (best->force - reference) / reference
                << " state_ms=" << best->state_ms
                << " target_met=" << (best->state_ms <= 40 ? "yes" : "no")
                << "\n";
    else
      std::cout << "RESULT convergence case=liver recommended=none "
                   "err_pct=nan state_ms=nan\n";
  }

  if (!csv_name.empty())
    {
      std::ofstream csv(csv_name);
      csv << "case,discretization,h_mm,nodes,unknowns,force_N,"
             "extrapolated_N,state_ms\n";
      for (const auto &s : all)
        for (const auto &l : s.levels)
          csv << s.case_name << "," << s.discretization << "," << 1e3 * l.h
              << "," << l.nodes << "," << l.unknowns << "," << l.force << ","
              << s.extrapolated << "," << l.state_ms << "\n";
    }
  return 0;
}



int
main(int argc, char **argv)
{
  return report_errors("convergence", run_benchmark, argc, argv);
}
