// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

// The driver of `palpate study` (run_study()): Study::run() reads like the
// study - choose where to look and what to vary, announce the work, solve
// the references, sweep the knobs, conclude - and the progress bar through
// which a stop signal or the time budget cuts it short, with what the
// study says when it ends early or has measured nothing. The steps are in
// the other study_*.cc files (study_impl.h lists them).

#include <palpate/app/study_impl.h>
#include <palpate/state_space/state_grid.h>

#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <iomanip>
#include <iostream>
#include <thread>

namespace palpate
{
  namespace
  {
    std::string
    material_key(const Parameters::MaterialModel &m)
    {
      if (m.model_name == "St.Venant-Kirchhoff")
        return "stvk";
      if (m.model_name == "Neo-Hookean")
        return "nh";
      // Any other plug-in: its name, lower case, spaces as dashes.
      std::string key = m.model_name;
      for (char &c : key)
        c = c == ' ' ? '-' : static_cast<char>(std::tolower(c));
      return key;
    }
  } // namespace



  namespace internal
  {
    Progress::Progress(std::ostream      &out,
                       const bool         enabled,
                       const double       total,
                       const StopRequest &stop,
                       const double       time_limit)
      : out(out)
      , enabled(enabled)
      , terminal(isatty(2))
      , total(total)
      , start(Clock::now())
      , stop(stop)
      , time_limit(time_limit)
    {}

    void
    Progress::step(const double amount, const std::string &what)
    {
      done += amount;
      if (stop.requested())
        throw StudyCut{"stopped by " + stop.description()};
      if (time_limit > 0 && seconds_since(start) > time_limit)
        throw StudyCut{"its time budget (--time-limit " +
                       std::to_string(static_cast<long>(time_limit)) +
                       " s) ran out"};
      if (!out)
        throw StudyCut{"the standard output could not be written"};
      if (!enabled)
        return;
      const double      fraction = std::min(1.0, done / total);
      const double      elapsed  = seconds_since(start);
      const std::string eta =
        fraction > 0.02 ? ", about " +
                            std::to_string(static_cast<int>(
                              std::ceil(elapsed * (1 - fraction) / fraction))) +
                            " s left" :
                          "";
      if (terminal)
        {
          const int width = 30, full = static_cast<int>(fraction * width);
          std::cerr << "\r  [" << std::string(full, '#')
                    << std::string(width - full, '.') << "] " << std::setw(3)
                    << static_cast<int>(fraction * 100) << " %" << eta << "  "
                    << what << "\033[K" << std::flush;
        }
      else if (what != last || fraction >= next_line)
        {
          // Not a terminal (a log): a line per step of the study, and
          // every 10 %.
          out << "  ... " << static_cast<int>(fraction * 100) << " %" << eta
              << ": " << what << "\n"
              << std::flush;
          last      = what;
          next_line = std::floor(fraction * 10 + 1) / 10;
        }
    }

    void
    Progress::finish()
    {
      if (enabled && terminal)
        std::cerr << "\r\033[K" << std::flush;
    }



    Study::Study(std::ostream       &out,
                 const Scene        &scene,
                 const StudyOptions &options)
      : out(out)
      , scene(scene)
      , options(options)
      , p0(scene.parameters)
      , quick(options.quick)
      , workers(
          std::max(1u,
                   std::min(p0.engine.workers,
                            std::max(1u, std::thread::hardware_concurrency()))))
    {
      result.material = material_key(p0.material_model);
    }

    StudyResult
    Study::run()
    {
      choose_positions();
      choose_knob_values();
      choose_finer_mesh();
      choose_probe();
      announce_and_estimate_work();
      check_csv_file();
      // Its header now: a file that cannot be written fails before the
      // work.
      write_csv();
      try
        {
          solve_references();
          measure_grid_knobs();
          measure_discretisation_knobs();
        }
      catch (const StudyCut &cut)
        {
          result.stopped     = cut.why;
          result.stop_signal = stop->signal_number();
        }
      progress->finish();
      say_if_cut_short();
      if (result.rows.empty())
        return nothing_measured();
      bound_discretisation_error();
      recommend();
      print_tables();
      print_discretisation_error_and_recommendation();
      write_csv_and_plot();
      result.seconds = seconds_since(study_start);
      out << "Study time " << fixed(result.seconds, 0) << " s; "
          << reference_line();
      return result;
    }

    void
    Study::announce_and_estimate_work()
    {
      // --- Work, for the progress bar: states to compute (estimated from
      // the cells and their neighbours) and direct solves, weighted by
      // their relative cost.
      base.emplace(scene);
      out << "Study: what accuracy costs in time, for '" << scene.file()
          << "'\n"
          << "  " << positions.size() << " HIP positions on " << n_paths
          << " smooth random trajectories within " << mm(radius)
          << " of rest; one knob at a time from the scene's settings; "
          << workers << " worker(s)"
          << (quick ? "; --quick: fewer knob values and positions" : "")
          << "\n";
      total = positions.size();
      for (const double h : spacings)
        total +=
          with_neighbours(StateGrid(h, p0.state_space.extent),
                          cell_corners(StateGrid(h, p0.state_space.extent),
                                       positions))
            .size();
      const double h0_states =
        with_neighbours(StateGrid(h0, p0.state_space.extent),
                        cell_corners(StateGrid(h0, p0.state_space.extent),
                                     positions))
          .size();
      total += (tolerances.size() + increments.size()) * h0_states;
      if (finer)
        total += 2 * n_disc * (1 + finer_cost);
      if (p2_knob)
        total += 2 * n_disc * p2_cost;
      // A stop signal or the time budget cuts the study short at the next
      // state or solve; what was measured until then is reported and written
      // (the CSV also after every knob setting, so that even a killed study
      // leaves its finished rows).
      stop.emplace();
      progress.emplace(out, options.progress, total, *stop, options.time_limit);
    }

    void
    Study::say_if_cut_short()
    {
      if (!result.stopped.empty())
        out << "\nThe study ended early: " << result.stopped << " after "
            << fixed(seconds_since(study_start), 0) << " s."
            << (result.rows.empty() ?
                  std::string() :
                  " What it measured until then follows (" +
                    std::to_string(result.rows.size()) +
                    " rows); the knobs and values not reached are not in it, "
                    "and the recommendation is among the rows measured.")
            << "\n";
    }

    std::string
    Study::reference_line() const
    {
      return reference.empty() ? "the " + std::to_string(positions.size()) +
                                   " reference solves did not finish.\n" :
                                 std::to_string(n_reference) + " of " +
                                   std::to_string(positions.size()) +
                                   " reference solves converged.\n";
    }

    StudyResult
    Study::nothing_measured()
    {
      out << "\nNothing was measured, so there is no table and no "
             "recommendation"
          << (!result.stopped.empty() && reference.empty() ?
                ": the study ended during its first step, the reference "
                "solves (direct solves at " +
                  std::to_string(positions.size()) +
                  " positions). Give it more time (--time-limit S, or "
                  "none)" :
                ". Give it more time (--time-limit S, or none), or leave "
                "fewer knobs out (--skip)")
          << ".\n";
      write_csv();
      out << "The CSV (its header only): " << result.csv_file << "\n";
      result.seconds = seconds_since(study_start);
      out << "Study time " << fixed(result.seconds, 0) << " s; "
          << reference_line();
      return result;
    }
  } // namespace internal



  StudyResult
  run_study(std::ostream &out, const Scene &scene, const StudyOptions &options)
  {
    internal::Study study(out, scene, options);
    return study.run();
  }
} // namespace palpate
