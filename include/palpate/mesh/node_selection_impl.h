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
    /**
     * How deep a sphere may be pushed, in radii: deeper, the tissue closes
     * over it, its nodes pass behind it and the state is a failure point.
     * The depth is the push's component along the surface's inward normal
     * at the probe: on the graded liver of liver-indenter.prm the first
     * failures come at 1.68 radii along the normal (a 6.1 mm sphere pushed
     * 1.1 cm along -z at the Point), and 1.5 stays below them (deeper
     * than a radius, the sphere must also clear the margin below). A
     * push's sideways part only slides the frictionless sphere (2 cm along
     * x, 4.3 mm in, converges at 0.308 N).
     * Measured with `palpate solve parameters/liver-indenter.prm --to
     * 0,0,-D` and the radius a refusal offers.
     */
    constexpr double deepest_push = 1.5;

    /**
     * How many times a sphere pushed deeper than its radius must clear the
     * node spacing the checks measure. The checks alone are what a sphere
     * needs to meet the nodes at all (a 1 cm sphere pressed 2 mm between
     * the beam's 14 mm edges renders Hertz's force); pushed that deep, one
     * that just passes them still slips between the nodes. On the graded
     * liver of liver-indenter.prm (edges up to 4.9 mm at Node ids 40 and
     * 41), spheres clearing the spacing 1.7 and 1.84 times are failure
     * points at 1.35 and 1.45 radii deep; 2.1 times holds at 1.45 radii,
     * and larger spheres at 1.54. Dragged along the surface the sphere
     * needs the margin from half a radius deep (margin_at()): a 4.2 mm
     * sphere clearing the spacing once, dragged 2 cm at 0.94 radii deep,
     * goes through the surface at Node id 37, while a 1 cm sphere 0.43
     * radii deep converges (0.308 N).
     * Measured with `palpate solve parameters/liver-indenter.prm`, pushes
     * along the inward normal.
     */
    constexpr double margin = 2.2;

    /**
     * How far towards the fixed nodes a refusal still offers a radius, as
     * a part of the distance from the active node to the nearest of them.
     * Deeper, the radius the checks find (at least the depth over 1.5)
     * makes a contact patch so large that Newton stagnates as it grows, or
     * the tissue is squeezed against the fixed nodes. On the graded liver
     * of liver-indenter.prm, pushed with the radius each refusal offers,
     * every push to 0.25 of the way converges (8 sites, 3 supports; and
     * liver-stvk.prm's 3 cm, 0.255), and failure points begin at 0.26:
     * 0.22 keeps a margin below them. Such a push asks 5 - 8 N there,
     * about what a haptic device renders (deeper, 15 - 60 N). A radius of
     * the user's own that passes the checks is not refused deeper: a 1 cm
     * sphere pushed 1 cm into the beam, half the way to its fixed end,
     * converges (the indenter tests), and a deeper push's failure point
     * says where it failed.
     * Measured 2026-11-27 (commit 6e87ee9; the table of every push is in
     * that day's change note in git history, CHANGELOG.md has the rule).
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
