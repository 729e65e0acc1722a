// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

// Application tests (as Lethe's): every scene palpate ships in parameters/,
// found on disk (a new scene shows here, and fails until its numbers are
// in the .output), solved as `palpate solve SCENE.prm` solves it: to its
// Prescribed displacement, with its mesh, material, probe and solver
// settings. The .output holds the scene's numbers: its report (mesh,
// boundary conditions, probe, material, effects), the system and solver,
// the increments and Newton iterations, and the force on the probe (to the
// 5 digits palpate prints). Left out: what depends on the machine or the
// run (times, paths written, MUMPS's flop count, the Newton history's
// round-off).

#include <algorithm>
#include <filesystem>
#include <regex>
#include <sstream>
#include <vector>

#include "../tests.h"

namespace
{
  /** Whether @p line of `palpate solve`'s output holds one of the scene's
   * numbers (a report line, or the solve's size, outcome and force). */
  bool
  kept(const std::string &line)
  {
    static const std::vector<std::string> keys  = {"source:",
                                                   "nodes:",
                                                   "tetrahedra:",
                                                   "bounding box:",
                                                   "quality:",
                                                   "fixed nodes:",
                                                   "active node:",
                                                   "probe tip:",
                                                   "model:",
                                                   "on:",
                                                   "off:",
                                                   "discretisation:",
                                                   "equations:",
                                                   "linear solver:",
                                                   "Newton steps:",
                                                   "converged:",
                                                   "force on probe:"};
    const auto                            first = line.find_first_not_of(' ');
    if (first == std::string::npos)
      return false;
    return std::any_of(keys.begin(), keys.end(), [&](const std::string &k) {
      return line.compare(first, k.size(), k) == 0;
    });
  }
} // namespace

int
main()
{
  initlog();

  // A surface meshed by palpate is meshed once and then reused: which of
  // the two this run did is not the scene's.
  const std::regex meshed_or_reused(R"( \((meshed now in [^)]*|reused)\))");
  for (const auto &scene : shipped_scenes())
    {
      const std::string name = scene.stem().string();
      const ProgramRun  r    = run_palpate("solve " + scene.string() +
                                       " --set 'Output/Directory=out-" + name +
                                       "' --set 'Output/Print timings=false'");
      deallog << scene.filename().string() << ": exit status " << r.exit_status
              << std::endl;
      std::istringstream in(r.output);
      std::string        line;
      while (std::getline(in, line))
        if (kept(line))
          deallog << std::regex_replace(line, meshed_or_reused, "")
                  << std::endl;
    }
}
