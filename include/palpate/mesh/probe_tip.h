// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

#ifndef palpate_mesh_probe_tip_h
#define palpate_mesh_probe_tip_h

#include <palpate/base/plugins.h>
#include <palpate/mesh/node_selection.h>

#include <memory>
#include <set>
#include <string>

namespace palpate
{
  class Mesh;
  class Scene;

  /**
   * What touches the organ at the active node: the node alone (a point),
   * the surface nodes glued around it, or a rigid sphere in contact with
   * the surface. `Boundary conditions / Active node / Tip` chooses one from
   * ProbeTipRegistry by name; NodeSelection::create() then asks it to
   * place itself on the mesh.
   *
   * Probe tips are plug-ins (doc/extending.md). A tip reads its own
   * entries from its subsection `Boundary conditions / Active node / <its
   * name>`, and may read the shared ones of `Active node` (Tip radius, the
   * built-in tips') from the scene; its file ends with
   *
   *     PALPATE_REGISTER_PROBE_TIP(Disc, "disc", "one line")
   *
   * where the class has `static void declare_parameters(ParameterHandler
   * &)`, `static std::unique_ptr<ProbeTip> create(const ParameterHandler
   * &own, const Scene &scene)` and, optionally, `static void
   * check_parameters(const ParameterHandler &own)` and `static void
   * check_scene(const Scene &scene)`: the checks of the entries it reads,
   * run when the scene is read (Scene::validate()), that throw
   * scene.error() naming the entry.
   *
   * The solver knows two ways a probe pushes: through the nodes that move
   * with the haptic interaction point (the active node and
   * NodeSelection::tip_vertices), or through a sphere in unilateral
   * contact (NodeSelection::sphere_tip). A tip chooses between them with
   * is_sphere() and place(); everything else about it (its checks, its
   * words in the report) is its own.
   */
  class ProbeTip
  {
  public:
    virtual ~ProbeTip() = default;

    /**
     * Whether the tip is a rigid sphere of radius Tip radius in
     * frictionless unilateral contact with the surface, whose centre
     * follows the HIP: the solver then solves the contact, and the
     * contact-patch interpolation can render it. False: the tip's nodes
     * follow the HIP (NodeSelection::tip_vertices).
     */
    virtual bool
    is_sphere() const;

    /**
     * Put the tip on @p mesh at @p selection's active node: the surface
     * nodes that move with it (tip_vertices; none of the @p fixed ones),
     * or the sphere's placement (sphere_center, active_normal,
     * sphere_lift), checked against the mesh; a sphere whose radius fails
     * the checks is refused with the radius @p sizing found to converge,
     * if one is given. A point adds nothing: the default.
     */
    virtual void
    place(const Scene                       &scene,
          const Mesh                        &mesh,
          const std::set<unsigned int>      &fixed,
          NodeSelection                     &selection,
          const NodeSelection::SphereSizing &sizing) const;

    /**
     * The scene report's line about the tip as @p nodes placed it (units
     * in it), or "" if the tip has nothing to say (a point).
     */
    virtual std::string
    report(const Scene &scene, const NodeSelection &nodes) const;

    /**
     * The tip as one of the scene report's effects ("contact with a rigid
     * sphere"), or "" if it is none (a point).
     */
    virtual std::string
    effect(const NodeSelection &nodes) const;

    /**
     * The tip the scene's `Active node / Tip` chooses, built from its own
     * entries; a value its factory refuses is an InputError naming the
     * entry.
     */
    static std::unique_ptr<ProbeTip>
    create(const Scene &scene);

  protected:
    /**
     * That Tip radius, which the tip reads, is a probe's: positive, and at
     * most Limits::max_sphere_radius. @p what names the tip in the message
     * ("a sphere"). For check_scene().
     */
    static void
    check_radius(const Scene &scene, const std::string &what);
  };

  /** The probe tips, by the names scenes give them. */
  using ProbeTipRegistry = Plugins::Registry<ProbeTip, Scene>;
  extern template class Plugins::Registry<ProbeTip, Scene>;

/** Register the probe tip @p classname as @p name (PALPATE_REGISTER_PLUGIN,
 * plus its declaration for the scene's Active node / Tip, its
 * check_parameters() and its check_scene()). */
#define PALPATE_REGISTER_PROBE_TIP(classname, name, description) \
  PALPATE_REGISTER_DECLARED_PLUGIN(                              \
    ::palpate::ProbeTipRegistry, "probe tip", classname, name, description)
} // namespace palpate

#endif
