// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

#ifndef palpate_mesh_mesh_source_h
#define palpate_mesh_mesh_source_h

#include <palpate/base/exceptions.h>
#include <palpate/base/plugins.h>
#include <palpate/mesh/mesh.h>

#include <memory>
#include <optional>
#include <string>

namespace palpate
{
  class Scene;
  namespace Parameters
  {
    struct Mesh;
  }

  /**
   * Where the body's tetrahedral mesh comes from: a mesh file, an organ's
   * surface that palpate meshes, or a generator. `Mesh / Source` chooses
   * one from MeshSourceRegistry by name.
   *
   * Mesh sources are plug-ins (doc/extending.md). A source reads its own
   * entries from its subsection `Mesh / <its name>`, and may read the
   * shared ones of `Mesh` (File name, Scale factor, and the subsections
   * Beam, Surface and Blob of the built-in sources) from the scene; its
   * file ends with
   *
   *     PALPATE_REGISTER_MESH_SOURCE(Cube, "cube", "one line")
   *
   * where the class has `static void declare_parameters(ParameterHandler
   * &)`, `static std::unique_ptr<MeshSource> create(const ParameterHandler
   * &own, const Scene &scene)` and, optionally, `static void
   * check_scene(const Scene &scene)`: the checks of the entries it reads,
   * run when the scene is read (Scene::validate()), that throw
   * scene.error() naming the entry.
   */
  class MeshSource
  {
  public:
    virtual ~MeshSource() = default;

    /**
     * The body's mesh, in metres. Errors about finding or reading its
     * input are InputErrors naming the scene's entry or the input file.
     * Mesh::create() checks the result's size (if from_file()) and the
     * memory a solve on it needs.
     */
    virtual Mesh
    create_mesh(const Scene &scene) const = 0;

    /**
     * Whether the body comes from a file in the user's unit, which
     * Mesh / Scale factor turns into metres (a mesh file, a surface): a
     * body outside 2 mm - 2 m across is then refused with a suggested
     * factor, and the scene report warns about a body of unusual size. A
     * generator makes metres and ignores the factor: false.
     */
    virtual bool
    from_file() const;

    /**
     * Where @p mesh (this source's, for @p scene) came from, for the scene
     * report: Mesh::description() and what the source adds to it (a mesh
     * file: the scale it was read at).
     */
    virtual std::string
    description(const Mesh &mesh, const Scene &scene) const;

    /** The names palpate study gives the scene's mesh and a finer one. */
    struct Finer
    {
      /** The scene's mesh, or "" to keep the study's name for it. */
      std::string coarse_name;
      /** The finer mesh. */
      std::string finer_name;
    };

    /**
     * A finer mesh of the same body, for palpate study's mesh knob: set
     * @p mesh (a copy of the scene's entries) to make it and return the
     * names, or return nothing if the source knows no finer mesh (the
     * study then says so). @p scene is the scene the copy was taken of.
     */
    virtual std::optional<Finer>
    make_finer(Parameters::Mesh &mesh, const Scene &scene) const;

    /**
     * The source the scene's `Mesh / Source` chooses, built from its own
     * entries; a value its factory refuses is an InputError naming the
     * entry.
     */
    static std::unique_ptr<MeshSource>
    create(const Scene &scene);

  protected:
    /**
     * That the scene names no file for a generator (Mesh / File name set
     * with Source = beam): the run would silently use the generated body
     * instead of the organ the user meant. For check_scene().
     */
    static void
    check_no_file_named(const Scene &scene);

    /**
     * @p e, an error about the file @p what (e.g. "this file") that
     * Mesh / File name names, with the scene that reads it added to its
     * fix, so that the user knows where to point it elsewhere.
     */
    static InputError
    read_by(const InputError &e, const Scene &scene, const std::string &what);
  };

  /** The mesh sources, by the names scenes give them. */
  using MeshSourceRegistry = Plugins::Registry<MeshSource, Scene>;
  extern template class Plugins::Registry<MeshSource, Scene>;

/** Register the mesh source @p classname as @p name
 * (PALPATE_REGISTER_PLUGIN, plus its declaration for the scene's Mesh /
 * Source, and its check_scene()). */
#define PALPATE_REGISTER_MESH_SOURCE(classname, name, description) \
  PALPATE_REGISTER_DECLARED_PLUGIN(::palpate::MeshSourceRegistry,  \
                                   "mesh source",                  \
                                   classname,                      \
                                   name,                           \
                                   description)
} // namespace palpate

#endif
