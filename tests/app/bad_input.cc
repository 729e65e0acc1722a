// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

// Bad input never crashes palpate: each case below runs the real program
// and must exit with status 2 (input error) and a message that names the
// file, the line if there is one, the entry, and what to do. Here: scene files:
// their grammar, entries, meshes, trajectories and numbers (bad_input_limits.cc
// and bad_input_files.cc have the rest, bad_input.h what they share).

#include "bad_input.h"

#include <palpate/state_space/state_store.h>

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
    std::ifstream in(palpate_meshes_dir + "/liver-tetgen/liver501.msh");
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
        interaction + beam_body + "subsection Engine\n  set Type = mpi\nend\n");
  write_file("path.csv", "t, x, y, z\n0, 0, 0, 0\n0.1, 0.001, 0\n");
  scene("a replay trajectory file with a bad line",
        "replay.prm",
        interaction + beam_body +
          "subsection Haptics\n  subsection Trajectory\n"
          "    set Type = replay\n    set File name = path.csv\n  end\nend\n");
  // A NaN time was taken for a header line and dropped without a word.
  write_file("nan.csv", "0, 0, 0, 0\nnan, 0, 0, 0\n0.002, 0, 0, 0\n");
  scene("a replay trajectory with a NaN time",
        "replay-nan.prm",
        interaction + beam_body +
          "subsection Haptics\n  subsection Trajectory\n"
          "    set Type = replay\n    set File name = nan.csv\n  end\nend\n");
  scene("a replay trajectory that is /dev/zero",
        "replay-zero.prm",
        interaction + beam_body +
          "subsection Haptics\n  subsection Trajectory\n"
          "    set Type = replay\n    set File name = /dev/zero\n  end\nend\n");
  // State space / Interpolation = contact patch needs a sphere, and a
  // store that keeps patches.
  const std::string patch =
    "good.prm --set 'State space/Interpolation=contact patch'";
  const std::string sphere =
    " --set 'Boundary conditions/Active node/Tip=sphere' --set "
    "'Boundary conditions/Active node/Tip radius=0.02'";
  run("contact patch with a point probe", patch);
  // A store made for another interpolation keeps no patches.
  {
    const Body hermite(palpate::Scene::read(
      "good.prm",
      {"State space/Interpolation=tricubic Hermite",
       "Boundary conditions/Active node/Tip=sphere",
       "Boundary conditions/Active node/Tip radius=0.02"}));
    std::filesystem::remove("hermite.h5");
    const palpate::StateStore made(
      "hermite.h5",
      palpate::StoreFingerprint::of(hermite.scene,
                                    hermite.mesh,
                                    hermite.nodes));
  }
  run("contact patch with a store made for tricubic Hermite",
      patch + sphere +
        " --set 'State space/Store=hermite.h5' --set 'Run/Mode=interaction'");
  run("a scene file that does not exist", "no-such-scene.prm");
  run("an unknown option", "--frobnicate");

  // Issue 11: each of these once crashed, hung, or ran with nonsense.
  std::filesystem::create_directories("scenes/sub");
  write_file("scenes/a.prm", beam);
  run("a directory given as the scene", "scenes");
  scene("Haptics / Loop rate = 1e9 (once: std::bad_alloc)",
        "loop-rate.prm",
        beam + "subsection Haptics\n  set Loop rate = 1e9\nend\n");
  scene("a trajectory Duration = 1e12 s (once: std::bad_alloc)",
        "duration.prm",
        beam + "subsection Haptics\n  subsection Trajectory\n"
               "    set Duration = 1e12\n  end\nend\n");
  write_file("ms.csv", "t, x, y, z\n0, 0, 0, 0\n5000000, 0, 0, -0.001\n");
  scene("a replay recording of 5e6 s (its times in ms?)",
        "replay-long.prm",
        interaction + beam_body +
          "subsection Haptics\n  subsection Trajectory\n"
          "    set Type = replay\n    set File name = ms.csv\n  end\nend\n");
  {
    // Two hours of strokes at 5 mm/s, a position every 0.25 s: a real
    // motion, but longer than the loop preallocates for.
    std::string two_hours = "t, x, y, z\n";
    for (unsigned int k = 0; k <= 28800; ++k)
      two_hours += std::to_string(0.25 * k) + ", 0, 0, " +
                   (k % 4 == 0 ? "0" :
                    k % 4 == 2 ? "-0.005" :
                                 "-0.0025") +
                   "\n";
    write_file("two-hours.csv", two_hours);
  }
  scene("a replay recording of two hours",
        "replay-two-hours.prm",
        interaction + beam_body +
          "subsection Haptics\n  subsection Trajectory\n"
          "    set Type = replay\n    set File name = two-hours.csv\n  "
          "end\nend\n");
  write_file("far.csv", "t, x, y, z\n0, 0, 0, 0\n1, 0, 0, 1e308\n");
  scene("a replay position at 1e308 m",
        "replay-far.prm",
        interaction + beam_body +
          "subsection Haptics\n  subsection Trajectory\n"
          "    set Type = replay\n    set File name = far.csv\n  end\nend\n");
  write_file("mm.csv", "t, x, y, z\n0, 0, 0, 0\n0.001, 0, 0, -0.5\n");
  scene("a replay jump of 0.5 m in 1 ms (500 m/s)",
        "replay-fast.prm",
        interaction + beam_body +
          "subsection Haptics\n  subsection Trajectory\n"
          "    set Type = replay\n    set File name = mm.csv\n  end\nend\n");
  {
    // A 99 ms stroke written in milliseconds, a line per ms: read as
    // seconds it would run as a 99 s motion, so the unit is questioned.
    std::string ms = "t, x, y, z\n";
    for (unsigned int k = 0; k < 100; ++k)
      ms += std::to_string(k) + ", 0, 0, " + std::to_string(-0.0002 * k) + "\n";
    write_file("short-ms.csv", ms);
  }
  scene("a 99 ms stroke with its times in milliseconds",
        "replay-short-ms.prm",
        interaction + beam_body +
          "subsection Haptics\n  subsection Trajectory\n"
          "    set Type = replay\n    set File name = short-ms.csv\n  "
          "end\nend\n");
  write_file("metres-far.csv", "t, x, y, z\n0, 0, 0, 0\n30, 0, 0, -0.9\n");
  scene("a replay moving 0.9 m over a 10 cm beam (a unit mistake)",
        "replay-beyond.prm",
        interaction + beam_body +
          "subsection Haptics\n  subsection Trajectory\n"
          "    set Type = replay\n    set File name = metres-far.csv\n  "
          "end\nend\n");
  scene("a straight line of 0.5 m over a 10 cm beam",
        "line-beyond.prm",
        interaction + beam_body +
          "subsection Haptics\n  subsection Trajectory\n"
          "    set Speed = 0.05\n    set Duration = 10\n  end\nend\n");
  scene("Engine / Workers = 1000 (once: accepted, 1,400 deadline misses)",
        "workers.prm",
        beam + "subsection Engine\n  set Workers = 1000\nend\n");
  scene("Nonlinear solver / Assembly threads = 1000",
        "assembly.prm",
        beam + "subsection Nonlinear solver\n  set Assembly threads = 1000\n"
               "end\n");
  scene("Cloud radius beyond the grid (once: a silent 120 s stall)",
        "cloud.prm",
        beam + "subsection Scheduler\n  set Cloud radius = 0.2\nend\n");
  scene("a memory budget that cannot hold the cloud (once: thrashing)",
        "budget.prm",
        interaction + beam_body +
          "subsection Engine\n  set Memory budget = 1\nend\n"
          "subsection Scheduler\n  set Cloud radius = 0.1\nend\n");
  scene("an entry set twice (once: the last silently won)",
        "twice.prm",
        beam + "subsection Run\n  set Mode = interaction\nend\n");
  scene("a NUL byte in a line (once: the message was cut off)",
        "nul.prm",
        beam +
          std::string("subsection Mesh\n  set Scale fac\0tor = 1\nend\n", 42));
  scene("Beam / Length = 0 (once: blamed on the beam generator)",
        "beam-length.prm",
        beam + "subsection Mesh\n  subsection Beam\n    set Length = 0\n"
               "  end\nend\n");
  scene("a trajectory Speed = 1e6 m/s (once: accepted)",
        "speed.prm",
        beam + "subsection Haptics\n  subsection Trajectory\n"
               "    set Speed = 1e6\n  end\nend\n");
  scene("an output directory that is a file",
        "outdir.prm",
        interaction + beam_body +
          "subsection Output\n  set Directory = good.prm/out\nend\n"
          "subsection Effects\n  set Force log = true\nend\n");

  // The parser is deal.II's: continuation lines and Windows line ends are
  // read as deal.II reads them (both scenes are fine).
  scene("a value continued on the next line (fine)",
        "continued.prm",
        beam + "subsection Material model\n"
               "  subsection St.Venant-Kirchhoff\n"
               "    set Young's modulus = \\\n      20000\n  end\nend\n");
  scene("Windows line ends (fine)",
        "crlf.prm",
        "subsection Run\r\n  set Mode = set-up only\r\nend\r\n");

  // The grammar of a scene file.
  scene("'end' without a subsection", "end.prm", beam + "end\n");
  scene("a set line without '='",
        "set.prm",
        beam + "subsection Mesh\n  set Scale factor 2\nend\n");
  scene("an include line", "include.prm", "include other.prm\n" + beam);
  scene("a line that is no statement", "junk.prm", beam + "hello world\n");
  // The first bytes of an executable, as when a binary is given by mistake.
  write_file("binary",
             std::string("\x7f"
                         "ELF\x02\x01\x01\0\0\0\0\0",
                         12));
  run("a binary file given as the scene", "binary");

  // Values that are numbers but not physical.
  scene("a negative Young's modulus",
        "young.prm",
        beam + "subsection Material model\n"
               "  subsection St.Venant-Kirchhoff\n"
               "    set Young's modulus = -5\n  end\nend\n");
  scene("Young's modulus = nan",
        "young-nan.prm",
        beam + "subsection Material model\n"
               "  subsection St.Venant-Kirchhoff\n"
               "    set Young's modulus = nan\n  end\nend\n");
  scene("Mooney-Rivlin with C10 + C01 = 0",
        "mr.prm",
        beam + "subsection Material model\n"
               "  set Model name = Mooney-Rivlin\n"
               "  subsection Mooney-Rivlin\n    set C10 = 0\n    set C01 = 0\n"
               "  end\nend\n");
  scene("Mooney-Rivlin P1-P1 with quadratic displacements",
        "mr-degree.prm",
        beam + "subsection Material model\n"
               "  set Model name = Mooney-Rivlin\nend\n"
               "subsection Discretization\n  set Polynomial degree = 2\nend\n");
  scene("Mesh / Scale factor = 0",
        "scale.prm",
        beam + "subsection Mesh\n  set Scale factor = 0\nend\n");
  scene("a beam of 1e9 nodes",
        "subdivisions.prm",
        beam + "subsection Mesh\n  subsection Beam\n"
               "    set Subdivisions = 1000, 1000, 1000\n  end\nend\n");
  scene("a blob with a zero semi-axis",
        "blob.prm",
        setup + "subsection Mesh\n  subsection Blob\n"
                "    set Semi-axes = 0.1, 0, 0.05\n  end\nend\n");
  scene("an empty fixed-node box",
        "box.prm",
        setup + "subsection Boundary conditions\n  subsection Fixed nodes\n"
                "    set Selection = box\n    set Box lower corner = 0, 0, 0\n"
                "    set Box upper corner = 1, 0, 1\n  end\nend\n");
  scene("a zero half-space normal",
        "normal.prm",
        setup + "subsection Boundary conditions\n  subsection Fixed nodes\n"
                "    set Half-space normal = 0, 0, 0\n  end\nend\n");
  scene("an empty fixed-node list",
        "node-list.prm",
        setup + "subsection Boundary conditions\n  subsection Fixed nodes\n"
                "    set Selection = node list\n  end\nend\n");
  scene("a grid spacing larger than the extent",
        "grid.prm",
        beam + "subsection State space\n  set Grid spacing = 0.2\nend\n");
  scene("a state space of 1e9 grid points",
        "extent.prm",
        beam + "subsection State space\n  set Extent = 5\nend\n");
  scene("a cloud too small for one cell",
        "cloud-small.prm",
        beam + "subsection Scheduler\n  set Cloud radius = 0.001\nend\n");
  scene("Scheduler / Rate = 1e9",
        "scheduler-rate.prm",
        beam + "subsection Scheduler\n  set Rate = 1e9\nend\n");
  scene("Haptics / Force limit = 0",
        "force-limit.prm",
        beam + "subsection Haptics\n  set Force limit = 0\nend\n");
  scene("a zero trajectory direction",
        "direction.prm",
        beam + "subsection Haptics\n  subsection Trajectory\n"
               "    set Direction = 0, 0, 0\n  end\nend\n");
  scene("a replay trajectory without a file",
        "replay-none.prm",
        beam + "subsection Haptics\n  subsection Trajectory\n"
               "    set Type = replay\n  end\nend\n");
  scene("Shape output at 1e6 Hz",
        "shape-rate.prm",
        beam + "subsection Effects\n  set Shape output = true\n"
               "  set Shape output rate = 1e6\nend\n");
  write_file("empty.msh", "");
  scene("an empty mesh file",
        "empty-mesh.prm",
        setup + "subsection Mesh\n  set Source = file\n"
                "  set File name = empty.msh\nend\n");
  scene("a mesh file that is a directory",
        "dir-mesh.prm",
        setup + "subsection Mesh\n  set Source = file\n"
                "  set File name = scenes\nend\n");
  scene("a mesh file of an unknown format",
        "format-mesh.prm",
        setup + "subsection Mesh\n  set Source = file\n"
                "  set File name = good.prm\nend\n");
  scene(
    "the liver mesh read in the wrong unit (scale factor 1)",
    "liver-mm.prm",
    setup +
      "subsection Mesh\n  set Source = file\n"
      "  set File name = " +
      palpate_meshes_dir +
      "/liver-tetgen/liver501.msh\nend\n"
      "subsection Boundary conditions\n  subsection Fixed nodes\n"
      "    set Selection = box\n    set Box lower corner = -1e9, -1e9, -1e9\n"
      "    set Box upper corner = 1e9, 1e9, -1\n  end\nend\n");
  scene("Young's modulus = 1e300 (once: 'converged' with a NaN residual)",
        "young-huge.prm",
        beam + "subsection Material model\n"
               "  subsection St.Venant-Kirchhoff\n"
               "    set Young's modulus = 1e300\n  end\nend\n");
  scene("a number below the double range (1e-320)",
        "denormal.prm",
        beam + "subsection Mesh\n  set Scale factor = 1e-320\nend\n");
  scene("a liver at Scale factor 1e-300 (blamed a flat element)",
        "liver-scale-tiny.prm",
        "subsection Mesh\n  set Source = file\n"
        "  set File name = inverted-liver.msh\n"
        "  set Scale factor = 1e-300\nend\n");
  scene("a liver at Scale factor 1.7e308 (a body -nan m across)",
        "liver-scale-huge.prm",
        "subsection Mesh\n  set Source = file\n"
        "  set File name = inverted-liver.msh\n"
        "  set Scale factor = 1.7e308\nend\n");

  summary();
}
