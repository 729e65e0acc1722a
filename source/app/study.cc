// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

#include <palpate/app/study.h>
#include <palpate/base/exceptions.h>
#include <palpate/base/stop_request.h>
#include <palpate/haptics/force_interpolation.h>
#include <palpate/hyperelastic/hyperelastic_system.h>
#include <palpate/hyperelastic/material.h>
#include <palpate/hyperelastic/sphere_trial.h>
#include <palpate/hyperelastic/state.h>
#include <palpate/hyperelastic/state_solver.h>
#include <palpate/mesh/mesh.h>
#include <palpate/mesh/node_selection.h>
#include <palpate/scene/scene.h>
#include <palpate/state_space/state_cache.h>
#include <palpate/state_space/state_grid.h>

#include <fcntl.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <csignal>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iomanip>
#include <iostream>
#include <map>
#include <memory>
#include <optional>
#include <random>
#include <set>
#include <sstream>
#include <thread>
#include <vector>

namespace palpate
{
  namespace
  {
    /** The first line of the study's CSV: a file that has another is not
     * overwritten. */
    const std::string csv_header =
      "material,knob,value,interpolation,probe,h_mm,samples,covered,"
      "err_mean_N,err_p95_N,err_max_N,err_mean_pct,err_p95_pct,"
      "err_max_pct,shape_err_mm,state_ms,states,failures,states_per_cm,"
      "region_states,precompute_s,memory_MiB,speed_mm_s,recommended";

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

    using Point3 = Utilities::Point3;
    using Clock  = std::chrono::steady_clock;

    /** Relative errors are taken against max(|f_ref|, this) (N): near
     * rest a force of a few mN has no meaningful relative error. */
    constexpr double force_floor = 0.1;

    /**
     * Two solvers on the two cores at once each run this much slower than
     * one alone: they share the memory bandwidth (measured 12.5 -> 19 ms
     * per StVK state on liver501, doc/benchmarks/scaling.md).
     */
    constexpr double two_solver_slowdown = 1.5;

    using Utilities::seconds_since;

    double
    percentile(std::vector<double> v, const double q)
    {
      if (v.empty())
        return 0;
      std::sort(v.begin(), v.end());
      const double r = q * (v.size() - 1);
      const auto   i = static_cast<std::size_t>(r);
      return i + 1 < v.size() ? v[i] + (r - i) * (v[i + 1] - v[i]) : v[i];
    }

    std::string
    fixed(const double x, const int digits)
    {
      std::ostringstream s;
      s << std::fixed << std::setprecision(digits) << x;
      return s.str();
    }

    /** A progress bar on stderr (a terminal), else a line per step. */
    /** Why the study ended before its last knob (Progress::step). */
    struct StudyCut
    {
      std::string why;
    };

    class Progress
    {
    public:
      Progress(std::ostream      &out,
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

      /**
       * One piece of work done (a state, a direct solve). Where the study
       * may be cut short: throws StudyCut after a stop signal, past the
       * time budget, or when nobody can read the output any more.
       */
      void
      step(const double amount, const std::string &what)
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
        const std::string eta      = fraction > 0.02 ?
                                       ", about " +
                                    std::to_string(static_cast<int>(std::ceil(
                                      elapsed * (1 - fraction) / fraction))) +
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
      finish()
      {
        if (enabled && terminal)
          std::cerr << "\r\033[K" << std::flush;
      }

    private:
      std::ostream      &out;
      bool               enabled, terminal;
      double             total, done = 0, next_line = 0;
      std::string        last;
      Clock::time_point  start;
      const StopRequest &stop;
      double             time_limit;
    };

    /**
     * HIP positions along smooth random trajectories in the ball of
     * @p radius around rest: Catmull-Rom splines through 5 random points,
     * @p per_trajectory positions each, in order along the path.
     */
    std::vector<std::vector<Point3>>
    trajectories(const unsigned int n,
                 const unsigned int per_trajectory,
                 const double       radius,
                 const unsigned int seed)
    {
      std::mt19937                           rng(seed);
      std::uniform_real_distribution<double> u(-1, 1);
      const auto                             random_point = [&]() {
        Point3 p;
        do
          p = {{u(rng), u(rng), u(rng)}};
        while (Utilities::norm(p) > 1);
        for (double &c : p)
          c *= radius;
        return p;
      };
      std::vector<std::vector<Point3>> result(n);
      for (auto &path : result)
        {
          std::vector<Point3> c(5);
          for (auto &p : c)
            p = random_point();
          // Catmull-Rom through c[1..3], with c[0] and c[4] as the ends'
          // tangent guides.
          for (unsigned int k = 0; k < per_trajectory; ++k)
            {
              const double       s = 2.0 * k / std::max(1u, per_trajectory - 1);
              const unsigned int seg = std::min(1u, static_cast<unsigned>(s));
              const double       t   = s - seg;
              const Point3 &p0 = c[seg], &p1 = c[seg + 1], &p2 = c[seg + 2],
                           &p3 = c[seg + 3];
              Point3 x;
              for (unsigned int d = 0; d < 3; ++d)
                x[d] =
                  0.5 * (2 * p1[d] + (-p0[d] + p2[d]) * t +
                         (2 * p0[d] - 5 * p1[d] + 4 * p2[d] - p3[d]) * t * t +
                         (-p0[d] + 3 * p1[d] - 3 * p2[d] + p3[d]) * t * t * t);
              // Keep it in the ball.
              const double r = Utilities::norm(x);
              if (r > radius)
                for (double &v : x)
                  v *= radius / r;
              path.push_back(x);
            }
        }
      return result;
    }

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
     * Direct solves at @p x (in trajectory order: each from the last
     * converged one of its trajectory, the first from rest), with the
     * Newton tolerance tightened to @p tolerance.
     */
    std::vector<Sample>
    direct_solves(const Body                             &body,
                  const std::vector<std::vector<Point3>> &paths,
                  const unsigned int                      limit,
                  const double                            tolerance,
                  std::vector<double>                    *state_times,
                  Progress                               &progress,
                  const double                            weight,
                  const std::string                      &what)
    {
      auto p                                = body.scene.parameters;
      p.nonlinear_solver.residual_tolerance = tolerance;
      p.nonlinear_solver.set_reuse(false);
      p.state_space.interpolation = "trilinear";
      StateSolver         solver(body.mesh, body.nodes, p);
      const State         rest = solver.rest_state();
      std::vector<Sample> samples;
      for (const auto &path : paths)
        {
          State previous = rest;
          for (const Point3 &x : path)
            {
              if (samples.size() == limit)
                return samples;
              Sample s;
              s.x           = x;
              const State a = solver.solve(previous, x);
              s.ok          = a.converged;
              if (a.converged)
                {
                  s.force    = a.force;
                  s.solution = a.solution;
                  previous   = a;
                  if (state_times != nullptr)
                    state_times->push_back(a.wall_time);
                }
              samples.push_back(std::move(s));
              progress.step(weight, what);
            }
        }
      return samples;
    }

    /** The grid states of one setting, computed as the engine computes
     * them. */
    struct GridStates
    {
      std::map<unsigned int, std::shared_ptr<const State>> states;
      std::set<unsigned int>                               failed;
      std::vector<double> times, stiffness_times;
    };

    /**
     * Compute the states at @p needed on @p grid with one solver (keeping
     * its factorisation from state to state, as a worker does): each from
     * an axis neighbour one step closer to rest (computed first, down to
     * rest), with the states behind it on the same grid line for the
     * second-/third-order start, as the engines do.
     */
    GridStates
    compute_grid(const Body                      &body,
                 const Parameters::AllParameters &p,
                 const StateGrid                 &grid,
                 const std::set<unsigned int>    &needed,
                 Progress                        &progress,
                 const double                     weight,
                 const std::string               &what)
    {
      StateSolver        solver(body.mesh, body.nodes, p);
      GridStates         g;
      const unsigned int origin = grid.linear({{0, 0, 0}});
      g.states[origin] = std::make_shared<const State>(solver.rest_state());
      const auto get   = [&](const unsigned int q) -> const State   *{
        const auto i = g.states.find(q);
        return i == g.states.end() ? nullptr : i->second.get();
      };
      std::function<void(unsigned int)> ensure = [&](const unsigned int q) {
        if (g.states.count(q) || g.failed.count(q))
          return;
        const GridIndex i = grid.index(q);
        unsigned int    a = 0;
        for (unsigned int d = 1; d < 3; ++d)
          if (std::abs(i[d]) > std::abs(i[a]))
            a = d;
        GridIndex parent = i;
        parent[a] -= (i[a] > 0) - (i[a] < 0);
        ensure(grid.linear(parent));
        // The source: that parent, else any computed axis neighbour.
        unsigned int source = grid.linear(parent);
        if (get(source) == nullptr)
          for (unsigned int d = 0; d < 3 && get(source) == nullptr; ++d)
            for (const int s : {-1, 1})
              {
                GridIndex n = i;
                n[d] += s;
                if (grid.contains(n) && get(grid.linear(n)) != nullptr)
                  {
                    source = grid.linear(n);
                    break;
                  }
              }
        if (get(source) == nullptr)
          {
            g.failed.insert(q);
            return;
          }
        unsigned int b = 0, bb = 0;
        const State *behind = grid.behind(source, q, b) ? get(b) : nullptr;
        const State *behind2 =
          behind != nullptr && grid.behind(b, source, bb) ? get(bb) : nullptr;
        const State s =
          solver.solve(*get(source), grid.position(q), behind, behind2);
        g.times.push_back(s.wall_time);
        g.stiffness_times.push_back(s.stiffness_time);
        if (s.converged)
          {
            State kept = s;
            kept.history.clear();
            g.states[q] = std::make_shared<const State>(std::move(kept));
          }
        else
          g.failed.insert(q);
        progress.step(weight, what);
      };
      // Nearest to rest first.
      std::vector<unsigned int> order(needed.begin(), needed.end());
      std::sort(order.begin(), order.end(), [&](unsigned int x, unsigned y) {
        return Utilities::norm(grid.position(x)) <
               Utilities::norm(grid.position(y));
      });
      for (const unsigned int q : order)
        ensure(q);
      return g;
    }

    /** The 8 corners of the cells of @p samples. */
    std::set<unsigned int>
    cell_corners(const StateGrid &grid, const std::vector<Point3> &x)
    {
      std::set<unsigned int> c;
      for (const Point3 &p : x)
        {
          GridIndex             lower;
          std::array<double, 3> local;
          if (grid.locate(p, lower, local))
            for (const unsigned int k : grid.corners(lower))
              c.insert(k);
        }
      return c;
    }

    /** @p points and their 26 neighbours (what Hermite reads). */
    std::set<unsigned int>
    with_neighbours(const StateGrid &grid, const std::set<unsigned int> &points)
    {
      std::set<unsigned int> r;
      for (const unsigned int q : points)
        for (const unsigned int n : grid.neighbourhood(q))
          r.insert(n);
      return r;
    }

    /**
     * Distinct grid points whose states the interpolation needs per cm of
     * a straight path: the corners of the cells crossed by 200 random
     * lines of 10 cm through the ball of 2 cm around rest.
     */
    double
    states_per_cm(const double h)
    {
      const StateGrid                        grid(h, 0.2);
      std::mt19937                           rng(3);
      std::uniform_real_distribution<double> u(-1, 1);
      double                                 total = 0;
      const unsigned int                     lines = 200;
      for (unsigned int l = 0; l < lines; ++l)
        {
          Point3 start = {{0.02 * u(rng), 0.02 * u(rng), 0.02 * u(rng)}}, dir;
          do
            dir = {{u(rng), u(rng), u(rng)}};
          while (Utilities::norm(dir) > 1 || Utilities::norm(dir) < 0.1);
          const double        n = Utilities::norm(dir);
          std::vector<Point3> x;
          const unsigned int  steps = static_cast<unsigned>(0.1 / (h / 20));
          for (unsigned int k = 0; k <= steps; ++k)
            {
              Point3 p;
              for (unsigned int d = 0; d < 3; ++d)
                p[d] = start[d] + dir[d] / n * 0.1 * k / steps;
              x.push_back(p);
            }
          total += cell_corners(grid, x).size();
        }
      return total / lines / 10.0;
    }

    /** Bytes of one state held by the engine. */
    double
    state_bytes(const State &s)
    {
      return sizeof(State) +
             (s.solution.size() + s.multipliers.size()) * sizeof(double);
    }

    /** The node of each DoF (-1: a pressure DoF), for nodal
     * displacements. */
    std::vector<int>
    nodes_of_dofs(const HyperelasticSystem &system)
    {
      const auto                          &position  = system.dof_positions();
      const auto                          &component = system.dof_components();
      std::map<std::array<double, 3>, int> number;
      std::vector<int>                     node(position.size(), -1);
      for (std::size_t d = 0; d < position.size(); ++d)
        if (component[d] < 3)
          node[d] = number
                      .emplace(std::array<double, 3>{{position[d][0],
                                                      position[d][1],
                                                      position[d][2]}},
                               number.size())
                      .first->second;
      return node;
    }

    /** Largest nodal displacement difference (m) of two solutions. */
    double
    shape_difference(const std::vector<int>    &node,
                     const std::vector<double> &a,
                     const std::vector<double> &b)
    {
      const int           n = *std::max_element(node.begin(), node.end()) + 1;
      std::vector<double> e2(n, 0.0);
      for (std::size_t d = 0; d < a.size(); ++d)
        if (node[d] >= 0)
          e2[node[d]] += (a[d] - b[d]) * (a[d] - b[d]);
      return std::sqrt(*std::max_element(e2.begin(), e2.end()));
    }

    /** Fill in the error columns of @p row from force pairs. */
    void
    errors(StudyRow                  &row,
           const std::vector<double> &absolute,
           const std::vector<double> &relative)
    {
      if (absolute.empty())
        return;
      double sum = 0, rsum = 0;
      for (const double e : absolute)
        sum += e;
      for (const double e : relative)
        rsum += e;
      row.err_mean_N   = sum / absolute.size();
      row.err_p95_N    = percentile(absolute, 0.95);
      row.err_max_N    = *std::max_element(absolute.begin(), absolute.end());
      row.err_mean_pct = 100 * rsum / relative.size();
      row.err_p95_pct  = 100 * percentile(relative, 0.95);
      row.err_max_pct =
        100 * *std::max_element(relative.begin(), relative.end());
    }

    double
    relative_error(const Point3 &f, const Point3 &reference)
    {
      return Utilities::distance(f, reference) /
             std::max(Utilities::norm(reference), force_floor);
    }

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

    std::string
    scientific(const double x)
    {
      std::ostringstream s;
      s << std::scientific << std::setprecision(0) << x;
      return s.str();
    }

    /** Whether a grid-knob row qualifies for the recommendation: p95
     * force error within @p threshold (%) on 95 % of the positions. */
    bool
    passes(const StudyRow &row, const double threshold)
    {
      return row.interpolation != "direct" && row.samples > 0 &&
             row.covered >= 0.95 * row.samples && row.err_p95_pct <= threshold;
    }

    std::string
    mm(const double metres)
    {
      std::ostringstream s;
      s << metres * 1000 << " mm";
      return s.str();
    }
  } // namespace


  namespace
  {
    /**
     * The study's steps and what they share (step-44's layout): run() reads
     * like the algorithm. A stop signal or the time budget cuts it short
     * at the next state or solve (StudyCut); what was measured until then
     * is reported and written.
     */
    class Study
    {
    public:
      Study(std::ostream &out, const Scene &scene, const StudyOptions &options)
        : out(out)
        , scene(scene)
        , options(options)
        , p0(scene.parameters)
        , quick(options.quick)
        , workers(std::max(
            1u,
            std::min(p0.engine.workers,
                     std::max(1u, std::thread::hardware_concurrency()))))
      {
        result.material = material_key(p0.material_model);
      }

      StudyResult
      run()
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

    private:
      /** The HIP positions: smooth random trajectories in a ball. */
      void
      choose_positions()
      {
        // --- The HIP positions: smooth random trajectories in a ball of
        // 12 mm around rest (cells of up to 20 mm around them stay within the
        // range where the liver scenes' states exist), or of half the state
        // space's extent if that is smaller.
        const unsigned int n_samples =
          options.samples > 0 ? options.samples : (quick ? 80 : 240);
        const unsigned int per_path = 20;
        n_paths                     = (n_samples + per_path - 1) / per_path;
        radius = std::min(0.012, 0.5 * p0.state_space.extent);
        paths  = trajectories(n_paths, per_path, radius, 2026);
        for (const auto &path : paths)
          for (const Point3 &x : path)
            if (positions.size() < n_samples)
              positions.push_back(x);
      }

      /** The knobs' values, one knob at a time from the scene's. */
      void
      choose_knob_values()
      {
        // --- The knobs and their values, one at a time from the scene's.
        h0       = p0.state_space.grid_spacing;
        spacings = quick ? std::vector<double>{0.005, 0.01, 0.02} :
                           std::vector<double>{0.0025, 0.005, 0.01, 0.02};
        // A spacing beyond half the extent leaves the positions' cells outside
        // the grid.
        spacings.erase(std::remove_if(spacings.begin(),
                                      spacings.end(),
                                      [&](const double h) {
                                        return h > 0.5 * p0.state_space.extent;
                                      }),
                       spacings.end());
        if (std::find(spacings.begin(), spacings.end(), h0) == spacings.end())
          spacings.push_back(h0);
        std::sort(spacings.begin(), spacings.end());
        tolerances = quick ? std::vector<double>{1e-4} :
                             std::vector<double>{1e-3, 1e-4, 1e-6};
        increments = quick ? std::vector<double>{0.0025} :
                             std::vector<double>{0.001, 0.0025};
        tolerances.erase(std::remove(tolerances.begin(),
                                     tolerances.end(),
                                     p0.nonlinear_solver.residual_tolerance),
                         tolerances.end());
        increments.erase(std::remove(increments.begin(),
                                     increments.end(),
                                     p0.nonlinear_solver.max_increment_length),
                         increments.end());
      }

      /** The finer mesh for the mesh knob: --finer-mesh, liver2k beside
       * liver501, or the generator's next refinement. */
      void
      choose_finer_mesh()
      {
        // The finer mesh for the mesh knob.
        {
          Scene       f = scene;
          auto       &m = f.parameters.mesh;
          std::string why_not;
          if (!options.finer_mesh.empty())
            {
              m.source = "file";
              m.file_name =
                std::filesystem::absolute(options.finer_mesh).string();
              finer_name = std::filesystem::path(options.finer_mesh).stem();
              finer      = f;
              // Read it and select its nodes now: a file that is not a mesh
              // of this organ is an input error before the reference solves,
              // not after them.
              try
                {
                  const Body check(f);
                  // Not finer than the scene's: the mesh knob would measure
                  // no refinement (0 % differences), which looks like a result.
                  const Mesh scene_mesh = Mesh::create(scene);
                  if (check.mesh.n_vertices() <= scene_mesh.n_vertices())
                    out
                      << "warning: --finer-mesh " << options.finer_mesh
                      << " has " << check.mesh.n_vertices()
                      << " nodes, not more than the scene's mesh ("
                      << scene_mesh.n_vertices()
                      << "): the mesh knob then measures no refinement. Give a "
                         "finer mesh of the same organ.\n";
                }
              catch (const InputError &e)
                {
                  // The file's own problem, but named as what it is here.
                  throw InputError(
                    e.file(),
                    e.line(),
                    "--finer-mesh (" + e.entry() + ")",
                    e.problem(),
                    "give a finer mesh of the same organ, in the "
                    "scene's file unit (its Scale factor applies): "
                    "the study solves the scene on it to measure "
                    "the mesh's error.");
                }
            }
          else if (m.source == "file")
            {
              std::filesystem::path file(m.file_name);
              if (file.is_relative() && !scene.file().empty())
                file = std::filesystem::path(scene.file()).parent_path() / file;
              const auto sibling = file.parent_path() / "liver2k.msh";
              if (file.filename() == "liver501.msh" &&
                  std::filesystem::exists(sibling))
                {
                  m.file_name = std::filesystem::absolute(sibling).string();
                  finer_name  = "liver2k";
                  coarse_name = "liver501";
                  finer       = f;
                }
            }
          else if (m.source == "surface")
            {
              // The same surface, finer: the refinement around the probe
              // halved (the indenter's region), or twice the nodes.
              if (m.surface_fine_size > 0)
                {
                  coarse_name = "refinement " + mm(m.surface_fine_size);
                  m.surface_fine_size /= 2;
                  finer_name = "refinement " + mm(m.surface_fine_size);
                }
              else
                {
                  coarse_name =
                    std::to_string(m.surface_target_nodes) + " nodes";
                  m.surface_target_nodes *= 2;
                  finer_name =
                    std::to_string(m.surface_target_nodes) + " nodes";
                }
              finer = f;
            }
          else if (m.source == "blob")
            {
              ++m.blob_refinements;
              finer_name =
                "blob, " + std::to_string(m.blob_refinements) + " refinements";
              finer = f;
            }
          else if (m.source == "beam")
            {
              m.beam_subdivisions_length *= 2;
              m.beam_subdivisions_width *= 2;
              m.beam_subdivisions_height *= 2;
              finer_name = "beam, twice the subdivisions";
              finer      = f;
            }
        }
      }

      void
      choose_probe()
      {
        // The probe: the scene's, and a rigid tip of 25 mm (or the scene's
        // tip) for the discretisation knobs, where a point probe has no
        // mesh-converged force.
        tip     = p0.boundary_conditions.active_node.tip_radius > 0 ?
                    p0.boundary_conditions.active_node.tip_radius :
                    0.025;
        n_disc  = quick ? 8 : 40;
        p2_knob = !quick || p0.material_model.model_name != "Mooney-Rivlin";
      }

      /** What the study does, and its work for the progress bar. */
      void
      announce_and_estimate_work()
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
        progress.emplace(
          out, options.progress, total, *stop, options.time_limit);
      }

      bool
      skipped(const std::string &knob) const
      {
        return std::find(options.skip.begin(), options.skip.end(), knob) !=
               options.skip.end();
      }

      /** The CSV's name: a directory is refused before anything runs. */
      void
      check_csv_file()
      {
        result.csv_file = options.csv_file;
        if (options.csv_given || !result.csv_file.empty())
          {
            namespace fs      = std::filesystem;
            const auto refuse = [&](const std::string &problem,
                                    const std::string &fix) {
              throw InputError(
                "command line", 0, "--csv " + result.csv_file, problem, fix);
            };
            // Names that do not say a file are refused with what to give:
            // otherwise an empty one would silently take the default name,
            // "-" would make a file of that name rather than mean standard
            // output, and "x.csv/" would be blamed as a missing directory.
            if (result.csv_file.empty())
              refuse("the file name is empty",
                     "name the table, e.g. --csv study.csv, or leave --csv "
                     "out to write it to Output / Directory.");
            // A name like an option or of blanks only is a slip, not a file
            // to make in the working directory.
            if (result.csv_file.front() == '-' && result.csv_file != "-")
              refuse("the name begins with '-', like an option",
                     "name the table, e.g. --csv study.csv (a file whose "
                     "name begins with '-': --csv ./" +
                       result.csv_file + ").");
            if (result.csv_file.find_first_not_of(" \t") == std::string::npos)
              refuse("the file name is blank",
                     "name the table, e.g. --csv study.csv.");
            if (result.csv_file == "-")
              refuse("the study cannot write its table to standard output: "
                     "the Pareto plot reads it back from a file",
                     "name a file, e.g. --csv study.csv.");
            if (result.csv_file.back() == '/')
              refuse("the name ends in '/', so it names a directory, not "
                     "a file",
                     "give the CSV file's name, e.g. --csv " +
                       (fs::path(result.csv_file) / "study.csv").string() +
                       ".");
            // A link to nowhere: the table would be made wherever it
            // points, or fail after the whole study.
            if (const std::string link = dangling_link(result.csv_file);
                !link.empty())
              refuse(link,
                     "name another file, or remove the link (rm '" +
                       result.csv_file + "') first.");
            // The plot is written beside the CSV, its name ending in .png.
            if (fs::path(result.csv_file).extension() == ".png")
              refuse("the Pareto plot is written beside the table under the "
                     "table's name ending in .png: it would overwrite the "
                     "table",
                     "name the CSV with .csv, e.g. --csv study.csv.");
            // Its directory, now, not after the first knob.
            const auto parent = fs::path(result.csv_file).parent_path();
            if (!parent.empty())
              {
                std::error_code error;
                const auto      status = fs::status(parent, error);
                if (const std::string link = dangling_link(parent.string());
                    !link.empty())
                  refuse("its directory " + link,
                         "make the link's target, or name a file in a "
                         "directory that exists.");
                if (status.type() == fs::file_type::not_found)
                  refuse("its directory '" + parent.string() +
                           "' does not exist",
                         "make it (mkdir -p '" + parent.string() +
                           "') or name a file in one that exists.");
                if (error)
                  refuse("the file system refuses its directory '" +
                           parent.string().substr(0, 300) + "' (" +
                           error.message() + ")",
                         "check the links on the way (a loop of symbolic "
                         "links?), the path's length and the permissions, "
                         "or name another file.");
                if (!fs::is_directory(status))
                  refuse("'" + parent.string() + "' is not a directory",
                         "name a file in a directory, e.g. --csv "
                         "study.csv.");
              }
            // Said before anything runs, not at the first knob's end.
            std::error_code                    error;
            const std::filesystem::file_status status =
              std::filesystem::status(result.csv_file, error);
            if (error && status.type() != std::filesystem::file_type::not_found)
              throw InputError("command line",
                               0,
                               "--csv " + result.csv_file,
                               "the file system refuses the path (" +
                                 error.message() + ")",
                               "check the links on the way (a loop of "
                               "symbolic links?) and the permissions, or "
                               "name another file.");
            // A device or a pipe (/dev/zero, a FIFO) is no table: the
            // Pareto plot would read it without end.
            if (std::filesystem::exists(status) &&
                !std::filesystem::is_directory(status) &&
                !std::filesystem::is_regular_file(status))
              throw InputError("command line",
                               0,
                               "--csv " + result.csv_file,
                               "'" + result.csv_file +
                                 "' is a device, a pipe or a socket, not a "
                                 "file: the study writes its table there "
                                 "and the Pareto plot reads it back",
                               "name a regular file, e.g. --csv study.csv.");
            // Nor is a PNG beside it that this plot did not draw (its
            // Software text chunk says "palpate study").
            // A link to nowhere there would be followed: the plot made
            // its target.
            if (const std::string link =
                  dangling_link(std::filesystem::path(result.csv_file)
                                  .replace_extension(".png")
                                  .string());
                options.plot && !link.empty())
              refuse("the Pareto plot would be written beside it, but " + link,
                     "name the CSV so that its .png is free, e.g. --csv "
                     "study.csv, or remove that link first.");
            if (std::filesystem::path png =
                  std::filesystem::path(result.csv_file)
                    .replace_extension(".png");
                options.plot && std::filesystem::exists(png, error))
              {
                std::ifstream in(png, std::ios::binary);
                std::string   head(65536, '\0');
                in.read(head.data(), head.size());
                head.resize(in.gcount());
                if (head.find("palpate study") == std::string::npos)
                  refuse("the Pareto plot would be written to '" +
                           png.string() +
                           "', which exists and is not a plot of a study",
                         "name the CSV so that its .png is free, e.g. --csv "
                         "study.csv, or remove that file first.");
              }
            // A file of the user's (the scene, its mesh) is not a table
            // to overwrite: only one a study wrote is.
            if (std::filesystem::is_regular_file(status))
              {
                // Its first bytes only (a large file without a newline
                // was read whole); printable, to quote them.
                std::ifstream in(result.csv_file, std::ios::binary);
                std::string   head(4096, '\0');
                in.read(head.data(), head.size());
                head.resize(in.gcount());
                if (!head.empty() && head.rfind(csv_header, 0) != 0)
                  {
                    std::string begins = head.substr(0, 40);
                    for (char &ch : begins)
                      if (!std::isprint(static_cast<unsigned char>(ch)))
                        ch = ' ';
                    refuse("'" + result.csv_file +
                             "' exists and is not a study's table (it "
                             "begins '" +
                             begins + "'): the study would overwrite it",
                           "name a new file, e.g. --csv study.csv, or remove "
                           "this one first if it is no longer needed.");
                  }
              }
            if (std::filesystem::is_directory(status))
              throw InputError(
                "command line",
                0,
                "--csv " + result.csv_file,
                "'" + result.csv_file + "' is a directory, not a file",
                "give the CSV file's name, e.g. --csv " +
                  (std::filesystem::path(result.csv_file) / "study.csv")
                    .string() +
                  ".");
          }
        if (result.csv_file.empty())
          {
            std::filesystem::create_directories(p0.output.directory);
            result.csv_file =
              (std::filesystem::path(p0.output.directory) /
               ("study-" + std::filesystem::path(scene.file()).stem().string() +
                ".csv"))
                .string();
          }
      }

      /** The rows so far (after every knob setting: even a killed study
       * leaves its finished rows). */
      void
      write_csv() const
      {
        std::ofstream csv(result.csv_file);
        csv << csv_header << "\n";
        for (unsigned int r = 0; r < result.rows.size(); ++r)
          {
            const auto &row = result.rows[r];
            csv << result.material << "," << row.knob << ",\"" << row.value
                << "\"," << row.interpolation << "," << row.probe << ","
                << row.h_mm << "," << row.samples << "," << row.covered << ","
                << row.err_mean_N << "," << row.err_p95_N << ","
                << row.err_max_N << "," << row.err_mean_pct << ","
                << row.err_p95_pct << "," << row.err_max_pct << ","
                << row.shape_err_mm << "," << row.state_ms << "," << row.states
                << "," << row.failures << "," << row.states_per_cm << ","
                << row.region_states << "," << row.precompute_s << ","
                << row.memory_MiB << "," << row.speed_mm_s << ","
                << (int(r) == result.recommended ? "yes" : "no") << "\n";
          }
        csv.close();
        if (!csv)
          throw OutputError("the study's CSV '" + result.csv_file +
                            "' could not be written (" + std::strerror(errno) +
                            ")");
      }

      /** Reference: direct solves at every position, tolerance 1e-10. */
      void
      solve_references()
      {
        // --- Reference: direct solves at every position, tolerance 1e-10.
        reference = direct_solves(*base,
                                  paths,
                                  positions.size(),
                                  1e-10,
                                  nullptr,
                                  *progress,
                                  1,
                                  "reference solves");
        for (const auto &s : reference)
          n_reference += s.ok;
        node_of_dof =
          nodes_of_dofs(StateSolver(base->mesh, base->nodes, p0).system());
      }

      /** One setting of the grid knobs: compute its states, interpolate
       * with both schemes, compare. */
      void
      grid_setting(const std::string              &knob,
                   const std::string              &value,
                   const Parameters::AllParameters p)
      {
        const StateGrid grid(p.state_space.grid_spacing, p.state_space.extent);
        const auto      corners     = cell_corners(grid, positions);
        const auto      needed      = with_neighbours(grid, corners);
        auto            q           = p;
        q.state_space.interpolation = "tricubic Hermite"; // stiffness too
        const GridStates g          = compute_grid(
          *base, q, grid, needed, *progress, 1, knob + " " + value);
        StateCache cache(grid, std::size_t(1) << 40);
        for (const auto &[point, state] : g.states)
          cache.publish(point, state, cache.generation());
        for (const unsigned int point : g.failed)
          cache.publish_failure(point, cache.generation());

        // Cost: state time with and without the stiffness.
        std::vector<double> plain, with;
        for (std::size_t i = 0; i < g.times.size(); ++i)
          {
            with.push_back(g.times[i]);
            plain.push_back(g.times[i] - g.stiffness_times[i]);
          }
        unsigned int region = 0;
        double       bytes  = 0;
        for (const unsigned int c : corners)
          if (const auto i = g.states.find(c); i != g.states.end())
            {
              ++region;
              bytes += state_bytes(*i->second);
            }
          else
            ++region;
        const double per_cm = states_per_cm(grid.spacing());

        // Shape: trilinear blend of the corners' displacement fields.
        std::vector<double> shape;
        for (std::size_t k = 0; k < positions.size(); ++k)
          {
            if (!reference[k].ok)
              continue;
            GridIndex             lower;
            std::array<double, 3> local;
            if (!grid.locate(positions[k], lower, local))
              continue;
            const auto          c = grid.corners(lower);
            const auto          w = trilinear_weights(local);
            std::vector<double> u(reference[k].solution.size(), 0.0);
            bool                complete = true;
            for (unsigned int j = 0; j < 8 && complete; ++j)
              {
                const auto i = g.states.find(c[j]);
                complete     = i != g.states.end();
                if (complete)
                  for (std::size_t d = 0; d < u.size(); ++d)
                    u[d] += w[j] * i->second->solution[d];
              }
            if (complete)
              shape.push_back(
                shape_difference(node_of_dof, u, reference[k].solution));
          }

        for (const auto scheme :
             {Interpolation::trilinear, Interpolation::hermite})
          {
            StudyRow row;
            row.knob  = knob;
            row.value = value;
            row.interpolation =
              scheme == Interpolation::hermite ? "Hermite" : "trilinear";
            row.h_mm               = grid.spacing() * 1000;
            row.residual_tolerance = p.nonlinear_solver.residual_tolerance;
            row.max_increment      = p.nonlinear_solver.max_increment_length;
            std::vector<double> absolute, relative;
            for (std::size_t k = 0; k < positions.size(); ++k)
              {
                if (!reference[k].ok)
                  continue;
                ++row.samples;
                const ForceSample s =
                  interpolate_force(grid, cache, positions[k], scheme);
                if (!s.complete)
                  continue;
                ++row.covered;
                absolute.push_back(
                  Utilities::distance(s.force, reference[k].force));
                relative.push_back(relative_error(s.force, reference[k].force));
              }
            errors(row, absolute, relative);
            if (!shape.empty())
              row.shape_err_mm =
                1000 * *std::max_element(shape.begin(), shape.end());
            row.state_ms =
              1000 *
              percentile(scheme == Interpolation::hermite ? with : plain, 0.5);
            row.states            = g.times.size();
            row.failures          = g.failed.size();
            row.states_per_cm     = per_cm;
            row.region_states     = region;
            const double slowdown = workers > 1 ? two_solver_slowdown : 1.0;
            row.precompute_s =
              region * row.state_ms / 1000 * slowdown / workers;
            row.memory_MiB = bytes / 1048576.0;
            // The engine keeps up while it computes the corners ahead as
            // fast as the HIP reaches them: workers / (state time) states
            // per second, per_cm states per cm (doc/accuracy-vs-time.md
            // compares it with benchmarks/run max-speed).
            row.speed_mm_s =
              workers / (row.state_ms / 1000 * slowdown) / per_cm * 10;
            result.rows.push_back(row);
          }
        write_csv();
      }

      /** Grid spacing, tolerance, increment, and the best of them together. */
      void
      measure_grid_knobs()
      {
        if (!skipped("grid"))
          for (const double h : spacings)
            {
              auto p                     = p0;
              p.state_space.grid_spacing = h;
              grid_setting("grid", mm(h), p);
            }
        if (!skipped("tolerance"))
          for (const double t : tolerances)
            {
              auto p                                = p0;
              p.nonlinear_solver.residual_tolerance = t;
              grid_setting("tolerance", scientific(t), p);
            }
        if (!skipped("increment"))
          for (const double l : increments)
            {
              auto p                                  = p0;
              p.nonlinear_solver.max_increment_length = l;
              grid_setting("increment", mm(l), p);
            }

        // The knobs together: the fastest grid setting that passes, with the
        // loosest tolerance that passes at the scene's spacing with the same
        // interpolation.
        {
          const StudyRow *best_grid = nullptr;
          double          loosest   = p0.nonlinear_solver.residual_tolerance;
          for (const auto &row : result.rows)
            if (passes(row, result.threshold_pct) && row.knob == "grid" &&
                (best_grid == nullptr ||
                 row.speed_mm_s > best_grid->speed_mm_s))
              best_grid = &row;
          if (best_grid != nullptr)
            for (const auto &row : result.rows)
              if (passes(row, result.threshold_pct) &&
                  row.knob == "tolerance" &&
                  row.interpolation == best_grid->interpolation)
                loosest = std::max(loosest, row.residual_tolerance);
          if (best_grid != nullptr && !skipped("combined") &&
              (best_grid->h_mm / 1000 != h0 ||
               loosest != p0.nonlinear_solver.residual_tolerance))
            {
              auto p                                = p0;
              p.state_space.grid_spacing            = best_grid->h_mm / 1000;
              p.nonlinear_solver.residual_tolerance = loosest;
              const std::string value =
                mm(p.state_space.grid_spacing) + ", " + scientific(loosest);
              grid_setting("combined", value, p);
            }
        }
      }

      /** Discretisation knobs: direct solves at the first n_disc positions,
       * against the finest setting of the knob, with the point probe and
       * with a rigid tip. */
      void
      discretisation(const std::string              &knob,
                     const std::vector<Scene>       &variants,
                     const std::vector<std::string> &names,
                     const std::vector<double>      &cost)
      {
        for (const double radius : {0.0, tip})
          {
            std::vector<std::vector<Sample>> forces;
            std::vector<std::vector<double>> times(variants.size());
            for (unsigned int v = 0; v < variants.size(); ++v)
              {
                Scene s      = variants[v];
                auto &active = s.parameters.boundary_conditions.active_node;
                active.tip_radius = radius;
                // The scene's sphere stays a sphere; otherwise a finite
                // radius is a glued tip.
                if (active.tip != Parameters::ActiveNode::Tip::sphere)
                  active.tip = radius > 0 ?
                                 Parameters::ActiveNode::Tip::glued_nodes :
                                 Parameters::ActiveNode::Tip::point;
                else if (!(radius > 0))
                  active.tip = Parameters::ActiveNode::Tip::point;
                const Body body(s);
                forces.push_back(direct_solves(
                  body,
                  paths,
                  std::min<unsigned>(n_disc, positions.size()),
                  p0.nonlinear_solver.residual_tolerance,
                  &times[v],
                  *progress,
                  cost[v],
                  knob + " " + names[v] +
                    (radius > 0 ? ", tip " + mm(radius) : ", point probe")));
              }
            const auto &finest = forces.back();
            for (unsigned int v = 0; v < variants.size(); ++v)
              {
                StudyRow row;
                row.knob          = knob;
                row.value         = names[v];
                row.interpolation = "direct";
                row.probe         = radius > 0 ? "tip " + mm(radius) : "point";
                row.h_mm          = 0;
                std::vector<double> absolute, relative;
                for (std::size_t k = 0; k < finest.size(); ++k)
                  {
                    ++row.samples;
                    if (!finest[k].ok || !forces[v][k].ok)
                      {
                        row.failures += !forces[v][k].ok;
                        continue;
                      }
                    ++row.covered;
                    absolute.push_back(
                      Utilities::distance(forces[v][k].force, finest[k].force));
                    relative.push_back(
                      relative_error(forces[v][k].force, finest[k].force));
                  }
                errors(row, absolute, relative);
                row.state_ms = 1000 * percentile(times[v], 0.5);
                row.states   = times[v].size();
                result.rows.push_back(row);
              }
            write_csv();
          }
      }

      void
      measure_discretisation_knobs()
      {
        if (finer && !skipped("mesh"))
          discretisation("mesh",
                         {scene, *finer},
                         {coarse_name, finer_name},
                         {1, finer_cost});
        if (p2_knob && !skipped("element"))
          {
            // An incompressible plug-in's element pair fixes the degree: the
            // knob is its Element entry (P1-P1 -> Taylor-Hood).
            Scene      p2   = scene;
            auto      &m    = p2.parameters.material_model;
            const auto f    = Material::create(m)->formulation();
            const bool pair = f.displacement_degree > 0;
            if (pair)
              m.set(m.model_name, "Element", "Taylor-Hood");
            else
              p2.parameters.discretization.polynomial_degree = 2;
            const std::string low  = pair ? "P1-P1" : "P1";
            const std::string high = pair ? "Taylor-Hood P2-P1" : "P2";
            if (f.degree(p0.discretization.polynomial_degree) == 1)
              discretisation("element", {scene, p2}, {low, high}, {1, p2_cost});
          }
      }

      void
      say_if_cut_short()
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
      reference_line() const
      {
        return reference.empty() ? "the " + std::to_string(positions.size()) +
                                     " reference solves did not finish.\n" :
                                   std::to_string(n_reference) + " of " +
                                     std::to_string(positions.size()) +
                                     " reference solves converged.\n";
      }

      /** Nothing measured (cut short during the reference solves, or every
       * knob skipped): no table, and no recommendation made of no rows. */
      StudyResult
      nothing_measured()
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

      /** The discretisation error of the scene's own mesh and element. */
      void
      bound_discretisation_error()
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
      recommend()
      {
        // --- The recommendation: the fastest grid-knob setting whose p95
        // force error, plus the discretisation error where it is known, is
        // below the threshold and that covers 95 % of the positions.
        budget =
          result.threshold_pct - std::max(0.0, result.discretization_pct);
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
      print_tables() const
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
          out
            << "| " << std::left << std::setw(10) << knob
            << " | interpolation | covered | force error mean / p95 / max (%) "
               "| max (N) | shape (mm) | state (ms) | states/cm | region: "
               "states, precompute (s), MiB | speed (mm/s) |\n";
          out << "|---|---|---|---|---|---|---|---|---|---|\n";
          for (unsigned int r = 0; r < result.rows.size(); ++r)
            {
              const auto &row = result.rows[r];
              if (row.knob != knob)
                continue;
              out << "| " << std::setw(10) << row.value << " | "
                  << std::setw(13) << row.interpolation << " | " << row.covered
                  << "/" << row.samples << " | " << fixed(row.err_mean_pct, 2)
                  << " / " << fixed(row.err_p95_pct, 2) << " / "
                  << fixed(row.err_max_pct, 2) << " | "
                  << fixed(row.err_max_N, 4) << " | "
                  << (row.shape_err_mm >= 0 ? fixed(row.shape_err_mm, 3) : "-")
                  << " | " << fixed(row.state_ms, 1) << " | "
                  << fixed(row.states_per_cm, 1) << " | " << row.region_states
                  << ", " << fixed(row.precompute_s, 1) << ", "
                  << fixed(row.memory_MiB, 1) << " | "
                  << fixed(row.speed_mm_s, 0)
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
            out
              << "| " << knob
              << " | probe | converged | force difference mean / p95 / max (%) "
                 "| max (N) | state (ms) |\n|---|---|---|---|---|---|\n";
            for (const auto &row : result.rows)
              if (row.knob == knob)
                out << "| " << row.value << " | " << row.probe << " | "
                    << row.samples - row.failures << "/" << row.samples << " | "
                    << fixed(row.err_mean_pct, 2) << " / "
                    << fixed(row.err_p95_pct, 2) << " / "
                    << fixed(row.err_max_pct, 2) << " | "
                    << fixed(row.err_max_N, 4) << " | "
                    << fixed(row.state_ms, 1) << " |\n";
            if (knob == "mesh")
              out
                << "A point probe has no mesh-converged force (a point load in "
                   "3-D has infinite compliance): compare the point rows with "
                   "the tip rows.\n";
          }
      }

      void
      print_discretisation_error_and_recommendation() const
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
                                                     "trilinear");
            if (row.residual_tolerance !=
                p0.nonlinear_solver.residual_tolerance)
              out << "; Nonlinear solver / Residual tolerance = "
                  << row.residual_tolerance;
            if (row.max_increment != p0.nonlinear_solver.max_increment_length)
              out << "; Nonlinear solver / Maximum increment length = "
                  << row.max_increment;
            out << ".\n";
          }
        else
          out << "  none of the settings keeps the p95 error below "
              << result.threshold_pct << " % on 95 % of the positions"
              << (result.discretization_pct >= result.threshold_pct ?
                    ": the discretisation alone is off by " +
                      fixed(result.discretization_pct, 2) +
                      " %; use a finer mesh or element.\n" :
                    ": use a finer grid or Hermite.\n");
      }

      /** The CSV with the recommendation marked, and the Pareto plot. */
      void
      write_csv_and_plot()
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

      std::ostream                    &out;
      const Scene                     &scene;
      const StudyOptions              &options;
      const Parameters::AllParameters &p0;
      const bool                       quick;
      const unsigned int               workers;
      const Clock::time_point          study_start = Clock::now();
      StudyResult                      result;
      // The HIP positions and their paths.
      unsigned int                     n_paths = 0;
      double                           radius  = 0;
      std::vector<std::vector<Point3>> paths;
      std::vector<Point3>              positions;
      // The knobs' values.
      double               h0 = 0;
      std::vector<double>  spacings, tolerances, increments;
      std::optional<Scene> finer;
      std::string          coarse_name = "scene mesh", finer_name;
      // The probe of the discretisation knobs, how many positions they
      // solve at, and whether the element knob runs.
      double       tip     = 0;
      unsigned int n_disc  = 0;
      bool         p2_knob = false;
      // Relative cost of a direct solve on the finer mesh and with P2.
      static constexpr double    finer_cost = 12, p2_cost = 20;
      double                     total = 0;
      std::optional<Body>        base;
      std::optional<StopRequest> stop;
      std::optional<Progress>    progress;
      std::vector<Sample>        reference;
      unsigned int               n_reference = 0;
      std::vector<int>           node_of_dof;
      bool                       point_probe = true;
      double                     budget      = 0;
    };
  } // namespace



  StudyResult
  run_study(std::ostream &out, const Scene &scene, const StudyOptions &options)
  {
    Study study(out, scene, options);
    return study.run();
  }
} // namespace palpate
