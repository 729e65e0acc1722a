// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

#include <palpate/app/application.h>
#include <palpate/app/interaction_run.h>
#include <palpate/app/static_solve.h>
#include <palpate/base/exceptions.h>
#include <palpate/base/stop_request.h>
#include <palpate/haptics/shape_interpolator.h>
#include <palpate/hyperelastic/hyperelastic_system.h>
#include <palpate/hyperelastic/state_solver.h>
#include <palpate/mesh/mesh.h>
#include <palpate/mesh/node_selection.h>
#include <palpate/scene/scene.h>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <memory>
#include <ostream>

namespace palpate
{
  namespace
  {
    /** What the solve does: its discretisation, equations, solvers and
     * path (and what a 'by size' entry chose for this system, and why). */
    void
    describe(std::ostream            &out,
             const Scene             &scene,
             StateSolver             &solver,
             const Utilities::Point3 &target)
    {
      const auto &p      = scene.parameters;
      const auto &system = solver.system();
      out << "Static solve\n"
          << "  discretisation: " << system.discretization_description() << ", "
          << system.n_dofs() << " DoFs\n"
          << "  equations:      " << system.n_equations() << " (";
      const auto &components = system.dof_components();
      const auto  n_pressure =
        std::count(components.begin(), components.end(), 3u);
      if (n_pressure > 0)
        out << system.n_equations() - system.n_multipliers() - n_pressure
            << " displacements, " << n_pressure << " pressures, ";
      else
        out << system.n_equations() - system.n_multipliers()
            << " displacements, ";
      // What a 'by size' entry chose for this system, and why.
      const unsigned int n        = system.n_equations();
      const auto         why_size = [n](const bool         by_size,
                                const std::string &entry,
                                const unsigned int threshold) {
        if (!by_size)
          return std::string();
        return " (" + entry +
               " = by size: " + (n >= threshold ? "at least " : "fewer than ") +
               Utilities::to_string(threshold) + " equations)";
      };
      const auto &linear = scene.parameters.linear_solver;
      out << system.n_multipliers() << " multipliers)\n"
          << "  linear solver:  " << solver.linear_solver_name()
          << why_size(linear.solver == "by size",
                      "Solver",
                      Parameters::LinearSolver::single_from)
          << why_size(linear.ordering == "by size",
                      "Ordering",
                      Parameters::LinearSolver::metis_from)
          << "\n"
          << "  Newton steps:   "
          << (solver.settings().reuse_factorization ?
                "GMRES preconditioned by a kept factorisation" :
                "a factorisation each")
          << why_size(scene.parameters.nonlinear_solver.reuse_by_size,
                      "Reuse factorization",
                      Parameters::NonlinearSolver::reuse_from)
          << "\n"
          << "  active node:    from rest to ("
          << Utilities::to_string(target, 4) << ") m\n"
          << (p.output.summary_formats.empty() ?
                std::string() :
                "  note:           Output / Summary formats: a static solve "
                "has no run summary to write; its results are printed here "
                "and written by Effects / Force log, Shape output and VTU "
                "export.\n")
          << std::flush;
    }



    /** The Newton history: the residual and constraint after each
     * iteration, the step length and the correction. */
    void
    print_newton_history(std::ostream &out, const State &state)
    {
      out
        << "  Newton history (force residual relative to the force scale, after\n"
        << "  each iteration; constraint violation of the active node):\n"
        << "    incr  iter   residual  constraint [m]   step  correction [m]\n";
      unsigned int iteration = 0, last_increment = 0;
      for (const auto &h : state.history)
        {
          if (h.increment != last_increment)
            iteration = 0, last_increment = h.increment;
          out << "    " << std::setw(4) << h.increment << "  " << std::setw(4)
              << ++iteration << "  " << std::scientific << std::setprecision(2)
              << std::setw(9) << h.residual_after << "  " << std::setw(9)
              << h.constraint_after << "       " << std::defaultfloat
              << std::setprecision(3) << std::setw(5) << h.step_length << "  "
              << std::scientific << std::setprecision(2) << h.correction
              << std::defaultfloat << "\n";
        }
    }



    /** The force (converged), how far a stop got, or the failure point
     * with a hint where the cause is known. */
    void
    print_outcome(std::ostream            &out,
                  const Scene             &scene,
                  const NodeSelection     &nodes,
                  const State             &state,
                  const StopRequest       &stop,
                  const double             reached,
                  const Utilities::Point3 &reached_at,
                  const Utilities::Point3 &reached_force)
    {
      const bool stopped = state.status == SolveStatus::stopped;
      if (state.converged)
        out
          << "  converged:      " << state.increments << " increments, "
          << state.newton_iterations << " Newton iterations (at most "
          << state.max_increment_iterations << " per increment)\n"
          << "  force on probe: (" << Utilities::to_string(state.force, 5)
          << ") N, |f| = "
          << Utilities::to_string(Utilities::norm(state.force), 5) << " N\n"
          << (Utilities::norm(state.force) >
                  3 * scene.parameters.haptics.force_limit ?
                "  warning:        this is " +
                  Utilities::to_string(Utilities::norm(state.force) /
                                         scene.parameters.haptics.force_limit,
                                       3) +
                  " times the device's force limit (Haptics / Force limit = " +
                  Utilities::to_string(scene.parameters.haptics.force_limit,
                                       4) +
                  " N): the device would clip it. Is the modulus in Pa, the "
                  "push in metres, the mesh's Scale factor right?\n" :
                std::string())
          << (Utilities::norm(state.force) == 0 && nodes.sphere_tip ?
                "  note:           the sphere does not touch the surface "
                "there (0 N): the push moves it away from the organ or "
                "along it. A push into the organ points against the "
                "surface's outward normal (the report's probe tip line).\n" :
                std::string());
      else if (stopped)
        out << "  STOPPED:        by " << stop.description() << " after "
            << state.newton_iterations
            << " Newton iterations, before the state converged (not a failure "
               "point)\n"
            << "  reached:        "
            << (reached > 0 ?
                  Utilities::to_string(100 * reached, 3) +
                    " % of the path, the active node at (" +
                    Utilities::to_string(reached_at, 4) + ") m, force there (" +
                    Utilities::to_string(reached_force, 5) + ") N" :
                  std::string("no increment converged"))
            << "\n";
      else
        out
          << "  FAILURE POINT:  " << to_string(state.status) << ": "
          << state.message << "\n  (no force is reported for a failure point)\n"
          << (state.status == SolveStatus::inverted_element &&
                  (scene.parameters.effects.on("Gravity") ||
                   scene.parameters.effects.on("Surface traction")) ?
                "  hint:           the scene's loads are on (Effects / "
                "Gravity, Surface traction): a load too large for the "
                "material inverts elements however the probe moves. Check "
                "Gravitational acceleration (m/s^2) and Traction (Pa) against "
                "the material's modulus, or solve without them.\n" :
              state.status == SolveStatus::inverted_element &&
                  scene.parameters.material_model.model_name ==
                    "St.Venant-Kirchhoff" ?
                "  hint:           St.Venant-Kirchhoff collapses under deep "
                "compression (its energy stays finite as an element "
                "flattens); Neo-Hookean or Mooney-Rivlin reach much further "
                "(doc/benchmarks/failure-points.md)\n" :
                "");
    }



    /** Effects / Force log of a static solve: one row, the force at the
     * last equilibrium reached on the path. */
    void
    write_force_row(const std::string       &file,
                    const Utilities::Point3 &target,
                    const State             &state,
                    const double             reached,
                    const Utilities::Point3 &reached_at,
                    const Utilities::Point3 &reached_force)
    {
      // The force at the last equilibrium reached on the path: the
      // target itself if the solve converged; where a stop signal or a
      // failure point ended it otherwise (reached_fraction < 1), so that
      // a stopped solve's row holds the force it printed, not zero.
      const Utilities::Point3 at = state.converged ? target : reached_at;
      const Utilities::Point3 force =
        state.converged ? state.force :
        reached > 0     ? reached_force :
                          Utilities::Point3{{0, 0, 0}};
      std::ofstream csv(file);
      csv << "target_x_m,target_y_m,target_z_m,force_x_N,force_y_N,force_z_N,"
             "converged,newton_iterations,reached_fraction,reached_x_m,"
             "reached_y_m,reached_z_m\n"
          << std::setprecision(10) << target[0] << "," << target[1] << ","
          << target[2] << "," << force[0] << "," << force[1] << "," << force[2]
          << "," << (state.converged ? 1 : 0) << "," << state.newton_iterations
          << "," << (state.converged ? 1.0 : reached) << "," << at[0] << ","
          << at[1] << "," << at[2] << "\n";
      csv.close();
      if (!csv)
        throw OutputError("cannot write the file '" + file + "'");
    }
  } // namespace



  namespace
  {
    /**
     * What the solve of @p state cost: the factorisation's figures, and
     * (Output / Print timings) where the time went, summed over the
     * iterations.
     */
    void
    print_costs(std::ostream                    &out,
                const Parameters::AllParameters &p,
                const StateSolver               &solver,
                const State                     &state)
    {
      if (!solver.linear_solver_statistics().empty())
        out << "  factorisation:  " << solver.linear_solver_statistics()
            << "\n";
      // Where the time went, summed over the iterations.
      double assembly = 0, solve = 0, line_search = 0;
      for (const auto &h : state.history)
        assembly += h.assembly_time, solve += h.solve_time,
          line_search += h.line_search_time;
      if (p.output.print_timings)
        out << std::setprecision(3) << "  time:           set-up "
            << 1000 * solver.setup_time() << " ms; solve "
            << 1000 * state.wall_time << " ms = assembly " << 1000 * assembly
            << " + linear solves " << 1000 * solve << " + line search "
            << 1000 * line_search << " + other "
            << 1000 * (state.wall_time - assembly - solve - line_search)
            << " ms\n";
    }
  } // namespace



  int
  run_static_solve(std::ostream            &out,
                   const Scene             &scene,
                   const Mesh              &mesh,
                   const NodeSelection     &nodes,
                   const Utilities::Point3 &target)
  {
    const auto &p = scene.parameters;
    // A directory that cannot take the outputs is said before the solve,
    // naming the entry (a loop of links was "the file system refuses the
    // path" after it).
    if (p.effects.shape_output || p.effects.vtu_export || p.effects.force_log)
      check_output_directory(scene);
    StateSolver solver(mesh, nodes, p);
    const auto &system = solver.system();

    // The solve can take minutes: say what it does first.
    describe(out, scene, solver, target);

    // Shape output: the path from rest, a frame per converged increment.
    const std::string stem =
      scene.file().empty() ?
        "default" :
        std::filesystem::path(scene.file()).stem().string();
    // The index names each frame as soon as it is written (PvdIndex), so
    // that a killed solve leaves its frames indexed.
    unsigned int                 frames = 0;
    std::unique_ptr<ShapeFrames> writer;
    PvdIndex                     index;
    const std::string            index_file =
      p.output.directory + "/" + stem + "-shape.pvd";
    const State rest  = solver.rest_state();
    const auto  frame = [&](const State &s, const double t) {
      char name[64];
      std::snprintf(name, sizeof(name), "-shape-%05u.vtu", frames);
      const std::string file = stem + name;
      writer->write(s.solution, s.force, p.output.directory + "/" + file);
      if (const std::string why = index.append(t, file); !why.empty())
        throw OutputError(why);
      ++frames;
    };
    if (p.effects.shape_output)
      {
        std::filesystem::create_directories(p.output.directory);
        writer = std::make_unique<ShapeFrames>(mesh, nodes, system);
        if (const std::string why = index.open(index_file); !why.empty())
          throw OutputError(why);
        frame(rest, 0);
      }
    // The last equilibrium on the path, for a report if a stop signal
    // (Ctrl-C) ends the solve early: its increments can take minutes on a
    // real organ, and what they reached is worth printing.
    double            reached = 0;
    Utilities::Point3 reached_at{{0, 0, 0}}, reached_force{{0, 0, 0}};
    solver.set_increment_observer([&](const State &s, const double t) {
      reached       = t;
      reached_at    = s.active_displacement;
      reached_force = s.force;
      if (writer)
        frame(s, t);
    });
    const StopRequest stop;
    solver.set_stop_check([&stop] { return stop.requested(); });
    const State state = solver.solve(rest, target);
    solver.set_increment_observer(nullptr);
    solver.set_stop_check(nullptr);
    const bool stopped = state.status == SolveStatus::stopped;

    print_newton_history(out, state);
    print_outcome(
      out, scene, nodes, state, stop, reached, reached_at, reached_force);

    print_costs(out, p, solver, state);

    // Effects: only when the scene asks for them.
    if (p.effects.vtu_export || p.effects.force_log)
      std::filesystem::create_directories(p.output.directory);
    if (writer)
      out << "  wrote " << index_file << " (" << frames
          << " frames: rest, then the end of every increment; time = the "
             "fraction of the path)\n";
    if (p.effects.vtu_export)
      {
        const std::string file = p.output.directory + "/" + stem + "-state.vtu";
        system.write_vtu(state, file);
        out << "  wrote " << file << " (warp by 'displacement' in ParaView)\n";
      }
    if (p.effects.force_log)
      {
        const std::string file =
          p.output.directory + "/" + stem + "-forces.csv";
        write_force_row(
          file, target, state, reached, reached_at, reached_force);
        out << "  wrote " << file << "\n";
      }
    if (stopped)
      return 128 + stop.signal_number();
    return state.converged ? ExitStatus::success : ExitStatus::solve_failed;
  }
} // namespace palpate
