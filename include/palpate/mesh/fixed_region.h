// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

#ifndef palpate_mesh_fixed_region_h
#define palpate_mesh_fixed_region_h

#include <palpate/base/plugins.h>
#include <palpate/base/utilities.h>

#include <memory>
#include <set>
#include <string>

namespace palpate
{
  class Mesh;
  class Scene;

  /**
   * Which nodes are held at zero displacement: those on boundary faces of
   * given ids, in a box, in a half-space, or listed by number.
   * `Boundary conditions / Fixed nodes / Selection` chooses one from
   * FixedRegionRegistry by name; NodeSelection::create() then checks that
   * the nodes it selects hold the body.
   *
   * Fixed regions are plug-ins (doc/extending.md). A region reads its own
   * entries from its subsection `Boundary conditions / Fixed nodes / <its
   * name>`, and may read the shared ones of `Fixed nodes` (Surface nodes
   * only, and the built-in regions' Boundary ids, Box lower corner, ...)
   * from the scene; its file ends with
   *
   *     PALPATE_REGISTER_FIXED_REGION(Sphere, "sphere", "one line")
   *
   * where the class has `static void declare_parameters(ParameterHandler
   * &)`, `static std::unique_ptr<FixedRegion> create(const ParameterHandler
   * &own, const Scene &scene)` and, optionally, `static void
   * check_scene(const Scene &scene)`: the checks of the entries it reads,
   * run when the scene is read (Scene::validate()), that throw
   * scene.error() naming the entry.
   */
  class FixedRegion
  {
  public:
    virtual ~FixedRegion() = default;

    /** The nodes a region selects on a mesh. */
    struct Selected
    {
      /** The fixed vertices (Mesh's indices). */
      std::set<unsigned int> fixed;
      /** The vertices in the region, on the surface or not: more than
       * fixed.size() if Surface nodes only left some out. */
      unsigned int in_region = 0;
    };

    /**
     * The nodes of @p mesh the region fixes. A node the region names that
     * the mesh does not have is an InputError naming the scene's entry.
     * An empty selection is not an error here: NodeSelection::create()
     * says why nothing holds the body.
     */
    virtual Selected
    select(const Scene &scene, const Mesh &mesh) const = 0;

    /**
     * The scene entry that defines the region ("Boundary conditions/Fixed
     * nodes/Box lower corner"), which the messages about its nodes (none
     * selected, all on one line) point at.
     */
    virtual std::string
    entry() const = 0;

    /** How the nodes of @p selected were chosen, one line for the scene
     * report and the messages ("nodes in the box [...] - [...] m"). */
    virtual std::string
    description(const Selected &selected) const = 0;

    /**
     * Whether the region is a place in space (a box, a half-space), which
     * a mesh read in the wrong unit misses; contains() then says which
     * points it holds, so that a suggested Scale factor can be one that
     * makes the region meet the body. Boundary ids and node numbers meet
     * a mesh in any unit: false.
     */
    virtual bool
    is_place() const;

    /** Whether the point @p x (m) is in the region; only asked of a
     * place (is_place()). */
    virtual bool
    contains(const Utilities::Point3 &x) const;

    /**
     * The region the scene's `Fixed nodes / Selection` chooses, built from
     * its own entries; a value its factory refuses is an InputError naming
     * the entry.
     */
    static std::unique_ptr<FixedRegion>
    create(const Scene &scene);

  protected:
    /** The vertices of @p mesh that contains() holds (of them only those
     * on the surface if @p surface_only), for a place's select(). */
    Selected
    select_contained(const Mesh &mesh, const bool surface_only) const;
  };

  /** The fixed regions, by the names scenes give them. */
  using FixedRegionRegistry = Plugins::Registry<FixedRegion, Scene>;
  extern template class Plugins::Registry<FixedRegion, Scene>;

/** Register the fixed region @p classname as @p name
 * (PALPATE_REGISTER_PLUGIN, plus its declaration for the scene's Fixed nodes
 * / Selection, and its check_scene()). */
#define PALPATE_REGISTER_FIXED_REGION(classname, name, description) \
  PALPATE_REGISTER_DECLARED_PLUGIN(::palpate::FixedRegionRegistry,  \
                                   "fixed region",                  \
                                   classname,                       \
                                   name,                            \
                                   description)
} // namespace palpate

#endif
