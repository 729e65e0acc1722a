// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

// Bad input never crashes palpate: each case below runs the real program
// and must exit with status 2 (input error) and a message that names the
// file, the line if there is one, the entry, and what to do.

#include <fstream>
#include <sstream>

#include "../tests.h"

namespace
{
  const std::string beam = "subsection Run\n  set Mode = set-up only\nend\n"
                           "subsection Mesh\n  set Source = beam\nend\n"
                           "subsection Boundary conditions\n"
                           "  subsection Fixed nodes\n"
                           "    set Selection = boundary id\n"
                           "    set Boundary ids = 0\n"
                           "  end\n"
                           "  subsection Active node\n"
                           "    set Point = 0.1, 0, 0.01\n"
                           "  end\n"
                           "end\n";

  void
  run(const std::string &what, const std::string &arguments)
  {
    const ProgramRun r = run_palpate(arguments);
    deallog << "=== " << what << ": exit status " << r.exit_status << std::endl;
    // Only the message: the report lines before it are tested elsewhere.
    const auto  start = r.output.find("palpate:");
    std::string message =
      start == std::string::npos ? r.output : r.output.substr(start);
    while (!message.empty() && message.back() == '\n')
      message.pop_back();
    deallog << message << std::endl;
  }

  void
  scene(const std::string &what,
        const std::string &file,
        const std::string &text)
  {
    write_file(file, text);
    run(what, file);
  }
} // namespace

int
main(int argc, char **argv)
{
  palpate::Environment env(argc, argv);
  initlog();

  scene("the beam scene itself is fine", "good.prm", beam);

  scene("a misspelled entry",
        "misspelled.prm",
        beam + "subsection Material model\n"
               "  subsection St.Venant-Kirchhoff\n"
               "    set Youngs modulus = 1e5\n"
               "  end\nend\n");
  scene("an unknown subsection",
        "subsection.prm",
        beam + "subsection Materials\n  set Model name = Neo-Hookean\nend\n");
  scene("an unknown model name",
        "model.prm",
        beam + "subsection Material model\n"
               "  set Model name = St.Venant-Kirchof\nend\n");
  scene("a number that is not one",
        "number.prm",
        "subsection Mesh\n  set Scale factor = one\nend\n");
  scene("a subsection never closed",
        "unclosed.prm",
        "subsection Mesh\n  set Source = beam\n");
  scene("Poisson's ratio 0.5 for St.Venant-Kirchhoff",
        "nu.prm",
        beam + "subsection Material model\n"
               "  subsection St.Venant-Kirchhoff\n"
               "    set Poisson's ratio = 0.5\n"
               "  end\nend\n");
  scene("a missing mesh file",
        "missing-mesh.prm",
        "subsection Mesh\n  set Source = file\n"
        "  set File name = meshes/missing.msh\nend\n");
  scene("a region that selects no fixed node",
        "no-fixed.prm",
        "subsection Mesh\n  set Source = beam\nend\n"
        "subsection Boundary conditions\n"
        "  subsection Fixed nodes\n"
        "    set Selection = box\n"
        "    set Box lower corner = 1, 1, 1\n"
        "    set Box upper corner = 2, 2, 2\n"
        "  end\nend\n");
  scene("an active node that is fixed",
        "active-fixed.prm",
        beam.substr(0, beam.find("  subsection Active node")) +
          "  subsection Active node\n    set Point = 0, 0, 0.01\n  end\nend\n");
  scene("an active node inside the body",
        "active-interior.prm",
        "subsection Run\n  set Mode = set-up only\nend\n"
        "subsection Mesh\n  set Source = beam\nend\n"
        "subsection Boundary conditions\n"
        "  subsection Fixed nodes\n"
        "    set Selection = boundary id\n    set Boundary ids = 0\n  end\n"
        "  subsection Active node\n"
        "    set Selection = node id\n    set Node id = 45\n  end\nend\n");

  // The shared liver with one tetrahedron's last two nodes swapped.
  {
    std::ifstream in(palpate_shared_dir + "/meshes/liver-tetgen/liver501.msh");
    std::ofstream out("inverted-liver.msh");
    std::string   line;
    bool          elements = false, done = false;
    while (std::getline(in, line))
      {
        if (line == "$Elements")
          elements = true;
        std::istringstream       s(line);
        std::vector<std::string> t;
        std::string              w;
        while (s >> w)
          t.push_back(w);
        if (elements && !done && t.size() == 9 && t[1] == "4")
          {
            std::swap(t[7], t[8]);
            line = t[0];
            for (unsigned int i = 1; i < t.size(); ++i)
              line += " " + t[i];
            done = true;
          }
        out << line << "\n";
      }
  }
  scene("a mesh with an inverted tetrahedron",
        "inverted.prm",
        "subsection Mesh\n  set Source = file\n"
        "  set File name = inverted-liver.msh\n"
        "  set Scale factor = 0.039146\nend\n");

  scene("the MPI engine without mpirun (exit status 2)",
        "mpi.prm",
        beam + "subsection Engine\n  set Type = mpi\nend\n"
               "subsection Run\n  set Mode = interaction\nend\n");
  write_file("path.csv", "t, x, y, z\n0, 0, 0, 0\n0.1, 0.001, 0\n");
  scene("a replay trajectory file with a bad line",
        "replay.prm",
        beam +
          "subsection Haptics\n  subsection Trajectory\n"
          "    set Type = replay\n    set File name = path.csv\n  end\nend\n"
          "subsection Run\n  set Mode = interaction\nend\n");
  run("a scene file that does not exist", "no-such-scene.prm");
  run("an unknown option", "--frobnicate");
}
