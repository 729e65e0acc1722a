// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

#ifndef palpate_app_study_h
#define palpate_app_study_h

#include <iosfwd>
#include <string>
#include <vector>

namespace palpate
{
  class Scene;

  /** What `palpate study` is asked to do. */
  struct StudyOptions
  {
    /** A reduced study: fewer knob values and HIP positions (minutes). */
    bool quick = false;
    /** HIP positions along the random trajectories (0: 240, 80 quick). */
    unsigned int samples = 0;
    /**
     * A finer mesh of the same organ for the mesh knob, in the scene's
     * file unit (its Scale factor applies). Empty: liver2k next to a
     * liver501 file, a refined blob or beam for generated meshes, else
     * the mesh knob is skipped.
     */
    std::string finer_mesh;
    /** The CSV to write (not given: study-SCENE.csv in Output /
     * Directory). */
    std::string csv_file;
    /** --csv was given (an empty name is refused, not the default). */
    bool csv_given = false;
    /** Draw the Pareto plot (PNG next to the CSV) with the source tree's
     * doc/images/accuracy_pareto.py, if python3 and matplotlib are there. */
    bool plot = true;
    /** Show a progress bar on stderr (a line per step if not a terminal). */
    bool progress = true;
    /**
     * A time budget (s; 0: none). Past it the study ends at the next state
     * or solve and reports the knobs measured until then, as after Ctrl-C.
     */
    double time_limit = 0;
    /** Knobs not to measure: grid, tolerance, increment, combined, mesh,
     * element (e.g. the element knob's P2 solves on a big organ). */
    std::vector<std::string> skip;
  };

  /** One setting of one knob, both sides measured. */
  struct StudyRow
  {
    /** grid, tolerance, increment, mesh, element. */
    std::string knob;
    /** The knob's value, e.g. "10 mm", "1e-06", "liver2k". */
    std::string value;
    /** trilinear, Hermite, or "direct" (discretisation knobs). */
    std::string interpolation;
    /** point, or "tip 25 mm" (discretisation knobs). */
    std::string probe = "point";
    double      h_mm  = 0;
    /** The setting's Newton residual tolerance and longest increment (m). */
    double residual_tolerance = 0, max_increment = 0;

    /** HIP positions compared, and how many had a complete cell. */
    unsigned int samples = 0, covered = 0;
    /** Force error against the reference: |f - f_ref| (N), and relative
     * to max(|f_ref|, 0.1 N) (%). */
    double err_mean_N = 0, err_p95_N = 0, err_max_N = 0;
    double err_mean_pct = 0, err_p95_pct = 0, err_max_pct = 0;
    /** Largest nodal displacement error of the interpolated shape (mm);
     * negative if not measured. */
    double shape_err_mm = -1;

    /** Median time per state (ms, one core), states computed, failure
     * points among them. */
    double       state_ms = 0;
    unsigned int states = 0, failures = 0;
    /** Distinct grid states the interpolation needs per cm of a straight
     * path (random directions). */
    double states_per_cm = 0;
    /** Precomputation of the visited region: its states (the cells of the
     * trajectories), time on the engine's workers (s) and memory (MiB). */
    unsigned int region_states = 0;
    double       precompute_s = 0, memory_MiB = 0;
    /** The straight-line HIP speed the engine can keep up with (mm/s). */
    double speed_mm_s = 0;
  };

  /** What the study found. */
  struct StudyResult
  {
    /** stvk, nh or mooney-rivlin (for RESULT lines). */
    std::string           material;
    std::vector<StudyRow> rows;
    /** The recommended row (index into rows), -1 if none qualifies. */
    int recommended = -1;
    /** The error bound of the recommendation: p95 (%). */
    double threshold_pct = 3.5;
    /**
     * The discretisation error of the scene's mesh and element for its
     * probe (p95 %, the larger of the mesh and element knobs' difference
     * to their finer variant), and what it was measured against; -1 when
     * not known (a point probe has none: its force does not converge).
     * The recommendation keeps the total within threshold_pct.
     */
    double      discretization_pct = -1;
    std::string discretization_against;
    /** Where the CSV and the plot went (plot empty: none drawn). */
    std::string csv_file, plot_file;
    /** Wall time of the study (s). */
    double seconds = 0;
    /** Why the study ended before its last knob ("stopped by SIGINT
     * (Ctrl-C)", "its time budget ... ran out"); empty if it did not. */
    std::string stopped;
    /** The signal that stopped it (0 if none). */
    int stop_signal = 0;
  };

  /**
   * `palpate study SCENE.prm`: what accuracy costs in time, for this
   * scene. Varies one knob at a time from the scene's settings - grid
   * spacing with trilinear and tricubic Hermite interpolation, Newton
   * residual tolerance, staging increment length, mesh resolution, element
   * order - and measures both sides: the force the device would render
   * (interpolated from grid states computed as the engine computes them,
   * each from a neighbour) against direct FE solves at HIP positions along
   * smooth random trajectories, and the time per state, states per cm of
   * path, precomputation time and memory, and the implied straight-line
   * speed. Prints a table per knob and the recommendation: the fastest
   * setting whose p95 force error stays below 3.5 % (half the human force
   * discrimination threshold); writes a CSV for the Pareto plot.
   */
  StudyResult
  run_study(std::ostream &out, const Scene &scene, const StudyOptions &options);
} // namespace palpate

#endif
