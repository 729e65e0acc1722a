// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

// Plausibility checks that name the likely mistake (issue 14), through the
// palpate program as a user meets them:
// - an active-node point 2 cm from a 10 cm beam: a warning; 0.5 m from it:
//   an input error (more than a quarter of the body's size: not on it);
// - a push whose force is far beyond the device's limit (E = 1e7 Pa, 5 cm
//   push): palpate solve warns and names the likely slips;
// - a File name while Source = beam: an input error;
// - a surface file with Source = file: an input error naming Source =
//   surface;
// - a trajectory that leaves the state space: a warning with the extent
//   to set;
// - a trajectory that pushes a sphere deeper than its set-up checks
//   weighed: a warning with their problem and fix;
// - palpate mesh on a surface in millimetres with the default scale: an
//   input error that says "millimetres: set 0.001".

#include <palpate/mesh/surface.h>

#include "../tests.h"

namespace
{
  /** @p text with @p from replaced by @p to (which must be there). */
  std::string
  replaced(std::string text, const std::string &from, const std::string &to)
  {
    const auto at = text.find(from);
    AssertThrow(at != std::string::npos, dealii::ExcMessage(from));
    return text.replace(at, from.size(), to);
  }

  /** The first line of @p output holding @p key, or "(none)". */
  std::string
  line_with(const std::string &output, const std::string &key)
  {
    const auto at = output.find(key);
    if (at == std::string::npos)
      return "(none)";
    const auto begin = output.rfind('\n', at) + 1;
    return output.substr(begin, output.find('\n', at) - begin);
  }
} // namespace

int
main()
{
  initlog();
  const std::string beam =
    read_file(palpate_source_dir + "/parameters/beam.prm");

  write_file("far.prm",
             replaced(replaced(replaced(beam,
                                        "set Point     = 0.1, 0, 0.01",
                                        "set Point     = 0.12, 0, 0.01"),
                               "set Prescribed displacement = 0, 0, -0.01",
                               "set Prescribed displacement = 0, 0, -0.05"),
                      "set Young's modulus = 1e5",
                      "set Young's modulus = 1e7"));
  ProgramRun r = run_palpate("solve far.prm");
  deallog << "far point, stiff push: exit status " << r.exit_status << std::endl
          << line_with(r.output, "the Point is") << std::endl
          << line_with(r.output, "times the device's force limit") << std::endl;
  write_file("farther.prm",
             replaced(beam,
                      "set Point     = 0.1, 0, 0.01",
                      "set Point     = 0.6, 0, 0.01"));
  r = run_palpate("solve farther.prm");
  deallog << "a point 0.5 m away: exit status " << r.exit_status << std::endl
          << line_with(r.output, "problem:") << std::endl;

  write_file("named.prm",
             beam + "\nsubsection Mesh\n  set File name = liver.stl\nend\n");
  r = run_palpate("solve named.prm");
  deallog << "File name with Source = beam: exit status " << r.exit_status
          << std::endl
          << line_with(r.output, "problem:") << std::endl;

  write_file("stl.prm",
             replaced(beam,
                      "set Source = beam",
                      "set Source = file\n  set File name = organ.stl"));
  r = run_palpate("solve stl.prm");
  deallog << "a surface with Source = file: exit status " << r.exit_status
          << std::endl
          << line_with(r.output, "problem:") << std::endl
          << line_with(r.output, "fix:") << std::endl;

  write_file("reach.prm", beam + R"(
subsection State space
  set Grid spacing = 0.002
  set Extent       = 0.004
end
subsection Scheduler
  set Cloud radius = 0.0035
end
subsection Haptics
  subsection Trajectory
    set Type      = straight line
    set Direction = 0, 0, -1
    set Speed     = 0.01
    set Duration  = 0.6
  end
end
)");
  r = run_palpate("reach.prm");
  deallog << "a trajectory beyond the state space: "
          << line_with(r.output, "the trajectory goes") << std::endl;

  // A sphere whose set-up checks weighed a 2 mm push, moved 25 mm by the
  // trajectory: deeper than its diameter, said before the motion.
  write_file("deep-sphere.prm",
             replaced(beam,
                      "set Prescribed displacement = 0, 0, -0.01",
                      "set Prescribed displacement = 0, 0, -0.002\n"
                      "    set Tip = sphere\n"
                      "    set Tip radius = 0.01") +
               R"(
subsection State space
  set Grid spacing = 0.005
  set Extent       = 0.03
end
subsection Haptics
  subsection Trajectory
    set Type      = straight line
    set Direction = 0, 0, -1
    set Speed     = 0.1
    set Duration  = 0.25
  end
end
)");
  r = run_palpate("deep-sphere.prm");
  deallog << "a trajectory deeper than the sphere's checks: "
          << line_with(r.output, "the trajectory's point").substr(0, 200)
          << std::endl;

  // A 10 cm cube's surface in millimetres, read as metres.
  palpate::Surface cube;
  for (unsigned int v = 0; v < 8; ++v)
    cube.vertices.push_back(
      {{0.1 * (v & 1), 0.1 * ((v >> 1) & 1), 0.1 * (v >> 2)}});
  cube.triangles = {{{0, 2, 1}},
                    {{1, 2, 3}},
                    {{4, 5, 6}},
                    {{5, 7, 6}},
                    {{0, 1, 4}},
                    {{1, 5, 4}},
                    {{2, 6, 3}},
                    {{3, 6, 7}},
                    {{0, 4, 2}},
                    {{2, 4, 6}},
                    {{1, 3, 5}},
                    {{3, 7, 5}}};
  palpate::write_surface(cube, "cube-mm.stl", true, 0.001);
  r = run_palpate("mesh cube-mm.stl cube.msh");
  deallog << "palpate mesh, millimetres read as metres: exit status "
          << r.exit_status << std::endl
          << line_with(r.output, "fix:") << std::endl;
  r = run_palpate("mesh cube-mm.stl cube.msh --scale 0.001 --nodes 200");
  deallog << "with --scale 0.001: exit status " << r.exit_status << ", "
          << line_with(r.output, "closed:") << std::endl;
}
