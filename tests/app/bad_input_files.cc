// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

// Bad input never crashes palpate: each case below runs the real program
// and must exit with status 2 (input error) and a message that names the
// file, the line if there is one, the entry, and what to do. Here: files:
// devices, huge and foreign meshes, links, the study's files, and the pushes
// and spheres the checks refuse.

#include <sys/stat.h>

#include "bad_input.h"

int
main(int argc, char **argv)
{
  palpate::Environment env(argc, argv);
  initlog();

  // The scene these cases start from (bad_input.cc checks it).
  write_file("good.prm", beam);

  // Files read whole are refused before any allocation when they cannot
  // be a mesh (issue 26): a device, a file of 600 MiB (sparse: no disk
  // used), a surface that is a device; and a mesh too big for this
  // machine's memory.
  make_link("/dev/zero", "zero.msh");
  run("a mesh file that is /dev/zero",
      "solve good.prm --set 'Mesh/Source=file' --set 'Mesh/File "
      "name=zero.msh'");
  {
    std::ofstream("huge.msh").close();
    std::filesystem::resize_file("huge.msh", std::uintmax_t(600) << 20);
  }
  run("a mesh file of 600 MiB",
      "solve good.prm --set 'Mesh/Source=file' --set 'Mesh/File "
      "name=huge.msh'");
  std::filesystem::remove("huge.msh");
  make_link("/dev/zero", "zero.obj");
  run("a surface file that is /dev/zero", "mesh zero.obj out.msh");
  // A legacy VTK surface whose POINTS count is 1e12: it ended in
  // std::bad_alloc (an internal error) before the count was checked.
  write_file("huge.vtk",
             "# vtk DataFile Version 3.0\nx\nASCII\nDATASET POLYDATA\n"
             "POINTS 1000000000000 float\n0 0 0\n");
  run("a VTK surface whose POINTS count is 1e12", "mesh huge.vtk out.msh");
  run("a mesh whose direct solve needs more memory than the machine has",
      "solve good.prm --set 'Mesh/Beam/Subdivisions=100,30,30' --set "
      "'Discretization/Polynomial degree=2'");

  // Messages that blamed the wrong thing (issue 26): a huge load blamed
  // the material, a wild coordinate a healthy element or the scale factor,
  // a push of a kilometre ended as a failure point.
  run("gravity of 1e6 m/s^2",
      "solve good.prm --set 'Effects/Gravity=true' --set "
      "'Effects/Gravitational acceleration=0,0,-1e6'");
  run("a traction of 1e9 Pa",
      "solve good.prm --set 'Effects/Surface traction=true' --set "
      "'Effects/Traction=0,0,-1e9'");
  run("solve --to 1000,0,0 (metres)", "solve good.prm --to 1000,0,0");
  {
    std::ifstream in(palpate_meshes_dir + "/liver-tetgen/liver501.msh");
    std::ofstream out("wild-node.msh");
    std::string   line;
    bool          first_node = false;
    while (std::getline(in, line))
      {
        if (first_node && line.find(' ') != std::string::npos)
          {
            line       = line.substr(0, line.find(' ')) + " 1e308 0 0";
            first_node = false;
          }
        if (line == "$Nodes")
          {
            out << line << "\n";
            std::getline(in, line); // the count
            first_node = true;
          }
        out << line << "\n";
      }
  }
  run("a mesh node at 1e308",
      "solve good.prm --set 'Mesh/Source=file' --set 'Mesh/File "
      "name=wild-node.msh' --set 'Mesh/Scale factor=0.039'");
  {
    std::ifstream in(palpate_meshes_dir + "/liver-tetgen/liver501-surface.obj");
    std::ofstream out("wild-vertex.obj");
    std::string   line;
    bool          done = false;
    while (std::getline(in, line))
      {
        if (!done && line.rfind("v ", 0) == 0)
          {
            line = "v 1e308 0 0";
            done = true;
          }
        out << line << "\n";
      }
  }
  run("a surface vertex at 1e308", "mesh wild-vertex.obj out.msh");

  // The lower bound is on the stiffness scale: a tiny C01 beside a
  // liver's C10 is a valid Mooney-Rivlin law (exit 0), both tiny is not.
  run("Mooney-Rivlin with C01 = 1e-4 Pa beside C10 = 2148 Pa (valid)",
      "--set 'Run/Mode=set-up only' " + palpate_source_dir +
        "/parameters/paper-mooney-rivlin.prm --set 'Material "
        "model/Mooney-Rivlin/C01=1e-4'");
  run("Mooney-Rivlin with C10 = C01 = 1e-5 Pa",
      palpate_source_dir +
        "/parameters/paper-mooney-rivlin.prm --set 'Material "
        "model/Mooney-Rivlin/C01=1e-5' --set 'Material "
        "model/Mooney-Rivlin/C10=1e-5'");

  // serve --host names the host, not the port (issue 26).
  run("serve --host 10.9.9.9 (not this machine's)",
      "serve good.prm --host 10.9.9.9");
  run("serve --host '' (empty)", "serve good.prm --host ''");
  run("serve --host with a space", "serve good.prm --host 'a b'");

  // study --finer-mesh with a file that is not a mesh: refused before the
  // reference solves, not after them.
  write_file("not-a-mesh.msh", "hello\n");
  run("study --finer-mesh with a file that is not a mesh",
      "study good.prm --quick --finer-mesh not-a-mesh.msh");

  // A scene that is a FIFO: refused, not waited on for ever.
  std::filesystem::remove("scene.fifo");
  if (mkfifo("scene.fifo", 0644) == 0)
    run("a scene that is a FIFO (named pipe)", "scene.fifo");

  // The scene itself a loop of links: not "does not exist".
  make_link("scene-loop.prm", "scene-loop.prm");
  run("a scene that is a loop of links", "scene-loop.prm");
  // A store whose name leaves no room for its lock file: not a full disk.
  run("a state store named with 250 characters",
      "precompute good.prm --set 'State space/Store=" + std::string(247, 's') +
        ".h5'");

  // Values a run would accept and then render nothing with (no motion,
  // no force, exit 0): refused before the run.
  scene("Haptics / Trajectory / Duration = 0 (no motion, 0 N, exit 0)",
        "duration-zero.prm",
        beam + "subsection Haptics\n  subsection Trajectory\n"
               "    set Duration = 0\n  end\nend\n");
  // Poisson's ratios inside their pattern but so near its ends that the
  // elements lock or the states fail to converge: refused with the bound.
  scene("St.Venant-Kirchhoff nu = 0.4999999 (3,817 N for a 1.6 N push)",
        "nu-locking.prm",
        beam + "subsection Material model\n  subsection St.Venant-Kirchhoff\n"
               "    set Poisson's ratio = 0.4999999\n  end\nend\n");
  scene("Neo-Hookean nu = -0.9999999 (every state failed, 0 N)",
        "nu-auxetic.prm",
        beam + "subsection Material model\n  set Model name = Neo-Hookean\n"
               "  subsection Neo-Hookean\n"
               "    set Poisson's ratio = -0.9999999\n  end\nend\n");
  // Neo-Hookean's lower bound is 0, not -0.9: with nu < 0 its energy has
  // no minimum once an element is crushed, so Newton fails well above -0.9.
  scene("Neo-Hookean nu = -0.8 (failure points: no energy minimum)",
        "nu-neo-hookean-negative.prm",
        beam + "subsection Material model\n  set Model name = Neo-Hookean\n"
               "  subsection Neo-Hookean\n"
               "    set Poisson's ratio = -0.8\n  end\nend\n");
  write_file("one-line.csv", "t, x, y, z\n0, 0, 0, 0\n");
  scene("a replay recording of one line (no motion, 0 N)",
        "replay-one-line.prm",
        interaction + beam_body +
          "subsection Haptics\n  subsection Trajectory\n"
          "    set Type = replay\n    set File name = one-line.csv\n"
          "  end\nend\n");
  {
    std::ofstream still("still.csv"), instant("instant.csv");
    for (unsigned int k = 0; k < 2000; ++k)
      {
        still << 0.001 * k << ", 0.01, 0.02, 0.03\n";
        instant << 1e-7 * k << ", 0, 0, " << -1e-7 * k << "\n";
      }
  }
  scene("a replay recording of 2,000 lines at one position",
        "replay-still.prm",
        interaction + beam_body +
          "subsection Haptics\n  subsection Trajectory\n"
          "    set Type = replay\n    set File name = still.csv\n"
          "  end\nend\n");
  scene("a replay recording of 2,000 lines within 0.2 ms",
        "replay-instant.prm",
        interaction + beam_body +
          "subsection Haptics\n  subsection Trajectory\n"
          "    set Type = replay\n    set File name = instant.csv\n"
          "  end\nend\n");
  scene("Engine / Server timeout = 1e308 s (servers outlived a killed rank 0)",
        "server-timeout.prm",
        beam + "subsection Engine\n  set Server timeout = 1e308\nend\n");
  write_file("flat.obj",
             "v 0 0 0\nv 0.1 0 0\nv 0 0.1 0\nv 0.1 0.1 0\n"
             "f 1 2 3\nf 1 4 2\nf 1 3 4\nf 2 4 3\n");
  run("a closed surface that encloses no volume (a flat tetrahedron)",
      "mesh flat.obj out.msh");
  write_file("point.obj",
             "v 0 0 0\nv 0 0 0\nv 0 0 0\nv 0 0 0\n"
             "f 1 2 3\nf 1 3 4\nf 1 4 2\nf 2 4 3\n");
  run("a surface of zero extent (the scale suggestion was inf)",
      "mesh point.obj out.msh");
  {
    std::ifstream in(palpate_meshes_dir + "/liver-tetgen/liver501-surface.obj");
    std::ofstream out("huge-units.obj");
    std::string   line;
    while (std::getline(in, line))
      {
        if (line.rfind("v ", 0) == 0)
          {
            std::istringstream v(line.substr(2));
            double             x, y, z;
            v >> x >> y >> z;
            out << "v " << x * 1e300 << " " << y * 1e300 << " " << z * 1e300
                << "\n";
          }
        else
          out << line << "\n";
      }
  }
  run("a surface with every coordinate times 1e300 (a healthy vertex was "
      "blamed)",
      "mesh huge-units.obj out.msh");

  // One parser for every whole number on the command line and in the
  // live view (Utilities::parse_whole_number).
  run("study --samples 12x (not a whole number)",
      "study good.prm --samples 12x");
  // More settings that run and render nothing (the probe at rest, no
  // frame, no limit at all): refused, or said.
  scene("Haptics / Trajectory / Speed = 0 (the probe held at rest, 0 N)",
        "speed-zero.prm",
        beam + "subsection Haptics\n  subsection Trajectory\n"
               "    set Speed = 0\n  end\nend\n");
  scene("Effects / Shape output limit = 0 MiB (no frame written, exit 0)",
        "shape-limit-zero.prm",
        beam + "subsection Effects\n  set Shape output = true\n"
               "  set Shape output limit = 0\nend\n");
  run("the shipped liver with a scale factor 1000 times too large (the "
      "suggestion must be the factor that fits the scene)",
      palpate_source_dir +
        "/parameters/liver-stvk.prm --set 'Mesh/Scale factor=39.146'");
  scene("Haptics / Force limit = 1e308 N (no limit at all)",
        "force-limit-huge.prm",
        beam + "subsection Haptics\n  set Force limit = 1e308\nend\n");
  scene("Haptics / Maximum force change above the force limit",
        "force-change-huge.prm",
        beam + "subsection Haptics\n  set Force limit = 8\n"
               "  set Maximum force change = 100\nend\n");
  run("serve --host with a port in it", "serve good.prm --host 127.0.0.1:80");
  run("serve --host given as a URL", "serve good.prm --host http://localhost/");
  run("serve --host: an IPv6 address with a port",
      "serve good.prm --host '[::1]:8080'");
  run("a 1 cm sphere on liver501, beside a node but smaller than the "
      "triangles around it",
      "solve '" + palpate_source_dir +
        "/parameters/liver-stvk.prm' --set 'Boundary conditions/Active "
        "node/Tip=sphere' --set 'Boundary conditions/Active node/Tip "
        "radius=0.01' --to 0,0,-0.01");
  // The depth check weighs the push that will be made: solve's --to, not
  // the scene's own prescribed displacement.
  run("a 5 mm sphere on the graded liver, pushed 2 cm by solve --to",
      "solve '" + palpate_source_dir +
        "/parameters/liver-indenter.prm' --set 'Boundary conditions/Active "
        "node/Tip radius=0.005' --set 'Boundary conditions/Active "
        "node/Prescribed displacement=0,0,-0.004' --to 0,0,-0.02");
  // Pushed 10 cm, no sphere radius converges: beyond 0.22 of the way to
  // the fixed nodes the message names the push as what to change, not the
  // radius.
  run("a 1 mm sphere on the graded liver, pushed 10 cm by solve --to",
      "solve '" + palpate_source_dir +
        "/parameters/liver-indenter.prm' --set 'Boundary conditions/Active "
        "node/Tip radius=0.001' --to 0,0,-0.1");
  // A stiff modulus is blamed, not the Poisson's ratio it is combined
  // with; a look-ahead of 1e9 s is refused; an output directory that is a
  // link to nowhere is named as such, not as "File exists".
  run("St.Venant-Kirchhoff's Young's modulus 1e12 Pa with nu = 0.49",
      "solve good.prm --set 'Material model/Model name=St.Venant-Kirchhoff' "
      "--set \"Material model/St.Venant-Kirchhoff/Poisson's ratio=0.49\" "
      "--set \"Material model/St.Venant-Kirchhoff/Young's modulus=1e12\"");
  // The modulus it names is accepted: the limit is rounded down when
  // printed (to nearest, a limit of 6.006e10 would be named 6.01e10, which
  // is refused again).
  run("St.Venant-Kirchhoff's Young's modulus 1e12 Pa with nu = 0.499",
      "good.prm --set 'Material model/Model name=St.Venant-Kirchhoff' --set "
      "\"Material model/St.Venant-Kirchhoff/Poisson's ratio=0.499\" --set "
      "\"Material model/St.Venant-Kirchhoff/Young's modulus=1e12\"");
  run("... with the modulus it names, 6e10 Pa",
      "good.prm --set 'Material model/Model name=St.Venant-Kirchhoff' --set "
      "\"Material model/St.Venant-Kirchhoff/Poisson's ratio=0.499\" --set "
      "\"Material model/St.Venant-Kirchhoff/Young's modulus=6e10\"");
  run("a look-ahead of 1e9 s",
      "good.prm --set 'Scheduler/Look-ahead time=1e9'");
  // Just over a limit, a value must not read as the limit (not "1e+13 Pa,
  // more than 1e+13 Pa"; a circle of radius 0.05000001 must not "go 0.1 m"
  // from rest, as if it fitted an extent of 0.1 m).
  run("a modulus that makes lambda just over 1e13 Pa",
      "good.prm --set 'Material model/Model name=St.Venant-Kirchhoff' --set "
      "\"Material model/St.Venant-Kirchhoff/Poisson's ratio=0.49\" --set "
      "\"Material model/St.Venant-Kirchhoff/Young's modulus=6.0817e11\"");
  run("a circle of radius 0.05000001 m in an extent of 0.1 m",
      "good.prm --set 'Haptics/Trajectory/Type=circle' --set "
      "'Haptics/Trajectory/Radius=0.05000001' --set 'State space/Extent=0.1'");
  make_link("no-such-target-out", "gone-out");
  run("Output / Directory a link to nowhere",
      "solve good.prm --set 'Output/Directory=gone-out' --set 'Effects/VTU "
      "export=true' --to 0,0,-0.001");
  make_link("loop-dir", "loop-dir");
  run("solve writing its VTU into a loop of links",
      "solve good.prm --set 'Output/Directory=loop-dir' --set 'Effects/VTU "
      "export=true' --to 0,0,-0.001");
  run("study --csv into a directory that does not exist",
      "study good.prm --quick --csv no-such-dir/study.csv");
  // Links to nowhere: "does not exist, mkdir -p" would be the wrong fix,
  // and a store that is such a link must not be replaced by a new file.
  make_link("no-such-target-dir", "gone-dir");
  make_link("no-such-target.csv", "gone.csv");
  make_link("no-such-target.h5", "gone.h5");
  make_link("no-such-target.prm", "gone.prm");
  run("study --csv in a directory that is a link to nowhere",
      "study good.prm --quick --csv gone-dir/study.csv");
  run("study --csv that is a link to nowhere",
      "study good.prm --quick --csv gone.csv");
  run("a state store that is a link to nowhere",
      "precompute good.prm --set 'State space/Store=gone.h5'");
  run("a state store in a directory that is a link to nowhere",
      "precompute good.prm --set 'State space/Store=gone-dir/x.h5'");
  run("a scene file that is a link to nowhere", "gone.prm");
  run("study --csv with an empty name", "study good.prm --quick --csv ''");
  run("study --csv - (standard output)", "study good.prm --quick --csv -");
  run("study --csv named like an option",
      "study good.prm --quick --csv -x.csv");
  run("study --csv of a blank", "study good.prm --quick --csv ' '");
  make_link("no-such-target.png", "beside.png");
  run("study --csv whose .png beside it is a link to nowhere",
      "study good.prm --quick --csv beside.csv");
  run("study --csv naming a directory with a trailing slash",
      "study good.prm --quick --csv new.csv/");
  // A value just over its limit must not read as the limit ("0.1 m
  // radius ... at most 0.1 m").
  run("a sphere of 0.1000001 m radius, just over the largest",
      "solve good.prm --set 'Boundary conditions/Active node/Tip=sphere' "
      "--set 'Boundary conditions/Active node/Tip radius=0.1000001'");
  run("a push just longer than liver501 is across",
      "solve '" + palpate_source_dir +
        "/parameters/liver-stvk.prm' --to 0,0,-0.35677");
  // At rest a sphere radius is offered only if it passes the checks at
  // all 26 grid points around rest: the first radius tried does, so the
  // message names a radius (the scene's own 0.01 m converges there)
  // rather than none.
  run("a 1 mm sphere at rest at Node id 38 of the graded liver",
      "'" + palpate_source_dir +
        "/parameters/liver-indenter.prm' --set 'State space/Store=' --set "
        "'Boundary conditions/Active node/Selection=node id' --set "
        "'Boundary conditions/Active node/Node id=38' --set 'Boundary "
        "conditions/Active node/Tip radius=0.001' --set 'Boundary "
        "conditions/Active node/Prescribed displacement=0,0,0' --set "
        "'Run/Mode=set-up only'");

  summary();
}
