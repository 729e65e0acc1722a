// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

// `palpate mesh --nodes N` lands within 10 % of N (issue 27: 4,000 asked
// for gave 3,421-3,468 nodes, 15 % under, which the old 15 % tolerance
// let through).
//
// The shipped liver surface (meshes/liver-tetgen/liver2k-surface.obj,
// 25 cm at 0.039146 m per file unit) is meshed as `palpate mesh` does it
// (read, repair, Gmsh) to 500, 2,000, 4,000 and 8,000 nodes. Each count
// must be within 10 % of the request, and the file written must hold the
// mesh the report describes (the mesher keeps the closest of its passes,
// not the last). Exact counts are not compared: they depend on Gmsh's
// version. 4,000 misses on the first pass (about 3,470 nodes) and needs
// the correction.
//
// When the count cannot be met, the report says so: a result that stayed
// 14 % under after four passes, and one stopped by the time limit, give a
// warning with the numbers and what to do.

#include <palpate/mesh/mesh_file.h>
#include <palpate/mesh/volume_mesher.h>

#include <cmath>

#include "../tests.h"

int
main(int argc, char **argv)
{
  palpate::Environment env(argc, argv);
  initlog();

  const std::string surface =
    palpate_source_dir + "/meshes/liver-tetgen/liver2k-surface.obj";
  for (const unsigned int target : {500u, 2000u, 4000u, 8000u})
    {
      const auto report = palpate::mesh_surface_file(
        surface, 0.039146, "--scale", target, 60, "liver.msh");
      const double off = std::abs(double(report.meshing.nodes) / target - 1);
      const palpate::MeshData written = palpate::read_mesh_file("liver.msh");
      deallog << target << " nodes asked for: within 10 % " << ok(off <= 0.1)
              << ", reported as met " << ok(report.meshing.target_nodes_met)
              << ", the file holds the reported mesh "
              << ok(written.nodes.size() == report.meshing.nodes &&
                    written.tetrahedra.size() == report.meshing.tetrahedra)
              << std::endl;
      if (off > 0.1)
        deallog << "  got " << report.meshing.nodes << " nodes in "
                << report.meshing.passes << " passes" << std::endl;
    }

  // The warnings when the count is not met.
  palpate::SurfaceMeshReport report;
  report.meshing.nodes            = 3440;
  report.meshing.target_nodes     = 4000;
  report.meshing.passes           = 4;
  report.meshing.attempts         = 4;
  report.meshing.target_nodes_met = false;
  for (const bool by_time : {false, true})
    {
      report.meshing.stopped_by_time_limit = by_time;
      for (const auto &line : report.lines())
        if (line.rfind("warning:", 0) == 0)
          deallog << line << std::endl;
    }
  // A graded mesh's count is not the target's (the target sets the coarse
  // size only): no warning.
  report.meshing.graded = true;
  unsigned int warnings = 0;
  for (const auto &line : report.lines())
    warnings += line.rfind("warning:", 0) == 0;
  deallog << "graded mesh: no count warning " << ok(warnings == 0) << std::endl;
}
