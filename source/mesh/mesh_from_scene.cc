// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

#include <palpate/base/exceptions.h>
#include <palpate/mesh/generators.h>
#include <palpate/mesh/mesh.h>
#include <palpate/mesh/mesh_file.h>
#include <palpate/mesh/surface.h>
#include <palpate/mesh/volume_mesher.h>
#include <palpate/scene/scene.h>

#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <limits>
#include <memory>
#include <sstream>

namespace palpate
{
  namespace
  {
    /**
     * @p e with the scene that reads the file named in its fix, so that the
     * user knows where to point it elsewhere.
     */
    InputError
    read_by(const InputError &e, const Scene &scene, const std::string &what)
    {
      return InputError(e.file(),
                        e.line(),
                        e.entry(),
                        e.problem(),
                        e.fix() + " (The scene '" + scene.file() + "' reads " +
                          what + " through Mesh / File name.)");
    }

    /**
     * The bytes of the surface file Mesh / File name names (resolved to
     * @p path), with errors that point at that entry.
     */
    std::string
    surface_bytes(const Scene &scene, const std::string &path)
    {
      const auto &p = scene.parameters.mesh;
      try
        {
          check_file_size(path,
                          "surface file",
                          max_mesh_file_bytes,
                          "an organ's surface of 100,000 triangles has "
                          "about 5 MiB");
        }
      catch (const InputError &e)
        {
          throw scene.error("Mesh/File name", e.problem(), e.fix());
        }
      std::ifstream in(path, std::ios::binary);
      if (!in)
        {
          // A name the file system refuses (a loop of links, too long,
          // no permission) is said as such, not as a missing file.
          bool              missing = false;
          const std::string why     = why_cannot_open(path, &missing);
          if (!missing && !why.empty())
            throw scene.error("Mesh/File name",
                              "the surface file '" + path +
                                "' cannot be read: " + why,
                              "check the path, the links on the way and "
                              "the permissions.");
          throw scene.error(
            "Mesh/File name",
            "the surface file '" + p.file_name +
              "' was not found: looked for " + scene.where_looked(p.file_name),
            "a relative path is relative to the scene file's directory; "
            "the example organs are in the project's meshes/ (its "
            "README), e.g. '../meshes/liver-tetgen/liver2k-surface.obj' "
            "from parameters/.");
        }
      std::ostringstream s;
      s << in.rdbuf();
      return s.str();
    }



    /**
     * Where the volume mesh of the surface at @p path (its bytes @p bytes)
     * is kept: in Mesh / Surface / Volume mesh directory, named by a hash
     * of the bytes, the scale factor and the target, so a changed surface
     * or setting is meshed again and an unchanged one never is.
     */
    std::filesystem::path
    volume_mesh_file(const Scene       &scene,
                     const std::string &path,
                     const std::string &bytes)
    {
      namespace fs       = std::filesystem;
      const auto   &p    = scene.parameters.mesh;
      std::uint64_t hash = 1469598103934665603ull; // FNV-1a
      for (const char c :
           bytes + "|" + Utilities::to_string(p.scale_factor, 17) + "|" +
             // -2: the mesher's node-count correction changed (within
             // 10 %); meshes of older builds are made again.
             std::to_string(p.surface_target_nodes) + "|palpate-mesh-2" +
             (p.surface_fine_size > 0 ?
                "|graded " + Utilities::to_string(p.surface_fine_size, 17) +
                  " " + Utilities::to_string(p.surface_fine_radius, 17) + " " +
                  Utilities::to_string(
                    scene.parameters.boundary_conditions.active_node.point,
                    17) :
                std::string()))
        hash = (hash ^ static_cast<unsigned char>(c)) * 1099511628211ull;
      char hex[17];
      std::snprintf(hex, sizeof(hex), "%016llx", (unsigned long long)hash);
      const fs::path  directory(p.surface_mesh_directory);
      std::error_code ec;
      fs::create_directories(directory, ec);
      if (ec || !fs::is_directory(directory))
        throw scene.error("Mesh/Surface/Volume mesh directory",
                          "the directory '" + directory.string() +
                            "' cannot be created (" + ec.message() + ")",
                          "name a directory palpate may write to.");
      return directory / (fs::path(path).stem().string() + "-" +
                          std::to_string(p.surface_target_nodes) + "-" +
                          std::string(hex).substr(0, 8) + ".msh");
    }



    /**
     * Mesh / Source = surface: the volume mesh palpate made of the surface
     * before (volume_mesh_file()), or a new one.
     */
    Mesh
    from_surface(const Scene &scene)
    {
      namespace fs        = std::filesystem;
      const auto    &p    = scene.parameters.mesh;
      const auto     path = scene.resolve_path(p.file_name);
      const fs::path file =
        volume_mesh_file(scene, path, surface_bytes(scene, path));
      std::string how = "reused";
      // A mesh whose node-count corrections the time limit stopped is
      // used once and not kept: with more time the next run does better.
      bool keep = true;
      if (std::error_code exists_error; !fs::exists(file, exists_error))
        try
          {
            MeshGrading grading;
            grading.fine_size = p.surface_fine_size;
            grading.radius    = p.surface_fine_radius;
            grading.center =
              scene.parameters.boundary_conditions.active_node.point;
            const auto report = mesh_surface_file(path,
                                                  p.scale_factor,
                                                  "Mesh / Scale factor",
                                                  p.surface_target_nodes,
                                                  p.surface_time_limit,
                                                  file.string(),
                                                  grading);
            how               = "meshed now in " +
                  Utilities::to_string(report.meshing.seconds, 3) + " s";
            const auto repairs = report.repairs.lines();
            for (const auto &r : repairs)
              how += "; " + r;
            // The mesher's warnings (a node count it could not meet,
            // slivers) reach the scene report too, not only palpate mesh.
            for (const auto &line : report.lines())
              if (line.rfind("warning:", 0) == 0)
                how += "; " + Utilities::trim(line);
            keep = !report.meshing.stopped_by_time_limit;
          }
        catch (const InputError &e)
          {
            throw read_by(e, scene, "this surface");
          }
      Mesh mesh(read_mesh_file(file.string()),
                1.0,
                p.file_name + ", meshed by palpate into " + file.string() +
                  " (" + how + (keep ? "" : "; not kept") + ")");
      if (!keep)
        {
          std::error_code error;
          fs::remove(file, error);
        }
      return mesh;
    }
  } // namespace



  namespace
  {
    /** A scale factor to suggest for a mesh read in the wrong unit. */
    struct ScaleSuggestion
    {
      double       factor = 0;
      unsigned int fits = 0, of = 0;
    };

    /**
     * The factor to suggest when the body is not 2 mm - 2 m across: one
     * with which the scene's places meet the body (the probe's point near
     * a node; the fixed nodes' box or half-space holding some nodes but
     * not all), a unit (a power of ten) or the scene's factor times one if
     * such a factor does it, else any (to three digits); of those the one
     * that makes the body closest to a liver's 0.25 m. The scene's places
     * come first because the size alone misleads: for a millimetre mesh a
     * factor making it 0.25 m exactly (0.02743), or the scene's factor over
     * 100 (0.00039146), misses the fixed nodes, which only 0.001 fits.
     */
    ScaleSuggestion
    suggest_scale_factor(const Scene &scene, const Mesh &mesh)
    {
      const double factor = scene.parameters.mesh.scale_factor;
      const double size   = mesh.diameter();
      const auto  &x      = mesh.vertices();
      const auto  &bc     = scene.parameters.boundary_conditions;
      const auto  &fixed  = bc.fixed_nodes;
      // Whether 0 < k < n vertices at scale s lie in the fixed region.
      const auto splits = [&](const double s, const auto &in_region) {
        std::size_t k = 0;
        for (const auto &v : x)
          k += in_region(Utilities::scaled(v, s));
        return k > 0 && k < x.size();
      };
      const auto fits = [&](const double f) {
        const double s = f / factor;
        unsigned int n = 0;
        if (bc.active_node.selection != "node id")
          {
            double nearest = std::numeric_limits<double>::infinity();
            for (const auto &v : x)
              nearest = std::min(nearest,
                                 Utilities::distance(Utilities::scaled(v, s),
                                                     bc.active_node.point));
            n += nearest <= 0.05 * size * s;
          }
        if (fixed.selection == "box")
          n += splits(s, [&](const Utilities::Point3 &v) {
            for (unsigned int d = 0; d < 3; ++d)
              if (v[d] < fixed.box_lower_corner[d] ||
                  v[d] > fixed.box_upper_corner[d])
                return false;
            return true;
          });
        if (fixed.selection == "half-space")
          n += splits(s, [&](const Utilities::Point3 &v) {
            double dot = 0;
            for (unsigned int d = 0; d < 3; ++d)
              dot +=
                (v[d] - fixed.half_space_point[d]) * fixed.half_space_normal[d];
            return dot >= 0;
          });
        return n;
      };
      ScaleSuggestion best;
      best.of = (bc.active_node.selection != "node id") +
                (fixed.selection == "box" || fixed.selection == "half-space");
      const auto consider = [&](const double f) {
        const double scaled = size * f / factor;
        if (!(scaled >= Limits::min_body_size &&
              scaled <= Limits::max_body_size))
          return;
        const unsigned int n = fits(f);
        if (best.factor == 0 || n > best.fits ||
            (n == best.fits &&
             std::abs(std::log(scaled / 0.25)) <
               std::abs(std::log(size * best.factor / factor / 0.25))))
          best = {f, n, best.of};
      };
      for (int k = -9; k <= 9; ++k)
        {
          consider(factor * std::pow(10.0, k));
          consider(std::pow(10.0, k));
        }
      // A file in no unit (the SOFA liver): any factor, to three digits.
      // (A power of ten up to 1e22 is exact, and so is dividing the
      // rounded digits by it: the double a user gets by typing the three
      // digits.)
      const auto three_digits = [](const double v) {
        const int e = static_cast<int>(std::floor(std::log10(v))) - 2;
        return e < 0 ? std::round(v * std::pow(10.0, -e)) / std::pow(10.0, -e) :
                       std::round(v / std::pow(10.0, e)) * std::pow(10.0, e);
      };
      if (best.fits < best.of)
        for (int k = -900; k <= 900; ++k)
          consider(three_digits(factor * std::pow(10.0, k / 100.0)));
      return best;
    }



    /** The mesh a scene describes, before the memory check. */
    Mesh
    create_unchecked(const Scene &scene)
    {
      // A body palpate can touch is between a few millimetres (a small
      // sample) and about a metre (the largest organs) across: anything else
      // is a mesh read in the wrong unit, and would run with nonsense
      // forces and a state space of the wrong size.
      const auto check_size = [](const Scene &scene, const Mesh &mesh) {
        const double size = mesh.diameter();
        if (size >= Limits::min_body_size && size <= Limits::max_body_size)
          return;
        const double factor    = scene.parameters.mesh.scale_factor;
        const auto   suggested = suggest_scale_factor(scene, mesh);
        const double best      = suggested.factor;
        throw scene.error(
          "Mesh/Scale factor",
          "with this scale factor the body is " +
            Utilities::to_string(size, 3) +
            " m across (the diagonal of its bounding box); a body to palpate "
            "is between 0.002 and 2 m: the mesh file's unit is not the one "
            "the scale factor assumes",
          "set Scale factor to the metres per mesh-file unit: 0.001 for "
          "millimetres, 0.01 for centimetres; here " +
            Utilities::to_string(best, 6) + " makes the body " +
            Utilities::to_string(size * best / factor, 3) + " m across" +
            (suggested.of == 0 ?
               std::string() :
               ", where " + std::to_string(suggested.fits) +
                 " of the scene's " + std::to_string(suggested.of) +
                 " places (the probe's point, the fixed nodes' region) "
                 "meet it") +
            ", and " + Utilities::to_string(factor * 0.25 / size, 4) +
            " makes it 0.25 m (a liver).");
      };
      const auto &p = scene.parameters.mesh;
      if (p.source == "beam")
        return Mesh(generate_beam(p), 1.0, "the beam generator");
      if (p.source == "blob")
        return Mesh(generate_blob(p), 1.0, "the blob generator");

      if (p.source == "surface")
        {
          auto mesh = from_surface(scene);
          check_size(scene, mesh);
          return mesh;
        }

      // (.vtk holds either, and its reader tells them apart.)
      if (is_surface_file_name(p.file_name) &&
          std::filesystem::path(p.file_name).extension() != ".vtk")
        throw scene.error("Mesh/Source",
                          "Source = file reads a tetrahedral mesh, but '" +
                            p.file_name + "' is a surface",
                          "set Source = surface: palpate then meshes the "
                          "surface (and keeps the mesh for the next run).");
      const std::string path = scene.resolve_path(p.file_name);
      // error_code: a name the file system refuses (too long, a loop of
      // links) is reported below as a file that cannot be read.
      std::error_code exists_error;
      if (!std::filesystem::exists(path, exists_error) && !exists_error)
        throw scene.error(
          "Mesh/File name",
          "the mesh file '" + p.file_name + "' was not found: looked for " +
            scene.where_looked(p.file_name),
          "a relative path is relative to the scene file's directory; the "
          "example organs are in the project's meshes/ (its README), e.g. "
          "'../meshes/liver-tetgen/liver501.msh' from parameters/. Or use "
          "Source = blob, which needs no file.");
      std::unique_ptr<Mesh> mesh;
      try
        {
          // Errors about the file's content name the file as the scene
          // writes it (and the report shows it that way too).
          mesh = std::make_unique<Mesh>(read_mesh_file(path),
                                        p.scale_factor,
                                        p.file_name);
        }
      catch (const InputError &e)
        {
          throw read_by(e, scene, "this file");
        }
      check_size(scene, *mesh);
      return std::move(*mesh);
    }
  } // namespace



  namespace
  {
    /**
     * That one direct solve on @p mesh fits in this machine's memory: an
     * InputError naming the mesh (or the element degree) otherwise, before
     * anything large is allocated. A 205,379-node mesh was accepted and the
     * solve grew past 15 GB without a word.
     *
     * The estimate: MUMPS's factor of a 3-D finite element matrix has about
     * unknowns^(4/3) entries under nested dissection (the separators of a
     * 3-D mesh); measured on this project's livers with P1 (1,921, 7,877
     * and 11,499 nodes: 41, 211 and 434 MB above the program's 170 MB),
     * 310-410 bytes per unknowns^(4/3). 500 bytes are assumed, so the
     * refusal errs towards letting a mesh through. P2 adds a node on every
     * edge (about nodes + tetrahedra edges).
     */
    void
    check_memory(const Scene &scene, const Mesh &mesh)
    {
      const unsigned int degree = scene.displacement_degree();
      const double       nodes  = mesh.n_vertices();
      const double dof_nodes = degree >= 2 ? 2 * nodes + mesh.n_cells() : nodes;
      const double unknowns  = 3 * dof_nodes;
      const double bytes     = 170e6 + 500 * std::pow(unknowns, 4.0 / 3.0);
      const double memory =
        double(sysconf(_SC_PHYS_PAGES)) * double(sysconf(_SC_PAGE_SIZE));
      if (!(memory > 0) || bytes <= memory)
        return;
      const auto gib = [](const double b) {
        return Utilities::to_string(b / 1073741824.0, 3) + " GiB";
      };
      const std::string problem =
        "the mesh has " + std::to_string(mesh.n_vertices()) + " nodes and " +
        std::to_string(mesh.n_cells()) + " tetrahedra; with degree " +
        std::to_string(degree) + " elements that is about " +
        Utilities::to_string(unknowns, 3) +
        " unknowns, and one direct solve would need about " + gib(bytes) +
        " of memory (an estimate), more than this machine's " + gib(memory);
      const std::string fix =
        "use a coarser mesh: palpate mesh SURFACE OUT.msh --nodes 4000 makes "
        "one of about 4,000 nodes (enough for a liver's force to converge "
        "with a sphere probe)" +
        std::string(degree >= 2 ? ", or degree 1 elements" : "") + ".";
      throw scene.error(degree >= 2 ? "Discretization/Polynomial degree" :
                                      "Mesh/File name",
                        problem,
                        fix);
    }
  } // namespace



  Mesh
  Mesh::create(const Scene &scene)
  {
    Mesh mesh = create_unchecked(scene);
    check_memory(scene, mesh);
    return mesh;
  }
} // namespace palpate
