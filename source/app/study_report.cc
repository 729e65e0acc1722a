// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

// What `palpate study` concludes from its rows: the discretisation error
// of the scene's own mesh and element, the recommendation (the fastest
// setting within the error bound), the tables and the lines to put in the
// scene, the CSV with the recommendation marked, and the Pareto plot drawn
// by the source tree's script in a process of its own.

#include <palpate/app/study_impl.h>

#include <fcntl.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <csignal>
#include <filesystem>
#include <iomanip>
#include <sstream>
#include <thread>

namespace palpate
{
  namespace internal
  {
    namespace
    {
      /**
       * python3 SCRIPT CSV PNG, without a shell (a quote in a file name is
       * only a name), with its input and output /dev/null, for at most
       * 120 s and until @p stop is asked for: a plot that hangs (a stalled
       * back end, a file on a dead mount) must not keep the study from
       * ending. Its exit status: 0 drawn, 124 cut at 120 s, 127 not
       * started, -1 stopped.
       */
      int
      run_plot_script(const std::string &script,
                      const std::string &csv,
                      const std::string &png,
                      const StopRequest &stop)
      {
        std::vector<std::string> words = {
          "timeout", "-k", "5", "120", "/usr/bin/python3", script, csv, png};
        std::vector<char *> argv;
        for (auto &w : words)
          argv.push_back(w.data());
        argv.push_back(nullptr);
        posix_spawn_file_actions_t actions;
        posix_spawn_file_actions_init(&actions);
        posix_spawn_file_actions_addopen(&actions, 0, "/dev/null", O_RDONLY, 0);
        posix_spawn_file_actions_addopen(&actions, 1, "/dev/null", O_WRONLY, 0);
        posix_spawn_file_actions_addopen(&actions, 2, "/dev/null", O_WRONLY, 0);
        // In a process group of its own, so that a plot that ignores
        // SIGTERM can be ended with everything it started.
        posix_spawnattr_t attributes;
        posix_spawnattr_init(&attributes);
        posix_spawnattr_setflags(&attributes, POSIX_SPAWN_SETPGROUP);
        posix_spawnattr_setpgroup(&attributes, 0);
        pid_t     child   = 0;
        const int spawned = posix_spawnp(
          &child, "timeout", &actions, &attributes, argv.data(), environ);
        posix_spawn_file_actions_destroy(&actions);
        posix_spawnattr_destroy(&attributes);
        if (spawned != 0)
          return 127;
        // A stop signal meanwhile ends the plot (timeout passes SIGTERM on
        // to python) instead of waiting out its time limit.
        int status = 0;
        for (;;)
          {
            const pid_t done = waitpid(child, &status, WNOHANG);
            if (done == child)
              break;
            if (done < 0 && errno != EINTR)
              return 127;
            if (stop.signal_number() != 0)
              {
                // SIGTERM, and after 2 s SIGKILL to the whole group: a plot
                // that ignores SIGTERM would otherwise hang the study for
                // good.
                ::kill(-child, SIGTERM);
                for (unsigned int k = 0;
                     k < 100 && waitpid(child, &status, WNOHANG) == 0;
                     ++k)
                  std::this_thread::sleep_for(std::chrono::milliseconds(20));
                ::kill(-child, SIGKILL);
                while (waitpid(child, &status, 0) < 0 && errno == EINTR)
                  {}
                return -1;
              }
            std::this_thread::sleep_for(std::chrono::milliseconds(20));
          }
        return WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
      }
    } // namespace



    std::string
    fixed(const double x, const int digits)
    {
      std::ostringstream s;
      s << std::fixed << std::setprecision(digits) << x;
      return s.str();
    }

    std::string
    mm(const double metres)
    {
      std::ostringstream s;
      s << metres * 1000 << " mm";
      return s.str();
    }

    bool
    passes(const StudyRow &row, const double threshold)
    {
      return row.interpolation != "direct" && row.samples > 0 &&
             row.covered >= 0.95 * row.samples && row.err_p95_pct <= threshold;
    }



    void
    Study::bound_discretisation_error()
    {
      // --- The discretisation error of the scene's own mesh and element,
      // for the scene's own probe: the largest p95 difference to the finer
      // variant of either knob. The grid knobs measure interpolation and
      // tolerance against direct solves on the *same* discretisation; the
      // force the device renders is off by both. A point probe has none:
      // its force does not converge as the mesh is refined.
      point_probe = !(p0.boundary_conditions.active_node.tip_radius > 0);
      if (!point_probe)
        for (const std::string knob : {"mesh", "element"})
          {
            // The knob's rows for this probe: the scene's first, the finest
            // (the reference) last.
            std::vector<const StudyRow *> rows;
            for (const auto &row : result.rows)
              if (row.knob == knob && row.probe == "tip " + mm(tip))
                rows.push_back(&row);
            if (rows.size() >= 2 && rows.front()->covered > 0 &&
                rows.front()->err_p95_pct > result.discretization_pct)
              {
                result.discretization_pct = rows.front()->err_p95_pct;
                result.discretization_against =
                  knob + " " + rows.front()->value + " against " +
                  rows.back()->value;
              }
          }
    }

    void
    Study::recommend()
    {
      // --- The recommendation: the fastest grid-knob setting whose p95
      // force error, plus the discretisation error where it is known, is
      // below the threshold and that covers 95 % of the positions.
      budget = result.threshold_pct - std::max(0.0, result.discretization_pct);
      for (unsigned int r = 0; r < result.rows.size(); ++r)
        {
          const auto &row = result.rows[r];
          if (!passes(row, budget))
            continue;
          if (result.recommended < 0 ||
              row.speed_mm_s > result.rows[result.recommended].speed_mm_s)
            result.recommended = r;
        }
    }

    void
    Study::print_tables() const
    {
      // --- Tables.
      const auto print_grid_table = [&](const std::string &knob,
                                        const std::string &title) {
        bool any = false;
        for (const auto &row : result.rows)
          any = any || row.knob == knob;
        if (!any)
          return;
        out << "\n" << title << "\n";
        out << "| " << std::left << std::setw(10) << knob
            << " | interpolation | covered | force error mean / p95 / max (%) "
               "| max (N) | shape (mm) | state (ms) | states/cm | region: "
               "states, precompute (s), MiB | speed (mm/s) |\n";
        out << "|---|---|---|---|---|---|---|---|---|---|\n";
        for (unsigned int r = 0; r < result.rows.size(); ++r)
          {
            const auto &row = result.rows[r];
            if (row.knob != knob)
              continue;
            out << "| " << std::setw(10) << row.value << " | " << std::setw(13)
                << row.interpolation << " | " << row.covered << "/"
                << row.samples << " | " << fixed(row.err_mean_pct, 2) << " / "
                << fixed(row.err_p95_pct, 2) << " / "
                << fixed(row.err_max_pct, 2) << " | " << fixed(row.err_max_N, 4)
                << " | "
                << (row.shape_err_mm >= 0 ? fixed(row.shape_err_mm, 3) : "-")
                << " | " << fixed(row.state_ms, 1) << " | "
                << fixed(row.states_per_cm, 1) << " | " << row.region_states
                << ", " << fixed(row.precompute_s, 1) << ", "
                << fixed(row.memory_MiB, 1) << " | " << fixed(row.speed_mm_s, 0)
                << (int(r) == result.recommended ? " (recommended)" : "")
                << " |\n";
          }
      };
      print_grid_table("grid",
                       "Grid spacing and interpolation (the scene's "
                       "tolerance and staging):");
      print_grid_table("tolerance",
                       "Newton residual tolerance (grid spacing " + mm(h0) +
                         "):");
      print_grid_table("increment",
                       "Staging: longest increment (grid spacing " + mm(h0) +
                         "):");
      print_grid_table("combined",
                       "Together: the fastest grid setting that passes, with "
                       "the loosest tolerance that passes:");
      for (const std::string knob : {"mesh", "element"})
        {
          bool any = false;
          for (const auto &row : result.rows)
            any = any || row.knob == knob;
          if (!any)
            continue;
          out
            << "\n"
            << (knob == "mesh" ? "Mesh resolution" : "Element order")
            << ": direct solves at "
            << std::min<unsigned>(n_disc, positions.size())
            << " positions, against the finest (the last row of each probe):\n";
          out << "| " << knob
              << " | probe | converged | force difference mean / p95 / max (%) "
                 "| max (N) | state (ms) |\n|---|---|---|---|---|---|\n";
          for (const auto &row : result.rows)
            if (row.knob == knob)
              out << "| " << row.value << " | " << row.probe << " | "
                  << row.samples - row.failures << "/" << row.samples << " | "
                  << fixed(row.err_mean_pct, 2) << " / "
                  << fixed(row.err_p95_pct, 2) << " / "
                  << fixed(row.err_max_pct, 2) << " | "
                  << fixed(row.err_max_N, 4) << " | " << fixed(row.state_ms, 1)
                  << " |\n";
          if (knob == "mesh")
            out << "A point probe has no mesh-converged force (a point load in "
                   "3-D has infinite compliance): compare the point rows with "
                   "the tip rows.\n";
        }
    }

    void
    Study::print_discretisation_error_and_recommendation() const
    {
      out << "\nDiscretisation error (the scene's mesh and element, its "
             "probe, p95):\n  ";
      if (point_probe)
        out << "not bounded: a point probe's force does not converge as the "
               "mesh is refined (Boundary conditions / Active node / Tip = "
               "sphere gives one that does).\n";
      else if (result.discretization_pct >= 0)
        out << fixed(result.discretization_pct, 2) << " % ("
            << result.discretization_against
            << (budget > 0 ?
                  "); the recommendation keeps interpolation and tolerance "
                  "within " +
                    fixed(budget, 2) + " % so that the total stays within " +
                    fixed(result.threshold_pct, 1) + " %.\n" :
                  "), which alone exceeds " + fixed(result.threshold_pct, 1) +
                    " %.\n");
      else
        out << "not measured (no finer mesh or element to compare with).\n";

      out << "\nRecommendation (fastest setting with p95 force error <= "
          << result.threshold_pct
          << " %, half the human force discrimination threshold"
          << (result.discretization_pct >= 0 ? ", discretisation included" :
                                               std::string())
          << "):\n";
      if (result.recommended >= 0)
        {
          const auto &row = result.rows[result.recommended];
          out << "  " << row.knob << " " << row.value << ", "
              << row.interpolation << ", h = " << row.h_mm
              << " mm: p95 force error " << fixed(row.err_p95_pct, 2) << " %"
              << (result.discretization_pct >= 0 ?
                    " (total with the discretisation: " +
                      fixed(row.err_p95_pct + result.discretization_pct, 2) +
                      " %)" :
                    std::string())
              << ", " << fixed(row.state_ms, 1) << " ms per state, about "
              << fixed(row.speed_mm_s, 0) << " mm/s straight-line speed with "
              << workers << " worker(s).\n"
              << "  In the scene: State space / Grid spacing = "
              << row.h_mm / 1000 << ", Interpolation = "
              << (row.interpolation == "Hermite" ? "tricubic Hermite" :
                                                   row.interpolation);
          if (row.residual_tolerance != p0.nonlinear_solver.residual_tolerance)
            out << "; Nonlinear solver / Residual tolerance = "
                << row.residual_tolerance;
          if (row.max_increment != p0.nonlinear_solver.max_increment_length)
            out << "; Nonlinear solver / Maximum increment length = "
                << row.max_increment;
          out << ".\n";
        }
      else
        {
          // The most accurate interpolation measured is what a finer grid
          // should use; the discretisation's share may be what leaves no
          // room for any.
          const StudyRow *best = nullptr;
          for (const auto &row : result.rows)
            if (row.knob == "grid" && row.samples > 0 &&
                row.covered >= 0.95 * row.samples &&
                (best == nullptr || row.err_p95_pct < best->err_p95_pct))
              best = &row;
          out << "  none of the settings keeps the p95 error below "
              << result.threshold_pct << " % on 95 % of the positions";
          if (result.discretization_pct >= result.threshold_pct)
            out << ": the discretisation alone is off by "
                << fixed(result.discretization_pct, 2)
                << " %; use a finer mesh or element.\n";
          else if (result.discretization_pct >= 0 && best != nullptr)
            out << " with the discretisation's " +
                     fixed(result.discretization_pct, 2) + " %: the best, "
                << best->interpolation << " at " << best->h_mm
                << " mm, is off by " << fixed(best->err_p95_pct, 2)
                << " % itself; use a finer mesh near the probe (Mesh / "
                   "Surface / Refinement size) or a finer grid with "
                << best->interpolation << ".\n";
          else
            out << ": use a finer grid"
                << (best != nullptr ? " with " + best->interpolation :
                                      std::string())
                << ".\n";
        }
    }

    void
    Study::write_csv_and_plot()
    {
      // --- CSV, with the recommendation marked.
      write_csv();
      out << "\nThe table as CSV: " << result.csv_file << "\n";

      // --- The Pareto plot, by the plotting script of the source tree
      // (matplotlib), next to the CSV.
      if (!options.plot)
        return;
      const std::filesystem::path script =
        std::filesystem::path(PALPATE_SOURCE_DIR) / "doc" / "images" /
        "accuracy_pareto.py";
      std::filesystem::path png(result.csv_file);
      png.replace_extension(".png");
      // Quoted for a shell, as the user will paste it: unquoted, a name
      // with an apostrophe breaks the command, and a scene's Output /
      // Directory of ';touch PWNED;' runs one when pasted.
      const auto quoted = [](const std::string &word) {
        std::string q = "'";
        for (const char c : word)
          q += c == '\'' ? std::string("'\\''") : std::string(1, c);
        return q + "'";
      };
      // The python3 the study runs (PATH's may lack matplotlib: pyenv).
      const std::string by_hand =
        "/usr/bin/python3 " + quoted(script.string()) + " " +
        quoted(result.csv_file) + " " + quoted(png.string());
      // After a stop signal the user wants the run to end: no plot.
      if (result.stop_signal != 0 || stop->signal_number() != 0)
        out << "No Pareto plot: the study was stopped; to draw it, run "
            << by_hand << "\n";
      else
        {
          const int status =
            std::filesystem::exists(script) ?
              run_plot_script(script.string(), result.csv_file, png, *stop) :
              127;
          if (status == 0)
            {
              result.plot_file = png.string();
              out << "The Pareto plot (force error against speed): "
                  << result.plot_file << "\n";
            }
          else if (stop->signal_number() != 0)
            {
              // Stopped while drawing: the study ends as stopped.
              result.stopped     = "stopped by " + stop->description();
              result.stop_signal = stop->signal_number();
              out << "No Pareto plot: the study was stopped while drawing "
                     "it; to draw it, run "
                  << by_hand << "\n";
            }
          else
            out << "No Pareto plot: "
                << (status == 124 || status == 137 ?
                      // 137: it ignored timeout's SIGTERM and was killed
                      // 5 s later.
                      std::string("the plotting script took more than "
                                  "120 s") :
                      status == 127 ?
                      std::string("python3, timeout (coreutils) or the "
                                  "plotting script was not found") :
                      "the plotting script failed (exit status " +
                          std::to_string(status) + ")")
                << "; it needs python3 with matplotlib (Debian: apt install "
                   "python3-matplotlib) and room for the PNG beside the "
                   "CSV. To see why, run "
                << by_hand << "\n";
        }
    }
  } // namespace internal
} // namespace palpate
