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
}
