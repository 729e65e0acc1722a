// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

// Mesh / Source = surface: an organ's closed surface (.stl, .obj, .ply, .vtk,
// .vtp), meshed by palpate into tetrahedra (Gmsh) and kept in Mesh /
// Surface / Volume mesh directory for the next run.

#include <palpate/base/exceptions.h>
#include <palpate/mesh/mesh_file.h>
#include <palpate/mesh/mesh_source.h>
#include <palpate/mesh/volume_mesher.h>
#include <palpate/scene/scene.h>

#include <deal.II/base/parameter_handler.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>

namespace palpate
{
  namespace
  {
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
     * The volume mesh palpate made of the surface before
     * (volume_mesh_file()), or a new one.
     */
    class SurfaceSource : public MeshSource
    {
    public:
      /** No entries of its own: it reads Mesh / File name, Scale factor
       * and the subsection Mesh / Surface. */
      static void
      declare_parameters(dealii::ParameterHandler &)
      {}

      static std::unique_ptr<MeshSource>
      create(const dealii::ParameterHandler &, const Scene &)
      {
        return std::make_unique<SurfaceSource>();
      }

      static void
      check_scene(const Scene &scene)
      {
        const auto &p = scene.parameters.mesh;
        if (p.file_name.empty())
          throw scene.error("Mesh/File name",
                            "Source = surface, but no surface file is named",
                            "set File name to the organ's closed surface "
                            "(.stl, .obj, .ply, .vtk or .vtp).");
        // As palpate mesh --fine-size: below 10 micrometres Gmsh works
        // until its time limit and the message blames the limit.
        if (p.surface_fine_size > 0 && p.surface_fine_size < 1e-5)
          throw scene.error(
            "Mesh/Surface/Refinement size",
            "an element size of " +
              Utilities::to_string(p.surface_fine_size, 3) +
              " m near the probe; at least 1e-5 m (10 micrometres)",
            "give the size in metres: a third of the sphere's radius "
            "is a good start, e.g. 0.003 for a 1 cm sphere.");
      }

      Mesh
      create_mesh(const Scene &scene) const override
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

      bool
      from_file() const override
      {
        return true;
      }

      /** The same surface, finer: the refinement around the probe halved
       * (the indenter's region), or twice the nodes. */
      std::optional<Finer>
      make_finer(Parameters::Mesh &m, const Scene &) const override
      {
        // As palpate study writes lengths.
        const auto mm = [](const double metres) {
          std::ostringstream s;
          s << metres * 1000 << " mm";
          return s.str();
        };
        Finer names;
        if (m.surface_fine_size > 0)
          {
            names.coarse_name = "refinement " + mm(m.surface_fine_size);
            m.surface_fine_size /= 2;
            names.finer_name = "refinement " + mm(m.surface_fine_size);
          }
        else
          {
            names.coarse_name =
              std::to_string(m.surface_target_nodes) + " nodes";
            m.surface_target_nodes *= 2;
            names.finer_name =
              std::to_string(m.surface_target_nodes) + " nodes";
          }
        return names;
      }
    };
  } // namespace

  PALPATE_REGISTER_MESH_SOURCE(
    SurfaceSource,
    "surface",
    "an organ's closed surface (File name: .stl, .obj, .ply, .vtk or .vtp), "
    "meshed by palpate (see subsection Surface) and kept for the next run")
} // namespace palpate
