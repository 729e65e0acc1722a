// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

// benchmarks/run effects [--quick|--smoke] [--repeats N]
//
// What each effect costs (issue 13): the paper-stvk interaction
// (liver501, 2 solver threads, the 1 kHz loop, the 2.86 s stroke at
// 28 mm/s after the initial cloud) with every effect off, then each effect
// on alone: gravity, a surface traction (10 Pa on the whole surface),
// shape output at 30 Hz, the force log, VTU export. For each: the median
// time per state, the initial cloud's time, deadline misses and the
// interpolation's p99.9. overhead_pct is against the runs with every
// effect off; those runs, repeated, show the noise: an effect that is off
// is not even constructed, so "none" is the floor.
//
// Target: shape output at 30 Hz costs the solvers <= 10 %.
//
// "Zero cost when off" against a build that has no effects at all: the
// full run (benchmarks/run builds it, in build-no-effects/, with
// -DPALPATE_EFFECT_PLUGINS=OFF: the effect plug-ins' files are not compiled,
// the registry holds none) adds a row "no-effects-build", the same run as
// "none" by that build's benchmark (--baseline BIN), interleaved with the
// others.
//
// --quick: none and shape output, once each (about 30 s).
// --smoke (the test suite's): every effect once, on a cloud of radius 9 mm
// (the least that holds a cell) and a stroke of 0.1 s (each run a second
// or two).

#include <palpate/app/interaction_run.h>
#include <palpate/base/environment.h>
#include <palpate/haptics/run_summary.h>
#include <palpate/scene/scene.h>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <iomanip>
#include <iostream>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "machine.h"
#include "report_errors.h"

using namespace palpate;

namespace
{
  struct Run
  {
    double state_ms = 0, cloud_s = 0, interp_p999_us = 0;
    double deadline_misses = 0, missing = 0;
  };

  Run
  run(const std::string &effect, const bool smoke = false)
  {
    Scene scene = Scene::read(std::string(PALPATE_SOURCE_DIR) +
                              "/parameters/paper-stvk.prm");
    auto &p     = scene.parameters;
    if (smoke)
      {
        p.scheduler.cloud_radius      = 0.009;
        p.haptics.trajectory.duration = 0.1;
      }
    p.output.directory = "effects-output";
    p.output.summary_formats.clear();
    p.output.print_timings = false;
    auto &e                = p.effects;
    for (auto &[name, on] : e.switches)
      on = false;
    e.shape_output = e.force_log = e.vtu_export = false;
    if (effect == "gravity")
      e.turn_on("Gravity");
    else if (effect == "surface-traction")
      {
        e.turn_on("Surface traction");
        // liver501: boundary id 1 is the whole surface.
        e.set("Surface traction", "Traction boundary id", "1");
        e.set("Surface traction", "Traction", "0, 0, -10");
      }
    else if (effect == "shape-output")
      {
        e.shape_output      = true;
        e.shape_output_rate = 30;
      }
    else if (effect == "force-log")
      e.force_log = true;
    else if (effect == "vtu-export")
      e.vtu_export = true;
    std::filesystem::remove_all("effects-output");
    std::ostringstream quiet;
    const RunSummary   s = run_interaction(quiet, scene);
    std::filesystem::remove_all("effects-output");
    Run r;
    r.state_ms        = s.median_state_ms;
    r.cloud_s         = s.motion_start;
    r.interp_p999_us  = s.interpolation_p999_us;
    r.deadline_misses = s.deadline_misses;
    r.missing         = s.missing_events;
    return r;
  }

  /** The "none" run by the benchmark of another build (its --child). */
  Run
  run_baseline(const std::string &binary)
  {
    Run         r;
    FILE       *pipe = popen((binary + " --child none").c_str(), "r");
    std::string out;
    char        buffer[4096];
    while (pipe != nullptr && fgets(buffer, sizeof(buffer), pipe) != nullptr)
      out += buffer;
    if (pipe == nullptr || pclose(pipe) != 0 ||
        std::sscanf(out.c_str() + out.find("CHILD"),
                    "CHILD %lf %lf %lf %lf %lf",
                    &r.state_ms,
                    &r.cloud_s,
                    &r.deadline_misses,
                    &r.interp_p999_us,
                    &r.missing) != 5)
      throw std::runtime_error("the baseline " + binary + " failed:\n" + out);
    return r;
  }

  double
  median(std::vector<double> v)
  {
    std::sort(v.begin(), v.end());
    return v.empty() ? 0 : v[v.size() / 2];
  }
} // namespace

static int
run_benchmark(int argc, char **argv)
{
  Environment  env(argc, argv);
  bool         quick = false, smoke = false;
  unsigned int repeats = 2;
  std::string  baseline;
  for (int i = 1; i < argc; ++i)
    {
      const std::string a = argv[i];
      if (a == "--quick")
        quick = true;
      else if (a == "--smoke")
        smoke = true;
      else if (a == "--repeats" && i + 1 < argc)
        repeats = std::max(1, std::stoi(argv[++i]));
      else if (a == "--baseline" && i + 1 < argc)
        baseline = argv[++i];
      else if (a == "--child" && i + 1 < argc)
        {
          const Run r = run(argv[++i]);
          std::cout << "CHILD " << r.state_ms << " " << r.cloud_s << " "
                    << r.deadline_misses << " " << r.interp_p999_us << " "
                    << r.missing << std::endl;
          return 0;
        }
      else
        {
          std::cerr << "usage: benchmarks/run effects [--quick|--smoke] "
                       "[--repeats N] [--baseline BIN]\n";
          return 2;
        }
    }
  if (quick || smoke)
    repeats = 1;
  std::vector<std::string> effects =
    quick && !smoke ? std::vector<std::string>{"none", "shape-output"} :
                      std::vector<std::string>{"none",
                                               "gravity",
                                               "surface-traction",
                                               "shape-output",
                                               "force-log",
                                               "vtu-export"};
  if (!baseline.empty())
    effects.push_back("no-effects-build");
  std::cout << "What each effect costs: paper-stvk interaction, " << machine()
            << ", " << repeats << " run(s) each, interleaved"
            << (smoke ? " [--smoke]" :
                quick ? " [--quick]" :
                        "")
            << "\n\n";

  // Interleaved rounds, so that a slow minute of the machine does not fall
  // on one effect only.
  std::vector<std::vector<Run>> runs(effects.size());
  for (unsigned int round = 0; round < repeats; ++round)
    for (unsigned int k = 0; k < effects.size(); ++k)
      {
        runs[k].push_back(effects[k] == "no-effects-build" ?
                            run_baseline(baseline) :
                            run(effects[k], smoke));
        std::cout << "  " << std::left << std::setw(17) << effects[k]
                  << " state " << std::fixed << std::setprecision(2)
                  << runs[k].back().state_ms << " ms, initial cloud "
                  << runs[k].back().cloud_s << " s, deadline misses "
                  << std::setprecision(0) << runs[k].back().deadline_misses
                  << ", interpolation p99.9 " << std::setprecision(2)
                  << runs[k].back().interp_p999_us << " us\n"
                  << std::flush;
      }

  const auto stat = [&](const unsigned int k, double Run::*field) {
    std::vector<double> v;
    for (const auto &r : runs[k])
      v.push_back(r.*field);
    return median(v);
  };
  const double none_ms = stat(0, &Run::state_ms);
  double       noise   = 0;
  for (const auto &r : runs[0])
    noise = std::max(noise, 100 * std::abs(r.state_ms / none_ms - 1));

  std::cout << "\n| effect | state (ms) | overhead | initial cloud (s) | "
               "deadline misses | interpolation p99.9 (us) |\n"
               "|---|---|---|---|---|---|\n";
  std::ostringstream results;
  results << std::fixed;
  for (unsigned int k = 0; k < effects.size(); ++k)
    {
      const double ms       = stat(k, &Run::state_ms);
      const double overhead = 100 * (ms / none_ms - 1);
      std::cout << "| " << effects[k] << " | " << std::setprecision(2) << ms
                << " | " << std::setprecision(1) << overhead << " % | "
                << std::setprecision(2) << stat(k, &Run::cloud_s) << " | "
                << std::setprecision(0) << stat(k, &Run::deadline_misses)
                << " | " << std::setprecision(2)
                << stat(k, &Run::interp_p999_us) << " |\n";
      results
        << "RESULT effects effect=" << effects[k]
        << " state_ms=" << std::setprecision(2) << ms
        << " overhead_pct=" << std::setprecision(1) << overhead
        << " cloud_s=" << std::setprecision(2) << stat(k, &Run::cloud_s)
        << " deadline_misses=" << std::setprecision(0)
        << stat(k, &Run::deadline_misses)
        << (k == 0 ? " noise_pct=" + std::to_string(noise) : "")
        << (effects[k] == "no-effects-build" ?
              std::string(" within_noise=") +
                (std::abs(overhead) <= std::max(noise, 3.0) ? "yes" : "no") :
              "")
        << (effects[k] == "shape-output" ?
              std::string(" target_met=") + (overhead <= 10 ? "yes" : "no") :
              "")
        << "\n";
    }
  std::cout << "\n" << results.str();
  return 0;
}



int
main(int argc, char **argv)
{
  return report_errors("effects", run_benchmark, argc, argv);
}
