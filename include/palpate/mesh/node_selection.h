// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

#ifndef palpate_mesh_node_selection_h
#define palpate_mesh_node_selection_h

#include <palpate/base/utilities.h>

#include <functional>
#include <string>
#include <vector>

namespace palpate
{
  class Mesh;
  class Scene;

  /**
   * The nodes a scene constrains: the fixed ones (zero displacement) and
   * the active one (follows the haptic interaction point).
   */
  struct NodeSelection
  {
    /** Fixed vertices (all three components), sorted, unique. */
    std::vector<unsigned int> fixed_vertices;
    /**
     * Further constraints on single components: (vertex, component) pairs
     * held at zero, e.g. a sliding support or plane strain. Not set by
     * scenes yet; tests and benchmarks use them.
     */
    std::vector<std::pair<unsigned int, unsigned int>> fixed_components;
    /** Value of active_vertex for a body without an active node. */
    static constexpr unsigned int no_active_node =
      static_cast<unsigned int>(-1);
    /** The active vertex, or no_active_node. */
    unsigned int active_vertex = 0;
    /** Distance from the scene's Point to the active node, metres (0 for
     * Selection = node id). */
    double active_distance = 0;
    /**
     * The other nodes of a rigid probe tip (Active node / Tip radius):
     * surface vertices within the radius of the active vertex, not fixed.
     * They move with the active node; empty for a point probe.
     */
    std::vector<unsigned int> tip_vertices;
    /** With a tip: the distance (m) from the active vertex to the nearest
     * other free surface vertex, the smallest radius that makes a tip. */
    double tip_neighbour_distance = 0;

    /**
     * Whether the probe's tip is a rigid sphere in frictionless contact
     * with the surface (ProbeTip::is_sphere()): the solver then solves the
     * contact instead of moving tip_vertices, and the members below place
     * the sphere.
     */
    bool sphere_tip = false;

    /**
     * With a sphere tip: the outward unit normal of the surface where the
     * sphere touches it at HIP = 0 (the area-weighted mean over the
     * surface triangles within one radius), and the sphere's centre at
     * HIP = 0 (m). The sphere touches the surface at the point of it
     * nearest to the scene's Point (Selection = nearest surface node; the
     * same place on every mesh of the organ) or at the active node
     * (Selection = node id); its centre is one radius out along the
     * normal, and further out by sphere_lift if a surface node (a concave
     * surface) would otherwise be inside it, so that at HIP = 0 it
     * touches the surface and presses on nothing.
     */
    Utilities::Point3 active_normal = {{0, 0, 0}};
    Utilities::Point3 sphere_center = {{0, 0, 0}};
    double            sphere_lift   = 0;

    /** One line describing how the fixed nodes were chosen. */
    std::string fixed_description;

    /** What a refusal of a sphere's radius names beside the radius, from
     * the sizing that tried it: the push to name with it ("" for the
     * scene's own), and what the trials found. */
    struct TriedOffer
    {
      std::string push, why;
    };

    /**
     * The sizing of a refused sphere by static solves, which only a layer
     * that can solve gives (hyperelastic/sphere_trial.h): the checks here
     * are geometric and cannot foresee where the contact Newton stagnates.
     * Called by the refusal with @p offer, a radius that passes the checks
     * for @p scene on @p mesh at @p selection's active node, and
     * @p first_passing, the first radius from r up that passes them. It
     * sets @p offer to the radius to name (one whose solve converged) and
     * returns what to name with it, or throws the refusal itself when
     * nothing it tried converged.
     */
    using SphereSizing = std::function<
      TriedOffer(const Scene                         &scene,
                 const Mesh                          &mesh,
                 const NodeSelection                 &selection,
                 double                              &offer,
                 const std::function<double(double)> &first_passing)>;

    /**
     * Select the nodes a scene asks for on @p mesh. Throws an InputError,
     * naming the scene entry, if the fixed region selects no node, if the
     * fixed nodes cannot hold the body (they all lie on one line, so it
     * could rotate about it), if a node number does not exist, or if the
     * active node is fixed or not on the surface. With a sphere whose
     * radius fails its checks, the radius the refusal offers is tried by
     * @p sizing if one is given.
     */
    static NodeSelection
    create(const Scene        &scene,
           const Mesh         &mesh,
           const SphereSizing &sizing = SphereSizing());

    /**
     * Ask a sphere tip's checks (that it meets the surface
     * nodes, with a margin when pushed deeper than its radius, and is not
     * pushed deeper than the tissue lets it, nor too far towards the fixed
     * nodes) for the push @p push instead of the scene's Prescribed
     * displacement; the fixed nodes are this selection's, not selected
     * again. Throws the InputError create() would.
     */
    void
    check_sphere_push(const Scene             &scene,
                      const Mesh              &mesh,
                      const Utilities::Point3 &push,
                      const SphereSizing      &sizing = SphereSizing()) const;
  };


  /**
   * A check of a scene's mesh that a layer above the mesh adds (the
   * effects': a traction's faces), run by NodeSelection::create() after the
   * fixed nodes are chosen and before the active node, so that a scene
   * fails before anything is computed. Throws the scene's InputError.
   */
  using MeshCheck = void (*)(const Scene &scene, const Mesh &mesh);

  /** Add @p check to those NodeSelection::create() runs (at static
   * initialisation, by the layer that defines it). Returns true. */
  bool
  add_mesh_check(MeshCheck check);
} // namespace palpate

#endif
