// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

// `palpate solve SCENE.prm` is a static solve whatever the scene's Run /
// Mode says (beam.prm leaves it at its default, an interaction): it reports
// the scene, solves for the prescribed displacement and prints the force,
// and runs no interaction. `--to` overrides the target.

#include "../tests.h"

int
main()
{
  initlog();
  const std::string beam = palpate_source_dir + "/parameters/beam.prm";
  for (const std::string &arguments :
       {"solve " + beam, "solve " + beam + " --to 0,0,-0.005"})
    {
      const ProgramRun r = run_palpate(arguments);
      deallog << "palpate " << arguments.substr(arguments.find("beam.prm"))
              << ": exit status " << r.exit_status << ", static solve "
              << (r.output.find("Static solve") != std::string::npos ? "yes" :
                                                                       "NO")
              << ", interaction "
              << (r.output.find("Interaction") != std::string::npos ? "YES" :
                                                                      "no")
              << std::endl;
      const auto at = r.output.find("force on probe:");
      if (at != std::string::npos)
        deallog << r.output.substr(at, r.output.find('\n', at) - at)
                << std::endl;
    }
  // A 1 cm sphere at the beam's tip pulled 5 mm away from the surface
  // (its outward normal there is (0.707, 0, 0.707)): accepted (a pull
  // presses it no deeper), 0 N, and said so.
  const ProgramRun r =
    run_palpate("solve " + beam +
                " --set 'Boundary conditions/Active node/Tip=sphere'"
                " --set 'Boundary conditions/Active node/Tip radius=0.01'"
                " --to 0.005,0,0.005");
  // Asking for help after a command (`palpate solve --help`, where --help
  // must not be read as the scene) or as a command of its own (`palpate
  // help`, `help solve`): the usage, exit 0.
  for (const std::string arguments :
       {"solve --help", "study -h", "mesh --help", "help", "help solve"})
    {
      const ProgramRun h = run_palpate(arguments);
      deallog << "palpate " << arguments << ": exit status " << h.exit_status
              << ", the usage "
              << (h.output.find("Usage:") != std::string::npos ? "yes" : "NO")
              << std::endl;
    }
  deallog << "a sphere pulled away: exit status " << r.exit_status
          << ", |f| = 0 "
          << (r.output.find("|f| = 0 N") != std::string::npos ? "yes" : "NO")
          << ", said "
          << (r.output.find("the sphere does not touch the surface") !=
                  std::string::npos ?
                "yes" :
                "NO")
          << std::endl;
}
