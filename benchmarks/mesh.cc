// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

// benchmarks/run mesh [--quick|--smoke] [--repeats N]
//
// Bring your own organ (issue 14): how long `palpate mesh` takes from a
// user's surface to a volume mesh, and whether a Mooney-Rivlin scene on it
// converges.
//
// The surface is made as a user's segmentation came to us: the liver
// (liver501-surface.obj, 377 vertices) subdivided twice to 6002 vertices
// and 12000 triangles, in millimetres, written as binary legacy VTK, facing
// inward, with three tiny zero-volume closed shells. It is meshed to about
// 1500 nodes (and, in the full run, 500 and 3000), timed end to end (read,
// repair, self-intersection check, Gmsh, quality). Then `palpate solve` on
// a Mooney-Rivlin scene built on the 1500-node mesh (Source = surface): the
// paper's fixed nodes, active node and 3 cm push.
//
// Target: about 1500 nodes in under 10 s; the solve converges.
//
// --quick: 1500 nodes only, once (a few seconds).
// --smoke (the test suite's): the same steps on the liver surface not
// subdivided (377 vertices), meshed to about 300 nodes, once.

#include <palpate/base/environment.h>
#include <palpate/hyperelastic/state_solver.h>
#include <palpate/mesh/mesh.h>
#include <palpate/mesh/node_selection.h>
#include <palpate/mesh/surface.h>
#include <palpate/mesh/volume_mesher.h>
#include <palpate/scene/scene.h>

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <map>
#include <sstream>

#include "machine.h"
#include "report_errors.h"

using namespace palpate;

namespace
{
  /** The user's surface, written to @p file; returns its vertex count. */
  unsigned int
  make_user_surface(const std::string &file, const unsigned int subdivisions)
  {
    Surface s = read_surface(std::string(PALPATE_SOURCE_DIR) +
                               "/meshes/liver-tetgen/liver501-surface.obj",
                             39.146e-3); // metres
    for (unsigned int k = 0; k < subdivisions; ++k)
      subdivide(s);
    for (auto &t : s.triangles) // inward
      std::swap(t[1], t[2]);
    // Three zero-volume shells next to the organ: the four faces of a
    // tetrahedron whose corners lie in one plane, 0.1 mm across.
    const auto box = s.bounding_box();
    for (unsigned int k = 0; k < 3; ++k)
      {
        const unsigned int b = s.vertices.size();
        for (unsigned int v = 0; v < 4; ++v)
          s.vertices.push_back({{box[0][0] - 0.005 - 0.002 * k + 1e-4 * (v & 1),
                                 box[0][1] + 1e-4 * (v >> 1),
                                 box[0][2]}});
        s.triangles.push_back({{b, b + 1, b + 2}});
        s.triangles.push_back({{b, b + 3, b + 1}});
        s.triangles.push_back({{b + 1, b + 3, b + 2}});
        s.triangles.push_back({{b, b + 2, b + 3}});
      }
    write_surface(s, file, true, 0.001); // millimetres
    return s.vertices.size();
  }
} // namespace

static int
run_benchmark(int argc, char **argv)
{
  Environment  env(argc, argv);
  bool         quick = false, smoke = false;
  unsigned int repeats = 3;
  for (int i = 1; i < argc; ++i)
    {
      const std::string a = argv[i];
      if (a == "--quick")
        quick = true;
      else if (a == "--smoke")
        smoke = quick = true;
      else if (a == "--repeats" && i + 1 < argc)
        repeats = std::max(1, std::stoi(argv[++i]));
      else
        {
          std::cerr
            << "usage: benchmarks/run mesh [--quick|--smoke] [--repeats N]\n";
          return 2;
        }
    }
  if (quick)
    repeats = 1;
  // The size the target and the scene's solve are about.
  const unsigned int              main_target = smoke ? 300 : 1500;
  const std::vector<unsigned int> targets =
    quick ? std::vector<unsigned int>{main_target} :
            std::vector<unsigned int>{500, 1500, 3000};

  const std::string  surface = "user-liver-mm.vtk";
  const unsigned int n       = make_user_surface(surface, smoke ? 0 : 2);
  std::cout << "palpate mesh on a user's liver surface: " << n
            << " vertices in millimetres, binary legacy VTK, inward, 3 "
               "zero-volume shells; "
            << machine() << ", " << repeats << " run(s) each"
            << (smoke ? " [--smoke]" :
                quick ? " [--quick]" :
                        "")
            << "\n\n";

  std::cout << "| target nodes | nodes | tetrahedra | time (s) | min radius "
               "ratio | dihedral (deg) | slivers |\n"
               "|---|---|---|---|---|---|---|\n";
  std::ostringstream results;
  SurfaceMeshReport  shown;
  for (const unsigned int target : targets)
    {
      std::vector<double> times;
      SurfaceMeshReport   r;
      for (unsigned int k = 0; k < repeats; ++k)
        {
          const auto t0 = std::chrono::steady_clock::now();
          r             = mesh_surface_file(
            surface, 0.001, "--scale", target, 60, "user-liver.msh");
          times.push_back(
            std::chrono::duration<double>(std::chrono::steady_clock::now() - t0)
              .count());
        }
      std::sort(times.begin(), times.end());
      const double t = times[times.size() / 2];
      if (target == main_target)
        shown = r;
      std::cout << "| " << target << " | " << r.meshing.nodes << " | "
                << r.meshing.tetrahedra << " | " << std::fixed
                << std::setprecision(2) << t << " | " << std::setprecision(3)
                << r.quality.min_radius_ratio << " | " << std::setprecision(1)
                << r.quality.min_dihedral_degrees << " - "
                << r.quality.max_dihedral_degrees << " | "
                << r.quality.slivers.size() << " |\n"
                << std::defaultfloat;
      results << "RESULT mesh surface_vertices=" << n
              << " target_nodes=" << target << " nodes=" << r.meshing.nodes
              << " tetrahedra=" << r.meshing.tetrahedra << " seconds=" << t
              << " min_radius_ratio=" << r.quality.min_radius_ratio
              << " slivers=" << r.quality.slivers.size()
              << (target == main_target ?
                    std::string(" under_10s=") + (t < 10 ? "yes" : "no") :
                    "")
              << "\n";
    }
  std::cout << "\nThe report for " << main_target << " nodes:\n";
  for (const auto &line : shown.lines())
    std::cout << "  " << line << "\n";

  // A Mooney-Rivlin scene on it: palpate solve's work.
  {
    std::ifstream     in(std::string(PALPATE_SOURCE_DIR) +
                     "/parameters/liver-surface.prm");
    std::stringstream text;
    text << in.rdbuf();
    std::string prm = text.str();
    const auto  a   = prm.find("subsection Mesh");
    const auto  b   = prm.find("subsection Boundary conditions");
    prm.replace(a,
                b - a,
                "subsection Mesh\n  set Source = surface\n  set File name = " +
                  std::filesystem::absolute(surface).string() +
                  "\n  set Scale factor = 0.001\n  subsection Surface\n    set "
                  "Target nodes = " +
                  std::to_string(main_target) +
                  "\n    set Volume mesh directory = "
                  "bench-meshes\n  end\nend\n\n");
    std::ofstream("user-liver-mr.prm") << prm;
    std::filesystem::remove_all("bench-meshes");
    const Scene         scene = Scene::read("user-liver-mr.prm");
    const Mesh          mesh  = Mesh::create(scene);
    const NodeSelection nodes = NodeSelection::create(scene, mesh);
    StateSolver         solver(mesh, nodes, scene.parameters);
    const auto          t0 = std::chrono::steady_clock::now();
    const State         s  = solver.solve(
      solver.rest_state(),
      scene.parameters.boundary_conditions.active_node.prescribed_displacement);
    const double t =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - t0)
        .count();
    std::cout << "\nMooney-Rivlin (P1-P1, exact) on it, 3 cm push: "
              << (s.converged ? "converged" : "FAILED") << " in "
              << s.increments << " increments, " << s.newton_iterations
              << " Newton iterations, " << std::setprecision(3) << t
              << " s; |f| = " << Utilities::norm(s.force) << " N ("
              << mesh.n_vertices() << " nodes)\n";
    results << "RESULT mesh scene=mooney-rivlin nodes=" << mesh.n_vertices()
            << " converged=" << (s.converged ? "yes" : "no")
            << " newton_iterations=" << s.newton_iterations
            << " force_N=" << Utilities::norm(s.force) << " solve_s=" << t
            << "\n";
    std::filesystem::remove_all("bench-meshes");
  }
  std::cout << "\n" << results.str();
  return 0;
}



int
main(int argc, char **argv)
{
  return report_errors("mesh", run_benchmark, argc, argv);
}
