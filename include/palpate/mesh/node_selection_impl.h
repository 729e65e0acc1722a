// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

#ifndef palpate_mesh_node_selection_impl_h
#define palpate_mesh_node_selection_impl_h

// Not an interface: choosing the nodes a scene fixes and moves
// (NodeSelection), shared by its source files, one job each:
//   node_selection.cc              NodeSelection::create() in order: the
//                                  fixed nodes, the effects' checks of the
//                                  mesh, the active node, the probe tip's
//                                  place()
//   node_selection_sphere_fit.cc   where a sphere tip rests, and whether
//                                  it meets the nodes for the scene's push
//   node_selection_sphere_offer.cc a sphere that fails its checks: the
//                                  refusal, and the radius it offers
//                                  (tried by the SphereSizing a layer
//                                  that solves gives)
// The sphere tip (probe_tips/sphere.cc) places itself through
// place_sphere_tip(). Users of node selection include node_selection.h,
// never this header.

#include <palpate/base/utilities.h>
#include <palpate/mesh/node_selection.h>

#include <limits>
#include <string>

namespace palpate
{
  class Mesh;
  class Scene;

  namespace internal
  {
    // The three constants of the sphere's checks below were measured on the
    // graded liver of liver-indenter.prm, pushing with the radius each
    // refusal offers: doc/formulation.md, "The sphere's checks and what
    // their constants rest on".

    /**
     * How deep a sphere may be pushed, in radii, along the surface's
     * inward normal at the probe: deeper, the tissue closes over it, its
     * nodes pass behind it and the state is a failure point. A push's
     * sideways part only slides the frictionless sphere, so it does not
     * count.
     */
    constexpr double deepest_push = 1.5;

    /**
     * How many times a sphere pushed deeper than its radius must clear the
     * node spacing the checks measure (from half a radius deep when
     * dragged along the surface): one that just clears it meets the nodes
     * when pressed, but slips between them when pushed that deep.
     */
    constexpr double margin = 2.2;

    /**
     * How far towards the fixed nodes a refusal still offers a radius, as
     * a part of the distance from the active node to the nearest of them.
     * Deeper, the radius the checks find (at least the depth over
     * deepest_push) makes a contact patch so large that Newton stagnates
     * as it grows, or the tissue is squeezed against the fixed nodes. A
     * radius of the user's own that passes the checks is not refused
     * deeper: a deeper push's failure point says where it failed.
     */
    constexpr double towards_support = 0.22;

    /** What place_sphere_tip()'s checks find for a sphere of one radius. */
    struct SphereFit
    {
      NodeSelection placed; // with the sphere's normal, centre and lift
      bool          midpoints = false;
      double        hole = 0, longest = 0, depth = 0, required = 1;
      /** The distance from the active node to the nearest fixed node. */
      double support = std::numeric_limits<double>::max();
      /** Pushed no farther towards them than a radius is offered for. */
      bool supported = true;
      /** It meets the nodes at all (the checks without a margin). */
      bool meets  = false;
      bool passes = false;
    };

    /**
     * Place a sphere of radius @p R at the scene's active node and ask the
     * checks, for the scene's push (Prescribed displacement, --to).
     */
    SphereFit
    fit_sphere(const Scene         &scene,
               const Mesh          &mesh,
               const NodeSelection &selection,
               const double         R);

    /**
     * Why @p fit, a sphere of radius @p R, fails place_sphere_tip()'s
     * checks, in words.
     */
    std::string
    sphere_problem(const double R, const SphereFit &fit);

    /**
     * The active node: the node of the scene's Node id, or the surface node
     * nearest to its Point (and how far that is, in @p selection).
     */
    void
    select_active_vertex(const Scene   &scene,
                         const Mesh    &mesh,
                         NodeSelection &selection);

    /**
     * Place the sphere (probe_tips/sphere.cc), and check that it is large
     * enough to meet a node.
     */
    void
    place_sphere_tip(const Scene                       &scene,
                     const Mesh                        &mesh,
                     NodeSelection                     &selection,
                     const NodeSelection::SphereSizing &sizing);
  } // namespace internal
} // namespace palpate

#endif
