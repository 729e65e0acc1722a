// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

// benchmarks/run contact-patch [--quick|--smoke] [--body liver|blob|all]
//                              [--spacing 5,10,20] [--verbose] [--dump FILE]
//
// The force between the states with the sphere (issue 45): on the shipped
// indenter liver (parameters/liver-indenter.prm, 2,012 nodes) and on the
// blob generator's organ meshed as the liver is (its surface from
// blob_shape(), 4 mm elements under the probe: 1,889 nodes), both touched
// by the liver scene's 1 cm sphere, HIP positions on sweeps that cross contact
// onset (5 mm above the surface to 8 mm deep, on the normal and beside it),
// slide along the surface at 2, 4 and 6 mm depth, and press deep along the
// scene's stroke. At each, the force a haptic loop renders from grid states
// (trilinear, tricubic Hermite, contact patch) against a direct solve there:
//   err = |f_rendered - f_direct| / max(|f_direct|, 0.05 N).
// Grid states are computed as the engine computes them (each from a
// computed neighbour, the scene's solver with Contact solver = condensed,
// stiffness and patch on), for every corner of a cell a sweep visits and
// those corners' neighbours (the cross derivatives of Hermite need them).
// A sample whose cell has a failure point for a corner is left out and
// counted (`uncovered`). contact_patch blends the patches of the 4 corners
// of the HIP's tetrahedron in its cell, as palpate renders
// (simplex_weights()); patch_8_corners the cell's 8 by trilinear
// weights with the same confidence; patch_plain those by the trilinear
// weights alone, without PatchContact::blend()'s confidence; all in the
// same run, each replay by a solver of its own.
//
// tick_us_p999: the contact patch's time per tick, replaying the sweeps at
// 20 ticks between neighbouring samples (the sphere moving about 0.05 mm a
// tick) in one thread, as the haptic loop calls it; held_tick_us_p999: as
// many ticks with the HIP held still (the same work each tick), this VM's
// jitter for a tick of that size in the same run; tick_work_us_p999: each
// tick's least time over three replays of the same ticks by fresh solvers
// (the tick's own work, the VM's interruptions taken out), beside
// bare_loop_us_p999, a loop of fixed arithmetic as long as the median tick
// timed as many times (what the VM alone makes of a loop of that length).
//
// Targets: contact patch at 10 mm: err_p95_pct <= 3.5, err_max_pct <= 7,
// tick_us_p999 <= 100, and below Hermite's error at the same spacing.
//
// --quick: the liver, 10 mm, a third of the samples (a few minutes).
// --smoke (the test suite's): the liver meshed at 8 mm under the probe
// (not 4 mm), 10 mm, one sweep in contact on the normal (1 to 4 mm deep,
// 0.5 mm steps), the grid states with one cutback: every interpolation
// and the ticks.
// --dump FILE: the corners' forces at each sample, for trying blends
// off-line (dump_corners()).

#include <palpate/base/environment.h>
#include <palpate/base/utilities.h>
#include <palpate/haptics/force_interpolation.h>
#include <palpate/hyperelastic/contact_lcp.h>
#include <palpate/hyperelastic/contact_patch.h>
#include <palpate/hyperelastic/hyperelastic_system.h>
#include <palpate/hyperelastic/patch_contact.h>
#include <palpate/hyperelastic/state_solver.h>
#include <palpate/mesh/generators.h>
#include <palpate/mesh/mesh.h>
#include <palpate/mesh/node_selection.h>
#include <palpate/mesh/surface.h>
#include <palpate/scene/scene.h>
#include <palpate/state_space/state_cache.h>
#include <palpate/state_space/state_grid.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <map>
#include <memory>
#include <set>
#include <sstream>
#include <vector>

#include "machine.h"
#include "report_errors.h"

using namespace palpate;
using Utilities::Point3;

namespace
{
  struct Options
  {
    bool                     quick = false, smoke = false, verbose = false;
    std::vector<std::string> bodies   = {"liver", "blob"};
    std::vector<double>      spacings = {0.005, 0.01, 0.02};
    /** The grid states' Nonlinear solver / patch_factor_residual
     * (--patch-residual R; 0: the scene's). */
    double patch_residual = 0;
    /** --dump FILE: the corners' forces at each sample (dump_corners()). */
    std::string dump;
  };

  Point3
  add(const Point3 &a, const Point3 &b, const double s = 1)
  {
    return {{a[0] + s * b[0], a[1] + s * b[1], a[2] + s * b[2]}};
  }

  Point3
  unit(const Point3 &a)
  {
    return Utilities::scaled(a, 1 / Utilities::norm(a));
  }

  /**
   * The blob generator's organ as a closed surface (an OBJ in metres, in
   * the temporary directory): an icosahedron subdivided @p levels times,
   * projected onto the unit sphere and mapped by blob_shape(). Meshed as
   * the liver is (Source = surface, graded under the probe), the blob is
   * touched by the same sphere with elements of the same size where it
   * touches; the generator's own uniform tetrahedra are 18 mm there.
   */
  std::string
  write_blob_surface(const Point3 &semi_axes, const unsigned int levels)
  {
    const double g = (1 + std::sqrt(5.0)) / 2;
    Surface      ball;
    ball.vertices  = {{{-1, g, 0}},
                      {{1, g, 0}},
                      {{-1, -g, 0}},
                      {{1, -g, 0}},
                      {{0, -1, g}},
                      {{0, 1, g}},
                      {{0, -1, -g}},
                      {{0, 1, -g}},
                      {{g, 0, -1}},
                      {{g, 0, 1}},
                      {{-g, 0, -1}},
                      {{-g, 0, 1}}};
    ball.triangles = {{{0, 11, 5}},  {{0, 5, 1}},  {{0, 1, 7}},  {{0, 7, 10}},
                      {{0, 10, 11}}, {{1, 5, 9}},  {{5, 11, 4}}, {{11, 10, 2}},
                      {{10, 7, 6}},  {{7, 1, 8}},  {{3, 9, 4}},  {{3, 4, 2}},
                      {{3, 2, 6}},   {{3, 6, 8}},  {{3, 8, 9}},  {{4, 9, 5}},
                      {{2, 4, 11}},  {{6, 2, 10}}, {{8, 6, 7}},  {{9, 8, 1}}};
    for (unsigned int l = 0; l <= levels; ++l)
      {
        // Onto the unit sphere, then finer (the last level only projected).
        for (Point3 &x : ball.vertices)
          x = unit(x);
        if (l < levels)
          subdivide(ball);
      }
    for (Point3 &x : ball.vertices)
      x = blob_shape(x, semi_axes);
    const std::string file =
      (std::filesystem::temp_directory_path() / "palpate-blob-surface.obj")
        .string();
    write_surface(ball, file, false, 1);
    return file;
  }

  Scene
  body_scene(const std::string &body,
             const std::string &interpolation,
             const bool         smoke)
  {
    std::vector<std::string> settings = {
      "State space/Store=",
      "State space/Interpolation=" + interpolation,
      "Nonlinear solver/Contact solver=condensed",
      "Nonlinear solver/Assembly threads=1"};
    if (smoke)
      settings.push_back("Mesh/Surface/Refinement size=0.008");
    if (body == "blob")
      for (const std::string &s : std::vector<std::string>{
             "Mesh/File name=" + write_blob_surface({{0.125, 0.09, 0.07}}, 5),
             "Mesh/Scale factor=1",
             "Boundary conditions/Fixed nodes/Half-space point=0, 0, -0.04",
             "Boundary conditions/Active node/Point=0, 0, 0.07"})
        settings.push_back(s);
    return Scene::read(std::string(PALPATE_SOURCE_DIR) +
                         "/parameters/liver-indenter.prm",
                       settings);
  }

  /** The HIP positions of the sweeps, one vector per sweep (m). */
  std::vector<std::vector<Point3>>
  sweeps(const Point3 &normal,
         const Point3 &stroke,
         const bool    quick,
         const bool    smoke)
  {
    // Tangents of the surface at the touching point.
    Point3 t1 =
      std::abs(normal[0]) < 0.9 ? Point3{{1, 0, 0}} : Point3{{0, 1, 0}};
    t1              = unit(add(t1, normal, -Utilities::dot(t1, normal)));
    const Point3 t2 = Utilities::cross(normal, t1);
    const double mm = 1e-3, step = (smoke ? 0.5 : quick ? 1.5 : 0.5) * mm;
    std::vector<std::vector<Point3>> all;
    auto line = [&](const Point3 &from, const Point3 &to) {
      const unsigned int  n = std::ceil(Utilities::distance(from, to) / step);
      std::vector<Point3> s;
      for (unsigned int i = 0; i <= n; ++i)
        s.push_back(add(from, add(to, from, -1), double(i) / n));
      all.push_back(s);
    };
    // Onset: 5 mm above to 8 mm deep, on the normal and 3 and 6 mm beside
    // it (the offsets not on grid lines). The smoke: 1 to 4 mm deep on
    // the normal, in contact throughout and on one side of the rest
    // position, a grid point: a line through it needs the states around
    // the cells on every side of it.
    const Point3 beside = unit(add(t1, t2, 0.6));
    if (smoke)
      {
        line(Utilities::scaled(normal, -1 * mm),
             Utilities::scaled(normal, -4 * mm));
        return all;
      }
    for (const double off : {0.0, 3.0, -6.0})
      line(add(Utilities::scaled(normal, 5 * mm), beside, off * mm),
           add(Utilities::scaled(normal, -8 * mm), beside, off * mm));
    // Slides at 2, 4 and 6 mm depth, 12 mm either side.
    for (const double depth : {2.0, 4.0, 6.0})
      line(add(Utilities::scaled(normal, -depth * mm),
               Utilities::scaled(t1, -12 * mm)),
           add(Utilities::scaled(normal, -depth * mm),
               Utilities::scaled(t1, 12 * mm)));
    if (!quick)
      line(add(Utilities::scaled(normal, -4 * mm),
               Utilities::scaled(t2, -12 * mm)),
           add(Utilities::scaled(normal, -4 * mm),
               Utilities::scaled(t2, 12 * mm)));
    // Press deep along the scene's stroke, from 2 mm above.
    line(Utilities::scaled(normal, 2 * mm),
         add(Utilities::scaled(normal, 2 * mm), stroke, 16 * mm));
    return all;
  }



  double
  percentile(std::vector<double> v, const double p)
  {
    if (v.empty())
      return std::nan("");
    std::sort(v.begin(), v.end());
    return v[std::min<std::size_t>(v.size() - 1, p * v.size())];
  }

  double
  error_pct(const Point3 &f, const Point3 &direct)
  {
    return 100 * Utilities::distance(f, direct) /
           std::max(Utilities::norm(direct), 0.05);
  }

  void
  print_sample(const std::string &what,
               const Point3      &x,
               const Point3      &direct,
               const Point3      &f)
  {
    std::cout << "    " << what << " x " << Utilities::to_string(x, 4)
              << " direct " << Utilities::to_string(direct, 4) << " rendered "
              << Utilities::to_string(f, 4) << " err " << error_pct(f, direct)
              << "\n";
  }

  struct Row
  {
    std::string body, interpolation;
    double spacing_mm = 0, p95 = 0, max = 0, tick_p999 = 0, states_per_cm = 0;
    double held_p50 = 0, held_p999 = 0, cpu_p999 = 0;
    // The tick's least time over three replays, and the bare loop's.
    double       work_p999 = 0, bare_p999 = 0;
    unsigned int samples = 0, uncovered = 0;
  };

  /** How a replay blends the corners' patches: as palpate renders (the
   * HIP's tetrahedron, simplex_weights()), the cell's 8 corners by
   * trilinear weights with the same confidence, or those alone. */
  enum class Blend
  {
    rendered,
    cell,
    plain,
    // The HIP's tetrahedron's corners, each's force kept apart
    // (Replay::corner_force): for --dump.
    corners
  };

  /** A replay of the sweeps through a PatchContact: the force at each
   * sample (covered: its cell's corners all have patches), each tick's
   * force, time and work, and as many ticks again held in place. */
  struct Replay
  {
    std::vector<Point3>             force;
    std::vector<char>               covered;
    std::vector<Point3>             tick_force;
    std::vector<double>             tick_us, cpu_us, held_us;
    std::vector<PatchContact::Work> works;
    unsigned int                    unsettled = 0;
    // Blend::corners: at each sample, each corner's weight and force.
    std::vector<std::array<double, 8>> corner_weight;
    std::vector<std::array<Point3, 8>> corner_force;
  };

  /** The slowest ticks (the p99.9 tail and a few more) with the work they
   * did: what the tail is made of. */
  void
  print_slowest_ticks(const std::vector<double>             &tick_us,
                      const std::vector<PatchContact::Work> &works)
  {
    std::vector<std::size_t> order(tick_us.size());
    for (std::size_t t = 0; t < order.size(); ++t)
      order[t] = t;
    std::sort(order.begin(), order.end(), [&](auto a, auto b) {
      return tick_us[a] > tick_us[b];
    });
    const std::size_t shown = std::min<std::size_t>(order.size(), 8);
    std::cout
      << "  the slowest ticks (least of 3 replays): us (corners, new corners, active-set "
         "iterations, factorisations, largest active set, largest "
         "patch)\n";
    for (std::size_t k = 0; k < shown; ++k)
      {
        const auto &w = works[order[k]];
        std::cout << "    " << tick_us[order[k]] << " (" << w.corners << ", "
                  << w.new_corners << ", " << w.iterations << ", "
                  << w.factorizations << ", " << w.largest_active << ", "
                  << w.largest_patch << ")\n";
      }
  }

  /** The work of a replay's ticks, summed (it does not drift with the
   * machine as their times do), and their times. */
  void
  print_work(const Replay &r, const std::string &what)
  {
    std::size_t iterations = 0, factorizations = 0, new_corners = 0;
    for (const auto &w : r.works)
      {
        iterations += w.iterations;
        factorizations += w.factorizations;
        new_corners += w.new_corners;
      }
    std::cout << "  " << what << ": " << r.works.size() << " ticks, "
              << new_corners << " corners met, " << iterations
              << " active-set iterations, " << factorizations
              << " factorisations; p50 " << percentile(r.tick_us, 0.5)
              << " us, p99 " << percentile(r.tick_us, 0.99) << " us, p999 "
              << percentile(r.tick_us, 0.999) << " us\n";
  }

  /** The CPU time this thread has used (s): a tick's work without the
   * time the VM or the scheduler took the core away. */
  double
  thread_cpu_seconds()
  {
    timespec t{};
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
    return t.tv_sec + 1e-9 * t.tv_nsec;
  }

  /** The hand's move per tick between sweeps (m): 25 mm/s. */
  constexpr double transit_step = 2.5e-5;


  /**
   * The sweeps @p lines replayed as a hand moves them: 20 ticks from one
   * sample to the next (about 0.05 mm a tick), after 20 ticks at rest on
   * the first, and from one sweep's end to the next one's start at 25 mm/s
   * (those ticks timed too); the force at a sample is what the tick there
   * renders. With
   * @p blend the corners are blended as palpate renders, or as the
   * comparisons do (Blend). Then as
   * many ticks again with the same work each (the HIP held where the last
   * sweep ended, the contact settled): what this VM's jitter alone makes of
   * a tick's time, in the same run.
   */
  Replay
  replay(const StateGrid                        &grid,
         const StateCache                       &cache,
         const std::vector<std::vector<Point3>> &lines,
         PatchContact                           &solver,
         const Blend                             blend)
  {
    Replay                r;
    std::array<double, 8> last_weight{};
    std::array<Point3, 8> last_force{};
    auto                  tick = [&](const Point3 &x, Point3 &f) {
      last_force = {};
      GridIndex             lower;
      std::array<double, 3> local;
      if (!grid.locate(x, lower, local))
        return false;
      const auto                          corners = grid.corners(lower);
      std::array<const ContactPatch *, 8> patches;
      for (unsigned int c = 0; c < 8; ++c)
        {
          const auto s = cache.state(corners[c]);
          if (!s || !s->contact_patch)
            return false;
          patches[c] = s->contact_patch.get();
        }
      std::array<double, 9> K;
      const auto w = blend == Blend::rendered || blend == Blend::corners ?
                                        simplex_weights(local) :
                                        trilinear_weights(local);
      last_weight        = w;
      const double cpu   = thread_cpu_seconds();
      const auto   start = std::chrono::steady_clock::now();
      bool         settled;
      if (blend == Blend::rendered || blend == Blend::cell)
        settled = solver.blend(patches, w, x, f, &K);
      else
        {
          settled = true;
          f       = {{0, 0, 0}};
          for (unsigned int c = 0; c < 8; ++c)
            if (w[c] != 0)
              {
                Point3 fc;
                settled = solver.force(*patches[c], x, fc) && settled;
                f             = add(f, fc, w[c]);
                last_force[c] = fc;
              }
        }
      r.tick_us.push_back(1e6 * Utilities::seconds_since(start));
      r.cpu_us.push_back(1e6 * (thread_cpu_seconds() - cpu));
      r.works.push_back(solver.last_work());
      r.tick_force.push_back(f);
      r.unsettled += settled ? 0 : 1;
      return true;
    };
    const Point3 *last = nullptr;
    for (const auto &line : lines)
      for (std::size_t i = 0; i < line.size(); ++i)
        {
          Point3 f;
          bool   covered = true;
          // From the end of the last sweep to the start of this one as the
          // hand moves (0.025 mm a tick): no tick jumps, as no hand does.
          if (i == 0 && last)
            {
              const unsigned int steps =
                std::ceil(Utilities::distance(*last, line[0]) / transit_step);
              for (unsigned int t = 1; t < steps; ++t)
                tick(add(*last, add(line[0], *last, -1), double(t) / steps), f);
            }
          last = &line[i];
          if (i == 0)
            for (unsigned int t = 0; t < 20; ++t)
              covered = tick(line[i], f);
          else
            for (unsigned int t = 1; t <= 20; ++t)
              covered =
                tick(add(line[i - 1], add(line[i], line[i - 1], -1), t / 20.0),
                     f);
          r.force.push_back(f);
          r.covered.push_back(covered);
          r.corner_weight.push_back(last_weight);
          r.corner_force.push_back(last_force);
        }
    if (!lines.empty() && !lines.back().empty())
      {
        Point3            f;
        const std::size_t n_ticks = r.tick_us.size();
        for (unsigned int t = 0; t < 20; ++t)
          tick(lines.back().back(), f);
        const std::size_t settled = r.tick_us.size();
        for (std::size_t t = 0; t < n_ticks; ++t)
          tick(lines.back().back(), f);
        r.held_us.assign(r.tick_us.begin() + settled, r.tick_us.end());
        r.tick_us.resize(n_ticks);
        r.cpu_us.resize(n_ticks);
        r.works.resize(n_ticks);
        r.tick_force.resize(n_ticks);
      }
    return r;
  }

  /** The tick's own time, without this VM's jitter: the sweeps replayed
   * again by fresh solvers (the same ticks, the same work: the forces must
   * agree to the bit), each tick's least time over the replays; and a bare
   * loop of fixed arithmetic as long as the median tick, timed as often in
   * the same run (the tail the VM alone gives a loop of that length). */
  struct TickWork
  {
    std::vector<double> least_us;
    std::vector<double> bare_us;
  };

  /** Busy arithmetic for about @p n steps, not optimised away. */
  double
  bare_work(const unsigned int n)
  {
    volatile double sink = 0;
    double          v    = 1;
    for (unsigned int i = 0; i < n; ++i)
      v = v * 1.0000001 + 1e-9;
    sink = v;
    return sink;
  }

  TickWork
  tick_work(const StateGrid                        &grid,
            const StateCache                       &cache,
            const std::vector<std::vector<Point3>> &lines,
            const Replay                           &first,
            const unsigned int                      max_nodes)
  {
    TickWork work;
    work.least_us = first.tick_us;
    for (unsigned int pass = 0; pass < 2; ++pass)
      {
        PatchContact again(max_nodes, 256);
        const Replay r = replay(grid, cache, lines, again, Blend::rendered);
        if (r.tick_force != first.tick_force)
          throw std::runtime_error("contact-patch: a replay of the same "
                                   "ticks rendered other forces");
        for (std::size_t t = 0; t < r.tick_us.size(); ++t)
          work.least_us[t] = std::min(work.least_us[t], r.tick_us[t]);
      }
    // The loop's length: as many steps as take the median tick's time.
    const double        target = percentile(first.tick_us, 0.5);
    std::vector<double> calibration;
    for (unsigned int t = 0; t < 101; ++t)
      {
        const auto start = std::chrono::steady_clock::now();
        bare_work(100000);
        calibration.push_back(1e6 * Utilities::seconds_since(start));
      }
    const unsigned int steps =
      std::max(1.0, 100000 * target / percentile(calibration, 0.5));
    for (std::size_t t = 0; t < first.tick_us.size(); ++t)
      {
        const auto start = std::chrono::steady_clock::now();
        bare_work(steps);
        work.bare_us.push_back(1e6 * Utilities::seconds_since(start));
      }
    return work;
  }

  /**
   * --dump FILE: per sample and corner of the HIP's tetrahedron, the
   * corner's weight, its patch's force at the sample (uncorrected), its
   * state's force and its model's force at the 27 grid points around it
   * (ContactPatch::neighbour_force), after the direct force: what a blend
   * is made from, for trying blends off-line. Appends (one body after the
   * other), one line per sample:
   *   body i x y z fx fy fz [c w Fx Fy Fz Sx Sy Sz m0 ... m26]...
   */
  void
  dump_corners(const std::string         &file,
               const std::string         &body,
               const StateGrid           &grid,
               const StateCache          &cache,
               const std::vector<Point3> &samples,
               const std::vector<Point3> &f_direct,
               const Replay              &r)
  {
    std::ofstream out(file, std::ios::app);
    out << std::setprecision(17);
    for (std::size_t i = 0; i < samples.size(); ++i)
      {
        if (!r.covered[i])
          continue;
        GridIndex             lower;
        std::array<double, 3> local;
        grid.locate(samples[i], lower, local);
        const auto corners = grid.corners(lower);
        out << body << ' ' << i;
        for (const Point3 *v : {&samples[i], &f_direct[i]})
          for (const double e : *v)
            out << ' ' << e;
        for (unsigned int c = 0; c < 8; ++c)
          {
            if (r.corner_weight[i][c] == 0)
              continue;
            const auto &patch = *cache.state(corners[c])->contact_patch;
            out << ' ' << c << ' ' << r.corner_weight[i][c];
            for (const double e : r.corner_force[i][c])
              out << ' ' << e;
            for (const double e : patch.force)
              out << ' ' << e;
            for (unsigned int e = 0; e < 27; ++e)
              out << ' '
                  << (patch.neighbour_force.size() == 27 ?
                        patch.neighbour_force[e] :
                        -1.0);
          }
        out << '\n';
      }
  }

  /** Everything measured on one body. */
  void
  measure_body(const std::string &body,
               const Options     &o,
               std::vector<Row>  &rows)
  {
    const Scene         scene = body_scene(body, "contact patch", o.smoke);
    const Mesh          mesh  = Mesh::create(scene);
    const NodeSelection nodes = NodeSelection::create(scene, mesh);
    std::cout << "== " << body << ": " << mesh.n_vertices() << " nodes\n";

    // The direct solves, along each sweep from its previous sample.
    // The references to the solver's tolerance of its own tests, whatever
    // the scene's (1e-3: a force 7e-5 from these).
    auto direct_params                                = scene.parameters;
    direct_params.state_space.interpolation           = "trilinear";
    direct_params.nonlinear_solver.residual_tolerance = 1e-8;
    StateSolver direct(mesh, nodes, direct_params);
    const auto &sys  = direct.system();
    const State rest = direct.rest_state();
    std::vector<HyperelasticSystem::ContactRow> contact;
    sys.contact_rows(sys.from_state(rest), {{0, 0, 0}}, contact);
    unsigned int touching = 0;
    for (unsigned int k = 1; k < contact.size(); ++k)
      if (contact[k].gap < contact[touching].gap)
        touching = k;
    const Point3 normal     = Utilities::scaled(contact[touching].n, -1.0);
    const auto  &stroke_dir = scene.parameters.haptics.trajectory.direction;
    const auto   lines = sweeps(normal, unit(stroke_dir), o.quick, o.smoke);

    std::vector<Point3>              samples;
    std::vector<Point3>              f_direct;
    std::vector<double>              direct_ms;
    std::vector<std::vector<Point3>> direct_lines;
    for (const auto &line : lines)
      {
        direct_lines.emplace_back();
        State from = rest;
        for (const Point3 &x : line)
          {
            State s = direct.solve(from, x);
            if (!s.converged)
              {
                std::cout << "  direct solve failed at "
                          << Utilities::to_string(x, 4) << ": " << s.message
                          << "\n";
                continue;
              }
            samples.push_back(x);
            direct_lines.back().push_back(x);
            f_direct.push_back(s.force);
            direct_ms.push_back(1e3 * s.wall_time);
            from = std::move(s);
          }
      }
    std::cout << "  " << samples.size() << " samples on " << lines.size()
              << " sweeps, direct solve median " << percentile(direct_ms, 0.5)
              << " ms\n";

    for (const double h : o.spacings)
      {
        auto p                               = scene.parameters;
        p.state_space.grid_spacing           = h;
        p.nonlinear_solver.compute_stiffness = true;
        // The smoke's failure points (deep grid points of the
        // neighbourhood) are most of its time: one cutback, not the
        // scene's two, fails the same points in half the time (none
        // fails all of the sweep's corners).
        if (o.smoke)
          p.nonlinear_solver.max_cutbacks = 1;
        if (o.patch_residual > 0)
          p.nonlinear_solver.patch_factor_residual = o.patch_residual;
        StateSolver     solver(mesh, nodes, p);
        const StateGrid grid(h, std::max(p.state_space.extent, 0.03));
        StateCache      cache(grid, std::size_t(1) << 36);

        // Every corner of a cell a sample is in, and their neighbours.
        std::set<unsigned int> needed;
        double                 path_cm = 0;
        std::set<unsigned int> path_corners;
        for (std::size_t i = 0; i < samples.size(); ++i)
          {
            GridIndex             lower;
            std::array<double, 3> local;
            if (!grid.locate(samples[i], lower, local))
              continue;
            for (const unsigned int c : grid.corners(lower))
              {
                path_corners.insert(c);
                for (const unsigned int q : grid.neighbourhood(c))
                  needed.insert(q);
              }
          }
        for (const auto &line : lines)
          path_cm += 100 * Utilities::distance(line.front(), line.back());
        // Computed nearest to rest first, each from its nearest computed
        // point (rest to begin with).
        std::vector<unsigned int> order(needed.begin(), needed.end());
        std::sort(order.begin(), order.end(), [&](unsigned a, unsigned b) {
          return Utilities::norm(grid.position(a)) <
                 Utilities::norm(grid.position(b));
        });
        const State rest_h = solver.rest_state();
        std::map<unsigned int, std::shared_ptr<const State>> done;
        std::vector<double> state_ms, patch_nodes, patch_ms, patch_kib;
        unsigned int        failures = 0;
        for (const unsigned int q : order)
          {
            const State *from = &rest_h;
            double       best = Utilities::norm(grid.position(q));
            for (const auto &[r, s] : done)
              if (const double d =
                    Utilities::distance(grid.position(r), grid.position(q));
                  d < best)
                best = d, from = s.get();
            auto s =
              std::make_shared<State>(solver.solve(*from, grid.position(q)));
            if (!s->converged)
              {
                ++failures;
                cache.publish_failure(q, cache.generation(), s->status);
                continue;
              }
            state_ms.push_back(1e3 * s->wall_time);
            if (s->contact_patch)
              {
                patch_nodes.push_back(s->contact_patch->size());
                patch_kib.push_back(s->contact_patch->memory() / 1024.0);
              }
            patch_ms.push_back(1e3 * s->contact_patch_time);
            cache.publish(q, s, cache.generation());
            done[q] = s;
          }
        std::cout << "  h = " << 1e3 * h << " mm: " << order.size()
                  << " states (" << failures << " failures), median "
                  << percentile(state_ms, 0.5) << " ms (patch "
                  << percentile(patch_ms, 0.5) << " ms), patch nodes median "
                  << percentile(patch_nodes, 0.5) << ", max "
                  << percentile(patch_nodes, 1.0) << ", patch KiB median "
                  << percentile(patch_kib, 0.5) << ", max "
                  << percentile(patch_kib, 1.0) << "\n";

        PatchContact patch_contact(contact.size(), 256);
        // At a grid point the patch must give the state's force.
        double grid_point_error = 0;
        for (const auto &[q, st] : done)
          if (st->contact_patch)
            {
              Point3                f;
              std::array<double, 9> K;
              patch_contact.force(*st->contact_patch, grid.position(q), f, &K);
              grid_point_error =
                std::max(grid_point_error,
                         Utilities::distance(f, st->force) /
                           std::max(Utilities::norm(st->force), 1e-3));
            }
        std::cout << "  patch force at the grid points: largest relative "
                     "difference to the state's "
                  << grid_point_error << "\n";
        // Trilinear and Hermite: the force at each sample, as the haptic
        // loop interpolates it (no state of its own).
        for (const auto &[scheme, interpolate] :
             {std::pair<const char *, InterpolateFunction>{"trilinear",
                                                           &interpolate_force},
              {"hermite", &interpolate_hermite}})
          {
            Row row;
            row.body          = body;
            row.interpolation = scheme;
            row.spacing_mm    = 1e3 * h;
            row.states_per_cm = path_corners.size() / path_cm;
            std::vector<double> err;
            for (std::size_t i = 0; i < samples.size(); ++i)
              {
                const ForceSample s = interpolate(grid, cache, samples[i]);
                if (!s.complete)
                  {
                    ++row.uncovered;
                    continue;
                  }
                err.push_back(error_pct(s.force, f_direct[i]));
                if (o.verbose)
                  print_sample(row.interpolation,
                               samples[i],
                               f_direct[i],
                               s.force);
              }
            row.samples = err.size();
            row.p95     = percentile(err, 0.95);
            row.max     = percentile(err, 1.0);
            rows.push_back(row);
            std::cout << "  " << row.interpolation << ": p95 " << row.p95
                      << " %, max " << row.max << " %" << std::endl;
          }

        // The contact patch keeps a warm start from tick to tick: the
        // sweeps are replayed as a hand moves, each pass by a solver of its
        // own (one pass does not warm the caches for another).
        Row row;
        row.body          = body;
        row.interpolation = "contact_patch";
        row.spacing_mm    = 1e3 * h;
        row.states_per_cm = path_corners.size() / path_cm;
        PatchContact rendered(contact.size(), 256);
        PatchContact cell_contact(contact.size(), 256);
        PatchContact plain_contact(contact.size(), 256);
        const Replay ticks =
          replay(grid, cache, direct_lines, rendered, Blend::rendered);
        const TickWork work =
          tick_work(grid, cache, direct_lines, ticks, contact.size());
        const Replay cell =
          replay(grid, cache, direct_lines, cell_contact, Blend::cell);
        const Replay plain =
          replay(grid, cache, direct_lines, plain_contact, Blend::plain);

        if (!o.dump.empty())
          {
            PatchContact dump_contact(contact.size(), 256);
            dump_corners(
              o.dump,
              body,
              grid,
              cache,
              samples,
              f_direct,
              replay(grid, cache, direct_lines, dump_contact, Blend::corners));
          }

        std::vector<double> err, err_cell, err_plain;
        for (std::size_t i = 0; i < samples.size(); ++i)
          {
            if (!ticks.covered[i])
              {
                ++row.uncovered;
                continue;
              }
            err.push_back(error_pct(ticks.force[i], f_direct[i]));
            err_cell.push_back(error_pct(cell.force[i], f_direct[i]));
            err_plain.push_back(error_pct(plain.force[i], f_direct[i]));
            if (o.verbose)
              print_sample(row.interpolation,
                           samples[i],
                           f_direct[i],
                           ticks.force[i]);
          }
        print_work(ticks, "contact patch (the HIP's tetrahedron, 4 corners)");
        print_work(cell, "the cell's 8 corners, trilinear weights");
        print_slowest_ticks(work.least_us, ticks.works);
        auto timed = [&](Row r, const Replay &replayed) {
          r.tick_p999 = percentile(replayed.tick_us, 0.999);
          r.held_p50  = percentile(replayed.held_us, 0.5);
          r.held_p999 = percentile(replayed.held_us, 0.999);
          r.cpu_p999  = percentile(replayed.cpu_us, 0.999);
          return r;
        };
        row.samples = err.size();
        row.p95     = percentile(err, 0.95);
        row.max     = percentile(err, 1.0);
        {
          Row timed_row       = timed(row, ticks);
          timed_row.work_p999 = percentile(work.least_us, 0.999);
          timed_row.bare_p999 = percentile(work.bare_us, 0.999);
          rows.push_back(timed_row);
        }
        Row cell_row           = timed(row, cell);
        cell_row.interpolation = "patch_8_corners";
        cell_row.p95           = percentile(err_cell, 0.95);
        cell_row.max           = percentile(err_cell, 1.0);
        rows.push_back(cell_row);
        Row plain_row           = row;
        plain_row.interpolation = "patch_plain";
        plain_row.p95           = percentile(err_plain, 0.95);
        plain_row.max           = percentile(err_plain, 1.0);
        rows.push_back(plain_row);
        const Row &r = rows[rows.size() - 3];
        std::cout << "  contact_patch: p95 " << r.p95 << " %, max " << r.max
                  << " %; the cell's 8 corners: p95 " << cell_row.p95
                  << " %, max " << cell_row.max
                  << " %; those by the trilinear weights alone: p95 "
                  << plain_row.p95 << " %, max " << plain_row.max << " %"
                  << std::endl;
        std::cout << "  contact patch: " << ticks.tick_us.size() << " ticks ("
                  << ticks.unsettled << " not settled), p50 "
                  << percentile(ticks.tick_us, 0.5) << " us, p99 "
                  << percentile(ticks.tick_us, 0.99) << " us, p999 "
                  << r.tick_p999 << " us; held in place: p50 " << r.held_p50
                  << " us, p999 " << r.held_p999 << " us" << std::endl;
        std::cout << "  the same ticks' least time over 3 replays: p50 "
                  << percentile(work.least_us, 0.5) << " us, p99 "
                  << percentile(work.least_us, 0.99) << " us, p999 "
                  << r.work_p999 << " us; a bare loop as long as the median "
                  << "tick: p50 " << percentile(work.bare_us, 0.5)
                  << " us, p999 " << r.bare_p999 << " us" << std::endl;
        std::cout << "  the same ticks' thread CPU time: p50 "
                  << percentile(ticks.cpu_us, 0.5) << " us, p99 "
                  << percentile(ticks.cpu_us, 0.99) << " us, p999 "
                  << r.cpu_p999 << " us" << std::endl;
      }
  }

  int
  run_benchmark(int argc, char **argv)
  {
    Environment env(argc, argv);
    Options     o;
    // --quick and --smoke choose the liver at 10 mm unless --body or
    // --spacing say otherwise.
    bool body_given = false, spacing_given = false;
    for (int i = 1; i < argc; ++i)
      {
        const std::string a = argv[i];
        if (a == "--quick")
          o.quick = true;
        else if (a == "--smoke")
          o.smoke = true;
        else if (a == "--verbose")
          o.verbose = true;
        else if (a == "--body" && i + 1 < argc)
          {
            const std::string b = argv[++i];
            o.bodies = b == "all" ? std::vector<std::string>{"liver", "blob"} :
                                    std::vector<std::string>{b};
            body_given = true;
          }
        else if (a == "--dump" && i + 1 < argc)
          o.dump = argv[++i];
        else if (a == "--patch-residual" && i + 1 < argc)
          o.patch_residual = std::stod(argv[++i]);
        else if (a == "--spacing" && i + 1 < argc)
          {
            o.spacings.clear();
            for (const auto &s : Utilities::split(argv[++i], ','))
              o.spacings.push_back(1e-3 * std::stod(s));
            spacing_given = true;
          }
        else
          {
            std::cerr
              << "usage: benchmarks/run contact-patch [--quick|--smoke] "
                 "[--body liver|blob|all] [--spacing 5,10,20] "
                 "[--patch-residual R] [--verbose] [--dump FILE]\n";
            return 2;
          }
      }
    if (o.quick || o.smoke)
      {
        if (!body_given)
          o.bodies = {"liver"};
        if (!spacing_given)
          o.spacings = {0.01};
      }
    std::cout << "The force between the states with the sphere; machine: "
              << machine() << "\n\n";
    std::vector<Row> rows;
    for (const auto &b : o.bodies)
      measure_body(b, o, rows);

    std::cout << "\n"
              << std::left << std::setw(7) << "body" << std::setw(17)
              << "interpolation" << std::right << std::setw(6) << "h mm"
              << std::setw(9) << "samples" << std::setw(10) << "uncovered"
              << std::setw(10) << "p95 %" << std::setw(10) << "max %"
              << std::setw(10) << "states/cm" << std::setw(12) << "tick p999"
              << "\n";
    for (const Row &r : rows)
      std::cout << std::left << std::setw(7) << r.body << std::setw(17)
                << r.interpolation << std::right << std::setw(6) << r.spacing_mm
                << std::setw(9) << r.samples << std::setw(10) << r.uncovered
                << std::setw(10) << std::setprecision(3) << r.p95
                << std::setw(10) << r.max << std::setw(10) << r.states_per_cm
                << std::setw(12) << r.tick_p999 << "\n";
    std::cout << "\n";
    for (const Row &r : rows)
      std::cout << "RESULT contact-patch mesh=" << r.body
                << " interpolation=" << r.interpolation
                << " spacing_mm=" << r.spacing_mm << " err_p95_pct=" << r.p95
                << " err_max_pct=" << r.max << " tick_us_p999=" << r.tick_p999
                << " held_tick_us_p999=" << r.held_p999
                << " tick_cpu_us_p999=" << r.cpu_p999
                << " tick_work_us_p999=" << r.work_p999
                << " bare_loop_us_p999=" << r.bare_p999
                << " states_per_cm=" << r.states_per_cm
                << " samples=" << r.samples << " uncovered=" << r.uncovered
                << "\n";
    return 0;
  }
} // namespace

int
main(int argc, char **argv)
{
  return report_errors("contact-patch", run_benchmark, argc, argv);
}
