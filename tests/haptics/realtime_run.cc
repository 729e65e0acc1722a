// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

// A short real run of the whole chain, as `palpate scene.prm` does it: the
// beam scene, 2 solver threads, the built-in 1 kHz haptic loop, a simulated
// device on a 3 mm circle at 5 mm/s for 1.5 s after the initial cloud,
// shape output at 30 Hz, force log and CSV/JSON summaries. Wall-clock
// times vary, so the test checks counts and bounds, not seconds:
// - the loop ran for (motion start + motion) x rate ticks, within 10 %;
// - no non-finite force, no force change above the scene's limit, in the
//   summary and in every row of the force log;
// - states were computed and used, no missing-data event (the HIP is slow
//   for this scene), fewer than 5 % of the ticks late beyond the misses
//   of a bare 1 kHz loop measured in the same test;
// - the summary files and the shape frames (PVD + one VTU per frame) exist;
// - the force log and the shape frames share the device's clock and start
//   with the motion: the log has a row per tick of the motion (not of the
//   wait for the initial cloud), times in (0, motion], increasing; the
//   frames' times are in [0, motion], at most one per 1/30 s;
// - VTU export writes every state the haptic loop used, with an index;
// - with every effect off and no summary file, the run leaves no file.

#include <palpate/app/interaction_run.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>

#include "../tests.h"

#include "../../benchmarks/machine.h"

namespace
{
  /** The key,value lines of a run summary CSV. */
  std::map<std::string, std::string>
  read_summary(const std::string &file)
  {
    std::map<std::string, std::string> values;
    std::ifstream                      in(file);
    std::string                        line;
    std::getline(in, line); // header
    while (std::getline(in, line))
      {
        const auto  comma = line.find(',');
        std::string value = line.substr(comma + 1);
        if (value.size() >= 2 && value.front() == '"')
          value = value.substr(1, value.size() - 2);
        values[line.substr(0, comma)] = value;
      }
    return values;
  }
} // namespace

int
main(int argc, char **argv)
{
  palpate::Environment env(argc, argv);
  initlog();

  // The shipped beam, ten times stiffer (a scene sets each entry once).
  std::string  beam  = read_file(palpate_source_dir + "/parameters/beam.prm");
  const auto   at    = beam.find("set Young's modulus = 1e5");
  const size_t width = std::string("set Young's modulus = 1e5").size();
  AssertThrow(at != std::string::npos, dealii::ExcInternalError());
  beam.replace(at, width, "set Young's modulus = 1e6");
  const std::string text = beam + R"(
subsection Effects
  set Shape output      = true
  set Shape output rate = 30
  set Force log         = true
  set VTU export        = true
end
subsection State space
  set Grid spacing = 0.002
  set Extent       = 0.01
end
subsection Scheduler
  set Cloud radius = 0.005
end
subsection Engine
  set Workers = 2
end
subsection Haptics
  set Loop rate               = 1000
  set Force limit             = 5
  set Maximum force change    = 0.01
  subsection Trajectory
    set Type      = circle
    set Direction = 0, 1, 0
    set Radius    = 0.003
    set Speed     = 0.005
    set Duration  = 1.5
  end
end
subsection Output
  set Directory       = realtime-output
  set Summary formats = csv, json
end
)";
  write_file("realtime.prm", text);
  std::filesystem::remove_all("realtime-output");

  std::ostringstream report;
  palpate::run_interaction(report, palpate::Scene::read("realtime.prm"));
  const bool events_logged =
    report.str().find("missing data at") != std::string::npos;

  auto       s      = read_summary("realtime-output/realtime-summary.csv");
  const auto number = [&](const std::string &key) {
    return std::stod(s.at(key));
  };
  const double rate = number("loop_rate_Hz");
  const double expected =
    (number("motion_start_s") + number("motion_duration_s")) * rate;
  const double ticks = number("ticks");
  deallog << "loop ran: " << s["loop_ran"]
          << "; ticks / ((motion start + motion) x rate) within "
          << "10 %: " << (std::abs(ticks / expected - 1) < 0.1 ? "yes" : "NO")
          << "; motion lasted " << number("motion_duration_s") << " s"
          << std::endl;
  deallog << "states computed > 0: "
          << (number("states_computed") > 0 ? "yes" : "NO")
          << ", states used >= 8: "
          << (number("states_used") >= 8 ? "yes" : "NO")
          << ", failure points: " << s["states_failed"] << std::endl;
  deallog << "missing-data events: " << s["missing_data_events"]
          << ", logged: " << (events_logged ? "yes" : "no") << std::endl;
  deallog << "non-finite forces: " << s["non_finite_forces"]
          << ", largest change per tick <= 0.01 N: "
          << (number("largest_force_change_N") <= 0.01 + 1e-12 ? "yes" : "NO")
          << ", largest force > 0: "
          << (number("largest_force_N") > 0 ? "yes" : "NO") << std::endl;
  // The misses this machine gives any 1 kHz loop beside busy solver
  // threads (a virtual machine's host, interrupts) are not the loop's: the
  // bound is on those beyond a bare loop's, of as many ticks with 2 busy
  // threads beside it, measured here.
  const auto bare = bare_loop(ticks / rate, rate, 2);
  deallog << "deadline misses beyond a bare loop's (as many ticks, 2 busy "
             "threads beside it) below 5 % of the ticks: "
          << (number("deadline_misses") < bare.first + 0.05 * ticks ? "yes" :
                                                                      "NO")
          << std::endl;
  deallog << "interpolation time measured: "
          << (number("interpolation_p50_us") > 0 &&
                  number("interpolation_p999_us") >=
                    number("interpolation_p50_us") ?
                "yes" :
                "NO")
          << std::endl;

  // The force log: one row per tick, finite, changing by at most 0.01 N.
  std::ifstream log("realtime-output/realtime-forces.csv");
  std::string   line;
  std::getline(log, line);
  deallog << "force log header: " << line << std::endl;
  unsigned int rows   = 0;
  bool         finite = true, smooth = true, clock = true;
  double       previous[3] = {0, 0, 0}, previous_t = 0;
  while (std::getline(log, line))
    {
      double             v[7];
      char               comma;
      std::istringstream in(line);
      in >> v[0];
      for (unsigned int k = 1; k < 7; ++k)
        in >> comma >> v[k];
      for (unsigned int k = 0; k < 7; ++k)
        finite = finite && std::isfinite(v[k]);
      clock = clock && v[0] > previous_t &&
              v[0] <= number("motion_duration_s") + 0.01;
      previous_t          = v[0];
      const double change = std::sqrt(std::pow(v[4] - previous[0], 2) +
                                      std::pow(v[5] - previous[1], 2) +
                                      std::pow(v[6] - previous[2], 2));
      smooth = smooth && change <= 0.01 + 1e-7; // the log has 9 digits
      for (unsigned int d = 0; d < 3; ++d)
        previous[d] = v[4 + d];
      ++rows;
    }
  // A stall skips the deadlines that passed (no burst of catch-up ticks)
  // and counts them as misses: under CI's load 2 % of the motion's ticks
  // were once skipped so. Every tick that ran has its row.
  const double motion_ticks = number("motion_duration_s") * rate;
  const double skipped      = number("deadline_misses");
  deallog << "force log: one row per tick of the motion (2 %, less the "
             "deadlines a stall skipped): "
          << (rows < 1.02 * motion_ticks &&
                  rows + skipped > 0.98 * motion_ticks ?
                "yes" :
                "NO")
          << ", times in (0, motion] and increasing: " << (clock ? "yes" : "NO")
          << ", all finite: " << (finite ? "yes" : "NO")
          << ", change per row <= 0.01 N: " << (smooth ? "yes" : "NO")
          << std::endl;

  // The shape frames.
  const unsigned int frames = static_cast<unsigned int>(number("shape_frames"));
  unsigned int       vtus   = 0;
  for (const auto &entry :
       std::filesystem::directory_iterator("realtime-output"))
    vtus +=
      entry.path().extension() == ".vtu" &&
      entry.path().filename().string().find("-shape-") != std::string::npos;
  const std::string pvd_text = read_file("realtime-output/realtime-shape.pvd");
  unsigned int      datasets = 0;
  for (std::size_t at = pvd_text.find("<DataSet"); at != std::string::npos;
       at             = pvd_text.find("<DataSet", at + 1))
    ++datasets;
  // The frames' times (file="...") in the PVD: timestep="t".
  bool   in_motion = true;
  double last_t    = -1;
  for (std::size_t at = pvd_text.find("timestep=\""); at != std::string::npos;
       at             = pvd_text.find("timestep=\"", at + 1))
    {
                  const double t = std::stod(pvd_text.substr(at + 10));
                  in_motion      = in_motion && t >= 0 &&
                              t <= number("motion_duration_s") + 0.05 && t > last_t;
                  last_t = t;
    }
  deallog << "shape frames on the device's clock, during the motion only, at "
             "most 30 per s: "
          << (in_motion && frames <= number("motion_duration_s") * 30 + 2 ?
                "yes" :
                "NO")
          << std::endl;
  deallog << "shape frames: " << (frames > 0 ? "some" : "NONE")
          << ", one VTU each: " << (vtus == frames ? "yes" : "NO")
          << ", all in the PVD: " << (datasets == frames ? "yes" : "NO")
          << std::endl;
  // VTU export in an interaction: every state the haptic loop used.
  {
    std::ifstream index("realtime-output/realtime-states.csv");
    std::string   row;
    std::getline(index, row);
    unsigned int states = 0, files = 0;
    while (std::getline(index, row))
      {
        ++states;
        files += std::filesystem::exists("realtime-output/" +
                                         row.substr(row.rfind(',') + 1));
      }
    deallog << "VTU export: one file per state the loop used: "
            << (states == number("states_used") && files == states ? "yes" :
                                                                     "NO")
            << std::endl;
  }

  // Every effect off, no summary file: no file at all.
  {
    std::string quiet = text;
    for (const auto &[from, to] :
         std::vector<std::pair<std::string, std::string>>{
           {"set Shape output      = true", "set Shape output      = false"},
           {"set Force log         = true", "set Force log         = false"},
           {"set VTU export        = true", "set VTU export        = false"},
           {"set Directory       = realtime-output",
            "set Directory       = quiet-output"},
           {"set Summary formats = csv, json", "set Summary formats ="},
           {"set Duration  = 1.5", "set Duration  = 0.3"}})
      {
        const auto at = quiet.find(from);
        AssertThrow(at != std::string::npos, dealii::ExcInternalError());
        quiet.replace(at, from.size(), to);
      }
    write_file("quiet.prm", quiet);
    std::filesystem::remove_all("quiet-output");
    std::ostringstream quiet_report;
    palpate::run_interaction(quiet_report, palpate::Scene::read("quiet.prm"));
    const bool none = !std::filesystem::exists("quiet-output") ||
                      std::filesystem::is_empty("quiet-output");
    deallog << "every effect off: no file written: " << (none ? "yes" : "NO")
            << std::endl;
  }
  deallog << "JSON summary written: "
          << (std::filesystem::exists("realtime-output/realtime-summary.json") ?
                "yes" :
                "NO")
          << std::endl;
}
