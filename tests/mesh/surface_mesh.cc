// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

// Bring your own organ (issue 14): from a surface file to a volume mesh.
// - Every format round-trips: an icosphere of radius 5 cm (642 vertices,
//   1280 triangles, polyhedron volume known), written in millimetres as
//   ASCII and binary STL, OBJ, ASCII and binary PLY, ASCII and binary
//   legacy VTK, ascii and base64 VTP, read back with scale 0.001 and
//   repaired: the same vertex and triangle counts, the volume to 1e-6; then
//   meshed to about 300 nodes: within 10 % of 300, volume within 3 % of
//   the surface's.
// - Repairs: a surface facing inward is turned outward; three tiny
//   zero-volume shells are removed; inconsistently oriented triangles are
//   turned; a one-triangle hole is closed; STL's unshared vertices merged.
// - Refusals, with their messages: an open surface (a cap cut off), edges
//   of three triangles, two bodies, a fold that crosses the far side.
// - The time limit stops Gmsh.
// - Quality: the regular tetrahedron has radius ratio 1 and dihedral
//   angles of 70.53 degrees; a flat one is a sliver.
// - Plausibility: a surface in millimetres read as metres names the unit,
//   in the words and limits of a scene's mesh; a size just past a limit
//   reads as more (or less) than the limit.

#include <palpate/base/exceptions.h>
#include <palpate/mesh/mesh_quality.h>
#include <palpate/mesh/surface.h>
#include <palpate/mesh/surface_repair.h>
#include <palpate/mesh/volume_mesher.h>

#include <cmath>
#include <filesystem>
#include <map>

#include "../tests.h"

namespace
{
  using palpate::Surface;
  using palpate::Utilities::Point3;

  /** An icosphere of radius @p r (m) centred at @p c, @p levels times
   * subdivided, triangles facing outward. */
  Surface
  icosphere(const double r, const unsigned int levels, const Point3 &c)
  {
    Surface      s;
    const double t = (1 + std::sqrt(5.0)) / 2;
    for (const auto &v : std::vector<Point3>{{{-1, t, 0}},
                                             {{1, t, 0}},
                                             {{-1, -t, 0}},
                                             {{1, -t, 0}},
                                             {{0, -1, t}},
                                             {{0, 1, t}},
                                             {{0, -1, -t}},
                                             {{0, 1, -t}},
                                             {{t, 0, -1}},
                                             {{t, 0, 1}},
                                             {{-t, 0, -1}},
                                             {{-t, 0, 1}}})
      s.vertices.push_back(v);
    s.triangles = {{{0, 11, 5}},  {{0, 5, 1}},  {{0, 1, 7}},  {{0, 7, 10}},
                   {{0, 10, 11}}, {{1, 5, 9}},  {{5, 11, 4}}, {{11, 10, 2}},
                   {{10, 7, 6}},  {{7, 1, 8}},  {{3, 9, 4}},  {{3, 4, 2}},
                   {{3, 2, 6}},   {{3, 6, 8}},  {{3, 8, 9}},  {{4, 9, 5}},
                   {{2, 4, 11}},  {{6, 2, 10}}, {{8, 6, 7}},  {{9, 8, 1}}};
    for (unsigned int level = 0; level < levels; ++level)
      palpate::subdivide(s);
    for (auto &v : s.vertices)
      {
        const double n = palpate::Utilities::norm(v);
        for (unsigned int d = 0; d < 3; ++d)
          v[d] = c[d] + r * v[d] / n;
      }
    return s;
  }

  /** The error's problem, or "NOT refused". */
  template <typename F>
  std::string
  refusal(const F &f)
  {
    try
      {
        f();
      }
    catch (const palpate::InputError &e)
      {
        return e.problem();
      }
    return "NOT refused";
  }
} // namespace

int
main(int argc, char **argv)
{
  palpate::Environment env(argc, argv);
  initlog();
  const Surface sphere = icosphere(0.05, 3, {{0.01, -0.02, 0.03}});
  const double  V      = sphere.volume();
  deallog << "icosphere: " << sphere.vertices.size() << " vertices, "
          << sphere.triangles.size()
          << " triangles, volume / (4/3 pi r^3) = " << std::setprecision(4)
          << V / (4.0 / 3 * M_PI * std::pow(0.05, 3)) << std::setprecision(6)
          << std::endl;

  // --- Every format round-trips, and meshes.
  for (const auto &[file, binary] :
       std::vector<std::pair<std::string, bool>>{{"sphere-ascii.stl", false},
                                                 {"sphere-binary.stl", true},
                                                 {"sphere.obj", false},
                                                 {"sphere-ascii.ply", false},
                                                 {"sphere-binary.ply", true},
                                                 {"sphere-ascii.vtk", false},
                                                 {"sphere-binary.vtk", true},
                                                 {"sphere-ascii.vtp", false},
                                                 {"sphere-base64.vtp", true}})
    {
      palpate::write_surface(sphere, file, binary, 0.001);
      Surface    s    = palpate::read_surface(file, 0.001);
      const auto r    = palpate::repair_surface(s, file);
      const bool same = s.vertices.size() == sphere.vertices.size() &&
                        s.triangles.size() == sphere.triangles.size() &&
                        std::abs(s.volume() / V - 1) < 1e-6 &&
                        !r.turned_outward;
      const auto m = palpate::mesh_volume(s, 300, 60, "sphere.msh", file);
      const palpate::MeshData data   = palpate::read_mesh_file("sphere.msh");
      double                  volume = 0;
      for (const auto &t : data.tetrahedra)
        {
          using namespace palpate::Utilities;
          const auto &x = data.nodes;
          volume += std::abs(dot(minus(x[t[1]], x[t[0]]),
                                 cross(minus(x[t[2]], x[t[0]]),
                                       minus(x[t[3]], x[t[0]])))) /
                    6;
        }
      deallog << file << " (" << s.format << "): read back " << ok(same)
              << (r.merged_vertices > 0 ? ", vertices merged" : "")
              << "; meshed: nodes within 10 % of 300 "
              << ok(std::abs(m.nodes / 300.0 - 1) <= 0.10)
              << ", volume within 3 % " << ok(std::abs(volume / V - 1) < 0.03)
              << std::endl;
    }

  // --- Repairs.
  {
    Surface s = sphere;
    for (auto &t : s.triangles)
      std::swap(t[1], t[2]);
    for (unsigned int k = 0; k < 10; ++k) // ten disagree with the rest
      std::swap(s.triangles[7 * k][1], s.triangles[7 * k][2]);
    // Three zero-volume closed shells: flat tetrahedra 0.1 mm across.
    for (unsigned int k = 0; k < 3; ++k)
      {
        const unsigned int b = s.vertices.size();
        for (const auto &p : std::vector<Point3>{
               {{0, 0, 0}}, {{1e-4, 0, 0}}, {{0, 1e-4, 0}}, {{1e-4, 1e-4, 0}}})
          s.vertices.push_back({{p[0] + 0.2 + k * 0.01, p[1], p[2]}});
        // A closed tetrahedron's four faces, on four points in a plane.
        s.triangles.push_back({{b, b + 1, b + 2}});
        s.triangles.push_back({{b, b + 3, b + 1}});
        s.triangles.push_back({{b + 1, b + 3, b + 2}});
        s.triangles.push_back({{b, b + 2, b + 3}});
      }
    s.triangles.erase(s.triangles.begin() + 100); // a one-triangle hole
    const auto r = palpate::repair_surface(s, "flipped.obj");
    deallog << "repairs of an inward surface with 10 flipped triangles, 3 "
               "flat shells and a hole:"
            << std::endl;
    for (const auto &line : r.lines())
      deallog << "  " << line << std::endl;
    deallog << "  volume after repair: " << std::setprecision(4)
            << s.volume() / V << " of the sphere's (closed by a fan)"
            << std::setprecision(6) << std::endl;
  }

  // --- Refusals.
  {
    Surface                                  open = sphere;
    std::vector<std::array<unsigned int, 3>> kept;
    for (const auto &t : open.triangles)
      if (open.vertices[t[0]][2] < 0.03 + 0.03)
        kept.push_back(t);
    open.triangles = kept;
    deallog << "open: " << refusal([&] {
      palpate::repair_surface(open, "open.stl");
    }) << std::endl;

    Surface    fin = sphere;
    const auto t0  = fin.triangles[0];
    fin.vertices.push_back({{0.2, 0.2, 0.2}});
    fin.triangles.push_back(
      {{t0[0], t0[1], static_cast<unsigned int>(fin.vertices.size() - 1)}});
    deallog << "three triangles at an edge: " << refusal([&] {
      palpate::repair_surface(fin, "fin.stl");
    }) << std::endl;

    Surface            two = sphere, other = icosphere(0.03, 2, {{0.3, 0, 0}});
    const unsigned int n = two.vertices.size();
    for (const auto &v : other.vertices)
      two.vertices.push_back(v);
    for (auto t : other.triangles)
      {
        for (auto &v : t)
          v += n;
        two.triangles.push_back(t);
      }
    deallog << "two bodies: " << refusal([&] {
      palpate::repair_surface(two, "two.stl");
    }) << std::endl;

    // A fold larger than the elements: the top cap (z above the centre
    // + 3 cm) pushed down through the body and out of its bottom.
    Surface fold = sphere;
    for (auto &v : fold.vertices)
      if (v[2] > 0.03 + 0.03)
        v[2] -= 0.1;
    Point3 where;
    deallog << "fold: crossing pairs found: "
            << ok(palpate::count_self_intersections(fold, where) > 0)
            << ", none in the sphere: "
            << ok(palpate::count_self_intersections(sphere, where) == 0)
            << std::endl;
    palpate::write_surface(fold, "fold.obj");
    std::filesystem::remove("fold.msh");
    deallog << "fold, meshed: "
            << refusal([&] {
                 palpate::mesh_surface_file(
                   "fold.obj", 1, "--scale", 300, 60, "fold.msh");
               }).substr(0, 60)
            << "..." << std::endl;
    deallog << "fold: no mesh file left behind: "
            << ok(!std::filesystem::exists("fold.msh")) << std::endl;
  }

  // --- The time limit.
  deallog << "time limit 0.05 s for 200000 nodes: "
          << refusal([&] {
               palpate::mesh_volume(sphere, 200000, 0.05, "big.msh", "big");
             }).substr(0, 58)
          << "..." << std::endl;

  // --- Quality.
  {
    const std::vector<Point3> x = {
      {{1, 1, 1}}, {{1, -1, -1}}, {{-1, 1, -1}}, {{-1, -1, 1}}, {{0, 0, 0.01}}};
    const auto regular = palpate::mesh_quality(x, {{{0, 1, 2, 3}}});
    const auto flat    = palpate::mesh_quality(
      {{{0, 0, 0}}, {{1, 0, 0}}, {{0, 1, 0}}, {{1, 1, 1e-3}}},
      {{{0, 1, 2, 3}}});
    deallog << "regular tetrahedron: radius ratio " << std::setprecision(4)
            << regular.min_radius_ratio << ", dihedral angles "
            << regular.min_dihedral_degrees << " - "
            << regular.max_dihedral_degrees << ", slivers "
            << regular.slivers.size() << "; a flat one: slivers "
            << flat.slivers.size() << std::setprecision(6) << std::endl;
  }

  // --- Plausibility: millimetres read as metres.
  palpate::write_surface(sphere, "sphere-mm.stl", true, 0.001);
  deallog << "millimetres read as metres: " << refusal([&] {
    palpate::mesh_surface_file(
      "sphere-mm.stl", 1, "--scale", 300, 60, "mm.msh");
  }) << std::endl;
  deallog << "advice for 192 m at scale 1: " << palpate::unit_advice(192, 1)
          << std::endl;
  // Sizes just past the limits do not read as the limits.
  deallog << "2.0004 m: " << palpate::Limits::body_size_problem(2.0004)
          << "; 0.0019996 m: " << palpate::Limits::body_size_problem(0.0019996)
          << std::endl;
}
