// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

// Bad input never crashes palpate: each case below runs the real program
// and must exit with status 2 (input error) and a message that names the
// file, the line if there is one, the entry, and what to do. Here: extremes:
// numbers that are valid but not physical, limits, paths and --set on the
// command line (the scenes they start from are made again here; bad_input.cc
// checks them).

#include "bad_input.h"

int
main(int argc, char **argv)
{
  palpate::Environment env(argc, argv);
  initlog();

  // The scenes these cases start from (bad_input.cc checks them).
  write_file("good.prm", beam);
  write_file("unclosed.prm", "subsection Mesh\n  set Source = beam\n");

  // Extremes inside each entry's pattern: each must be refused by its own
  // entry's check, not blamed on another entry or run with nonsense.
  scene("a beam 1e-300 m wide (blamed a flat generated element)",
        "beam-thin.prm",
        beam + "subsection Mesh\n  subsection Beam\n"
               "    set Width = 1e-300\n  end\nend\n");
  scene("a glued tip of 1e300 m radius (glued the whole surface)",
        "glued-huge.prm",
        beam + "subsection Boundary conditions\n  subsection Active node\n"
               "    set Tip = glued nodes\n    set Tip radius = 1e300\n"
               "  end\nend\n");
  scene("nu = 0.49999999999999994 (1.7e12 N for 1 cm)",
        "nu-half.prm",
        beam + "subsection Material model\n"
               "  subsection St.Venant-Kirchhoff\n"
               "    set Poisson's ratio = 0.49999999999999994\n  end\nend\n");
  scene("Server timeout 0.1 s, the heartbeat period (healthy servers lost)",
        "server-timeout.prm",
        beam + "subsection Engine\n  set Server timeout = 0.1\nend\n");
  {
    std::string       far   = beam;
    const std::string point = "    set Point = 0.1, 0, 0.01\n";
    far.replace(far.find(point),
                point.size(),
                "    set Point = 1e300, 0, 0.01\n");
    scene("an active node Point 1e300 m away (an arbitrary node, 'inf mm')",
          "point-far.prm",
          far);
  }
  run("mesh --refine 100 m from the organ (refined nothing, silently)",
      "mesh " + palpate_source_dir +
        "/meshes/liver-tetgen/liver501-surface.obj far.msh --scale 0.039146 "
        "--refine 100,0,0 --fine-size 0.002");
  run("study --csv naming a directory (found after the first knob)",
      "study good.prm --quick --csv .");
  scene("an entry name with a different case",
        "case.prm",
        beam + "subsection Mesh\n  set scale factor = 1\nend\n");
  // Numbers that set a loop count, an allocation or a time are bounded
  // (issue 26): each of these hung, overflowed or gave NaN with exit 0.
  scene("a circle of radius 0",
        "circle-zero.prm",
        beam + "subsection Haptics\n  subsection Trajectory\n"
               "    set Type = circle\n    set Radius = 0\n  end\nend\n");
  scene("Memory budget = 1e14 MiB",
        "budget-huge.prm",
        beam + "subsection Engine\n  set Memory budget = 1e14\nend\n");
  scene("Young's modulus = 1e-200 Pa",
        "young-tiny.prm",
        beam + "subsection Material model\n"
               "  subsection St.Venant-Kirchhoff\n"
               "    set Young's modulus = 1e-200\n"
               "  end\nend\n");
  scene("Loop rate = 1e-9 Hz",
        "loop-slow.prm",
        beam + "subsection Haptics\n  set Loop rate = 1e-9\nend\n");
  scene("Number of increments = 1000000000",
        "increments.prm",
        beam + "subsection Nonlinear solver\n"
               "  set Number of increments = 1000000000\nend\n");
  scene("Maximum Newton iterations = 1000000000",
        "iterations.prm",
        beam + "subsection Nonlinear solver\n"
               "  set Maximum Newton iterations = 1000000000\n"
               "  set Residual tolerance = 1e-12\nend\n");
  scene("Maximum line search steps = 1000000000",
        "line-search.prm",
        beam + "subsection Nonlinear solver\n"
               "  set Maximum line search steps = 1000000000\nend\n");
  scene("Maximum cutbacks = 1000000000",
        "cutbacks.prm",
        beam + "subsection Nonlinear solver\n"
               "  set Maximum cutbacks = 1000000000\nend\n");
  scene("Shape output limit = 1e303 MiB",
        "shape-limit.prm",
        beam + "subsection Effects\n  set Shape output = true\n"
               "  set Shape output limit = 1e303\nend\n");
  scene("a smooth random motion of radius 1e308 m",
        "random-radius.prm",
        beam + "subsection Haptics\n  subsection Trajectory\n"
               "    set Type = smooth random\n    set Radius = 1e308\n"
               "  end\nend\n");
  scene("Shape output rate = 1e-15 Hz",
        "shape-rate.prm",
        beam + "subsection Effects\n  set Shape output = true\n"
               "  set Shape output rate = 1e-15\nend\n");
  // Tolerances that make every state wrong or every state a failure point,
  // increments too short to reach anything, a density in g/cm^3 x 1e6.
  scene("Residual tolerance = 1",
        "tolerance-loose.prm",
        beam + "subsection Nonlinear solver\n"
               "  set Residual tolerance = 1\nend\n");
  scene("Residual tolerance = 1e-300",
        "tolerance-tight.prm",
        beam + "subsection Nonlinear solver\n"
               "  set Residual tolerance = 1e-300\nend\n");
  scene("Increment tolerance = 0.5",
        "increment-tolerance.prm",
        beam + "subsection Nonlinear solver\n"
               "  set Increment tolerance = 0.5\nend\n");
  scene("Maximum increment length = 1e-9",
        "increment-length.prm",
        beam + "subsection Nonlinear solver\n"
               "  set Maximum increment length = 1e-9\nend\n");
  scene("Density = 1e9",
        "density.prm",
        beam + "subsection Material model\n"
               "  set Density = 1e9\nend\n");
  // Values that would let a run render no force and still exit 0: each is
  // refused before the run.
  scene("Scheduler / Rate = 1e-9 Hz",
        "scheduler-rate.prm",
        beam + "subsection Scheduler\n  set Rate = 1e-9\nend\n");
  scene("Haptics / Maximum force change = 1e-300 N",
        "force-change.prm",
        beam + "subsection Haptics\n  set Maximum force change = 1e-300\n"
               "end\n");
  scene("Mooney-Rivlin Stabilization factor = 1e308",
        "stabilization.prm",
        beam + "subsection Material model\n  set Model name = Mooney-Rivlin\n"
               "  subsection Mooney-Rivlin\n"
               "    set Stabilization factor = 1e308\n  end\nend\n");
  scene("a density in g/cm^3 (1.06)",
        "density-g-cm3.prm",
        beam + "subsection Material model\n  set Density = 1.06\nend\n");
  scene("an unstable Yeoh law (C20 = -1e9 Pa)",
        "yeoh-unstable.prm",
        beam + "subsection Material model\n  set Model name = Yeoh\n"
               "  subsection Yeoh\n    set C20 = -1e9\n  end\nend\n");
  {
    // The beam scene with its Point moved between nodes and a tiny sphere.
    std::string       small_sphere = beam;
    const std::string point        = "    set Point = 0.1, 0, 0.01\n";
    small_sphere.replace(small_sphere.find(point),
                         point.size(),
                         "    set Point = 0.055, 0.004, 0.01\n"
                         "    set Tip = sphere\n    set Tip radius = 0.0001\n");
    scene("a sphere probe smaller than the gaps between surface nodes",
          "small-sphere.prm",
          small_sphere);
  }
  // Paths the file system refuses: a link to itself.
  make_link("loop", "loop");
  scene("an output directory that is a loop of links",
        "outdir-loop.prm",
        interaction + beam_body +
          "subsection Output\n  set Directory = loop\nend\n"
          "subsection Effects\n  set Force log = true\nend\n");
  scene("a state store that is a loop of links",
        "store-loop.prm",
        interaction + beam_body +
          "subsection State space\n  set Store = loop\nend\n");
  make_link("loop.obj", "loop.obj");
  scene("a surface file that is a loop of links (Source = surface)",
        "surface-loop.prm",
        interaction + "subsection Mesh\n  set Source = surface\n"
                      "  set File name = loop.obj\nend\n");
  run("a surface file that is a loop of links (palpate mesh)",
      "mesh loop.obj out.msh");
  // The study's table is read back by its plot: a device would be read
  // without end (the study hung after a stop).
  run("a study CSV that is a device", "study good.prm --quick --csv /dev/zero");
  run("a study CSV that is a loop of links",
      "study good.prm --quick --csv loop");
  run("a study CSV that is the scene itself (it would be overwritten)",
      "study good.prm --quick --csv good.prm");
  run("a study CSV named .png (the plot would overwrite it)",
      "study good.prm --quick --csv study.png");
  write_file("photo.png", "not a plot\n");
  run("a study CSV whose .png beside it is not a plot (it would be "
      "overwritten)",
      "study good.prm --quick --csv photo.csv");
  run("a study CSV in a 'directory' that is a file",
      "study good.prm --quick --csv good.prm/study.csv");
  run("a study CSV in a directory that is a loop of links",
      "study good.prm --quick --csv loop/study.csv");
  run("'solve' without a scene", "solve");
  run("'solve --to' with two numbers", "solve good.prm --to 0,0");
  run("'solve --to' without its value", "solve good.prm --to");
  run("'solve --to' given twice",
      "solve good.prm --to 0,0,-0.01 --to 0,0,-0.02");
  run("'serve --port' given twice", "serve good.prm --port 8080 --port 8081");
  run("an unexpected second argument", "good.prm other.prm");
  run("a mistyped command", "slove good.prm");
  run("a mistyped command alone", "slove");
  write_file("good.obj",
             "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\n"
             "f 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n");
  make_link("no-such-dir/organ.msh", "gone.msh");
  run("palpate mesh writing through a link to nowhere",
      "mesh good.obj gone.msh");
  write_file("notes.msh", "my notes, not a mesh\n");
  run("palpate mesh overwriting a file that is no mesh",
      "mesh good.obj notes.msh");
  // Scene variants on the command line (--set): checked like a line of
  // the file, and named in the message.
  run("--set with a misspelled entry",
      "good.prm --set 'Material model/St.Venant-Kirchhoff/Youngs "
      "modulus=1e5'");
  run("--set with a value its pattern refuses",
      "good.prm --set 'Material model/Model name=Neo-Hookan'");
  run("--set without '='", "good.prm --set 'Run/Mode'");
  run("--set of one entry twice",
      "good.prm --set 'Run/Mode=set-up only' --set 'Run/Mode=interaction'");
  run("--set that makes the scene wrong (nu = 0.5)",
      "solve good.prm --set \"Material model/St.Venant-Kirchhoff/Poisson's "
      "ratio=0.5\"");
  run("--set with a command that reads no scene",
      "mesh surface.stl out.msh --set 'Run/Mode=set-up only'");
  run("--set without its value", "good.prm --set");
  run("--set of a mesh file while Source = beam",
      "good.prm --set 'Mesh/File name=liver.msh'");
  run("--set on a file whose subsection is never closed",
      "unclosed.prm --set 'Run/Mode=set-up only'");

  summary();
}
