// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

// Mesh / Source = file: a tetrahedral mesh file (Gmsh .msh, .vtk, .vtu),
// read in the unit Mesh / Scale factor converts to metres.

#include <palpate/mesh/mesh_file.h>
#include <palpate/mesh/mesh_source.h>
#include <palpate/mesh/surface.h>
#include <palpate/scene/scene.h>

#include <deal.II/base/parameter_handler.h>

#include <filesystem>
#include <iomanip>
#include <sstream>

namespace palpate
{
  namespace
  {
    /** The mesh file Mesh / File name names. */
    class FileSource : public MeshSource
    {
    public:
      /** No entries of its own: it reads Mesh / File name and Scale
       * factor. */
      static void
      declare_parameters(dealii::ParameterHandler &)
      {}

      static std::unique_ptr<MeshSource>
      create(const dealii::ParameterHandler &, const Scene &)
      {
        return std::make_unique<FileSource>();
      }

      static void
      check_scene(const Scene &scene)
      {
        if (scene.parameters.mesh.file_name.empty())
          throw scene.error("Mesh/File name",
                            "Source = file, but no mesh file is named",
                            "set File name to a .msh, .vtk or .vtu file, or "
                            "choose Source = beam or blob.");
      }

      Mesh
      create_mesh(const Scene &scene) const override
      {
        const auto &p = scene.parameters.mesh;
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
        try
          {
            // Errors about the file's content name the file as the scene
            // writes it (and the report shows it that way too).
            return Mesh(read_mesh_file(path), p.scale_factor, p.file_name);
          }
        catch (const InputError &e)
          {
            throw read_by(e, scene, "this file");
          }
      }

      bool
      from_file() const override
      {
        return true;
      }

      std::string
      description(const Mesh &mesh, const Scene &scene) const override
      {
        std::ostringstream s;
        s << mesh.description() << ", scaled by " << std::setprecision(6)
          << scene.parameters.mesh.scale_factor << " m/unit";
        return s.str();
      }

      /** The example liver of 501 nodes has a finer sibling of 2,011 in
       * its directory; of another file no finer mesh is known. */
      std::optional<Finer>
      make_finer(Parameters::Mesh &mesh, const Scene &scene) const override
      {
        std::filesystem::path file(mesh.file_name);
        if (file.is_relative() && !scene.file().empty())
          file = std::filesystem::path(scene.file()).parent_path() / file;
        const auto sibling = file.parent_path() / "liver2k.msh";
        if (file.filename() != "liver501.msh" ||
            !std::filesystem::exists(sibling))
          return std::nullopt;
        mesh.file_name = std::filesystem::absolute(sibling).string();
        return Finer{"liver501", "liver2k"};
      }
    };
  } // namespace

  PALPATE_REGISTER_MESH_SOURCE(FileSource,
                               "file",
                               "a tetrahedral mesh file (File name)")
} // namespace palpate
