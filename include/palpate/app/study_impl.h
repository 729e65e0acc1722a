// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

#ifndef palpate_app_study_impl_h
#define palpate_app_study_impl_h

// Not an interface: `palpate study`'s implementation (run_study()), shared
// by its source files, one job each:
//   study.cc              the driver: Study::run(), its announcement, the
//                         progress bar and how a study cut short ends
//   study_sampling.cc     where it looks: the HIP positions on random
//                         trajectories, the grid cells around them
//   study_knobs.cc        what it varies: the knobs' values, the finer mesh,
//                         the probe, and the sweeps over them
//   study_measurement.cc  what it measures: direct solves, grid states as
//                         the engine computes them, force and shape errors
//   study_csv.cc          the table's file: refused before anything runs,
//                         written after every setting
//   study_report.cc       what it concludes: the discretisation error, the
//                         recommendation, the tables and the Pareto plot
// Users of the study include study.h, never this header.

#include <palpate/app/study.h>
#include <palpate/base/stop_request.h>
#include <palpate/base/utilities.h>
#include <palpate/hyperelastic/sphere_trial.h>
#include <palpate/mesh/mesh.h>
#include <palpate/mesh/node_selection.h>
#include <palpate/scene/parameters.h>
#include <palpate/scene/scene.h>

#include <chrono>
#include <optional>
#include <ostream>
#include <set>
#include <string>
#include <vector>

namespace palpate
{
  class StateGrid;

  namespace internal
  {
    using Point3 = Utilities::Point3;
    using Clock  = std::chrono::steady_clock;

    using Utilities::seconds_since;

    /** @p x with @p digits digits after the point. */
    std::string
    fixed(const double x, const int digits);

    /** A length given in m, in mm: "10 mm". */
    std::string
    mm(const double metres);

    /** Whether a grid-knob row qualifies for the recommendation: p95
     * force error within @p threshold (%) on 95 % of the positions. */
    bool
    passes(const StudyRow &row, const double threshold);

    /** The 8 corners of the cells of @p samples. */
    std::set<unsigned int>
    cell_corners(const StateGrid &grid, const std::vector<Point3> &x);

    /** @p points and their 26 neighbours (what Hermite reads). */
    std::set<unsigned int>
    with_neighbours(const StateGrid              &grid,
                    const std::set<unsigned int> &points);

    /**
     * Distinct grid points whose states the interpolation needs per cm of
     * a straight path: the corners of the cells crossed by 200 random
     * lines of 10 cm through the ball of 2 cm around rest.
     */
    double
    states_per_cm(const double h);

    /** Why the study ended before its last knob (Progress::step). */
    struct StudyCut
    {
      std::string why;
    };

    /** A progress bar on stderr (a terminal), else a line per step. */
    class Progress
    {
    public:
      /** @p total: the work of the whole study, in the units of step(). */
      Progress(std::ostream      &out,
               const bool         enabled,
               const double       total,
               const StopRequest &stop,
               const double       time_limit);

      /**
       * One piece of work done (a state, a direct solve). Where the study
       * may be cut short: throws StudyCut after a stop signal, past the
       * time budget, or when nobody can read the output any more.
       */
      void
      step(const double amount, const std::string &what);

      /** Clears the bar from the terminal. */
      void
      finish();

    private:
      std::ostream      &out;
      bool               enabled, terminal;
      double             total, done = 0, next_line = 0;
      std::string        last;
      Clock::time_point  start;
      const StopRequest &stop;
      double             time_limit;
    };

    /** A HIP position and the direct FE solution there. */
    struct Sample
    {
      Point3              x;
      bool                ok = false;
      Point3              force{{0, 0, 0}};
      std::vector<double> solution;
    };

    /** The body of one discretisation: mesh, nodes and their solver's
     * settings. */
    struct Body
    {
      Scene         scene;
      Mesh          mesh;
      NodeSelection nodes;

      explicit Body(const Scene &s)
        : scene(s)
        , mesh(Mesh::create(scene))
        , nodes(select_nodes(scene, mesh))
      {}
    };

    /**
     * The study's steps and what they share (step-44's layout): run() reads
     * like the algorithm. A stop signal or the time budget cuts it short
     * at the next state or solve (StudyCut); what was measured until then
     * is reported and written.
     */
    class Study
    {
    public:
      /** The study of @p scene as @p options ask, reported on @p out. */
      Study(std::ostream &out, const Scene &scene, const StudyOptions &options);

      /** The whole study (study.cc). */
      StudyResult
      run();

    private:
      /** The HIP positions: smooth random trajectories in a ball
       * (study_sampling.cc). */
      void
      choose_positions();

      /** The knobs' values, one knob at a time from the scene's
       * (study_knobs.cc). */
      void
      choose_knob_values();

      /** The finer mesh for the mesh knob: --finer-mesh, liver2k beside
       * liver501, or the generator's next refinement. */
      void
      choose_finer_mesh();

      /** The probe of the discretisation knobs, how many positions they
       * solve at, and whether the element knob runs. */
      void
      choose_probe();

      /** What the study does, and its work for the progress bar
       * (study.cc). */
      void
      announce_and_estimate_work();

      /** Whether --skip leaves @p knob out. */
      bool
      skipped(const std::string &knob) const;

      /** The CSV's name: a directory is refused before anything runs
       * (study_csv.cc). */
      void
      check_csv_file();

      /** check_csv_file()'s first step: a name that says no file (empty,
       * blank, like an option, standard output, a directory, a link to
       * nowhere, the plot's name) is refused. */
      void
      check_csv_name();

      /** check_csv_file()'s second step: the name's directory must exist
       * and be one. */
      void
      check_csv_directory();

      /** check_csv_file()'s last step: what is there now under the name
       * and the plot's (a device, a file of the user's, a directory) is
       * refused. */
      void
      check_csv_target();

      /** The rows so far (after every knob setting: even a killed study
       * leaves its finished rows). */
      void
      write_csv() const;

      /** Reference: direct solves at every position, tolerance 1e-10
       * (study_measurement.cc). */
      void
      solve_references();

      /** One setting of the grid knobs: compute its states, interpolate
       * with both schemes, compare. */
      void
      grid_setting(const std::string              &knob,
                   const std::string              &value,
                   const Parameters::AllParameters p);

      /** Grid spacing, tolerance, increment, and the best of them together
       * (study_knobs.cc). */
      void
      measure_grid_knobs();

      /** Discretisation knobs: direct solves at the first n_disc positions,
       * against the finest setting of the knob, with the point probe and
       * with a rigid tip (study_measurement.cc). */
      void
      discretisation(const std::string              &knob,
                     const std::vector<Scene>       &variants,
                     const std::vector<std::string> &names,
                     const std::vector<double>      &cost);

      /** Mesh resolution and element order (study_knobs.cc). */
      void
      measure_discretisation_knobs();

      /** Why the study ended early, if it did (study.cc). */
      void
      say_if_cut_short();

      /** How many reference solves converged, as the last line says. */
      std::string
      reference_line() const;

      /** Nothing measured (cut short during the reference solves, or every
       * knob skipped): no table, and no recommendation made of no rows. */
      StudyResult
      nothing_measured();

      /** The discretisation error of the scene's own mesh and element
       * (study_report.cc). */
      void
      bound_discretisation_error();

      /** The fastest grid-knob setting that passes, within what the
       * discretisation error leaves. */
      void
      recommend();

      /** A table per knob. */
      void
      print_tables() const;

      /** The discretisation error, and the recommendation with the lines
       * to put in the scene. */
      void
      print_discretisation_error_and_recommendation() const;

      /** The CSV with the recommendation marked, and the Pareto plot. */
      void
      write_csv_and_plot();

      /** Where the report goes. */
      std::ostream &out;
      /** The scene studied. */
      const Scene &scene;
      /** What the command line asked for. */
      const StudyOptions &options;
      /** The scene's parameters, from which each knob varies. */
      const Parameters::AllParameters &p0;
      /** --quick: fewer knob values and positions. */
      const bool quick;
      /** The engine's workers the speed estimates assume. */
      const unsigned int workers;
      /** When the study started. */
      const Clock::time_point study_start = Clock::now();
      /** What it found so far. */
      StudyResult result;
      /** The HIP positions and their paths. */
      unsigned int                     n_paths = 0;
      double                           radius  = 0;
      std::vector<std::vector<Point3>> paths;
      std::vector<Point3>              positions;
      /** The knobs' values. */
      double               h0 = 0;
      std::vector<double>  spacings, tolerances, increments;
      std::optional<Scene> finer;
      std::string          coarse_name = "scene mesh", finer_name;
      /** The probe of the discretisation knobs, how many positions they
       * solve at, and whether the element knob runs. */
      double       tip     = 0;
      unsigned int n_disc  = 0;
      bool         p2_knob = false;
      /** Relative cost of a direct solve on the finer mesh and with P2. */
      static constexpr double finer_cost = 12, p2_cost = 20;
      /** The work of the whole study, for the progress bar. */
      double total = 0;
      /** The scene's own body. */
      std::optional<Body> base;
      /** Stop signals, and the progress bar that acts on them. */
      std::optional<StopRequest> stop;
      std::optional<Progress>    progress;
      /** The reference solves, and how many converged. */
      std::vector<Sample> reference;
      unsigned int        n_reference = 0;
      /** The node of each DoF (-1: a pressure DoF). */
      std::vector<int> node_of_dof;
      /** Whether the scene's probe is a point (no discretisation error
       * bound), and the error budget left to interpolation (%). */
      bool   point_probe = true;
      double budget      = 0;
    };
  } // namespace internal
} // namespace palpate

#endif
