// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

#include <palpate/hyperelastic/effect.h>
#include <palpate/mesh/mesh.h>
#include <palpate/mesh/node_selection.h>
#include <palpate/scene/scene.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <set>
#include <sstream>

namespace palpate
{
  namespace
  {
    using Utilities::Point3;

    using Utilities::cross;
    using Utilities::dot;
    using Utilities::minus;

    /**
     * Whether the points span at least a plane. Points on one line (or a
     * single point) leave a rotation free: the stiffness matrix is
     * singular and no state can be computed.
     */
    bool
    holds_body(const std::vector<Point3> &points, const double length_scale)
    {
      if (points.size() < 3)
        return false;
      // The two points farthest apart define a line; some point must be
      // off it by more than round-off.
      unsigned int a = 0, b = 0;
      double       best = -1;
      for (unsigned int i = 0; i < points.size(); ++i)
        {
          const double d = Utilities::distance(points[0], points[i]);
          if (d > best)
            best = d, a = i;
        }
      best = -1;
      for (unsigned int i = 0; i < points.size(); ++i)
        {
          const double d = Utilities::distance(points[a], points[i]);
          if (d > best)
            best = d, b = i;
        }
      const Point3 axis = minus(points[b], points[a]);
      if (Utilities::norm(axis) <= 1e-9 * length_scale)
        return false;
      for (const auto &p : points)
        if (Utilities::norm(cross(axis, minus(p, points[a]))) /
              Utilities::norm(axis) >
            1e-6 * length_scale)
          return true;
      return false;
    }



    /**
     * The sphere's rest placement (Tip = sphere). It touches the surface
     * at the anchor: the point of the surface nearest to the scene's Point
     * (Selection = nearest surface node), or the active node (Selection =
     * node id). Touching a point of the surface rather than its nearest
     * node puts the sphere at the same place on every mesh of the organ,
     * which a study of the force's convergence needs. The normal is the
     * area-weighted mean of the outward normals of the surface triangles
     * within one radius of the anchor (and of the anchor's own): on a
     * coarse mesh one triangle's normal would tilt the sphere by its
     * facet. The centre is one radius out along the normal, then lifted
     * further along it until no surface node (vertex, or edge midpoint of
     * a surface triangle: the nodes a P2 contact sees) is inside the
     * sphere. For a node X at d = X - P from the unlifted centre P,
     * |d - t n| >= R holds for t >= d.n + sqrt((d.n)^2 - |d|^2 + R^2).
     */
    double
    place_sphere(const Mesh              &mesh,
                 const double             R,
                 const Utilities::Point3 *point,
                 const bool               midpoints,
                 NodeSelection           &selection)
    {
      using namespace Utilities;
      const auto  &x            = mesh.vertices();
      const auto  &faces        = mesh.surface_faces();
      Point3       anchor       = x[selection.active_vertex];
      unsigned int nearest_face = 0;
      double       best         = std::numeric_limits<double>::max();
      for (unsigned int f = 0; f < faces.size(); ++f)
        {
          const auto  &v = faces[f].vertices;
          const Point3 q = Utilities::closest_on_triangle(
            point != nullptr ? *point : anchor, x[v[0]], x[v[1]], x[v[2]]);
          const double d = distance(q, point != nullptr ? *point : anchor);
          if (d < best)
            {
              best         = d;
              nearest_face = f;
              if (point != nullptr)
                anchor = q;
            }
        }
      Point3 n = {{0, 0, 0}};
      for (unsigned int f = 0; f < faces.size(); ++f)
        {
          const auto  &v        = faces[f].vertices;
          const Point3 centroid = {
            {(x[v[0]][0] + x[v[1]][0] + x[v[2]][0]) / 3,
             (x[v[0]][1] + x[v[1]][1] + x[v[2]][1]) / 3,
             (x[v[0]][2] + x[v[1]][2] + x[v[2]][2]) / 3}};
          if (f != nearest_face && distance(centroid, anchor) > R)
            continue;
          // Surface faces are oriented outward (Mesh): the cross product
          // is twice the area times the normal.
          const Point3 c =
            cross(minus(x[v[1]], x[v[0]]), minus(x[v[2]], x[v[0]]));
          for (unsigned int d = 0; d < 3; ++d)
            n[d] += c[d];
        }
      n                       = scaled(n, 1 / std::max(norm(n), 1e-300));
      selection.active_normal = n;
      const Point3 P          = {
                 {anchor[0] + R * n[0], anchor[1] + R * n[1], anchor[2] + R * n[2]}};
      double     lift  = 0;
      const auto clear = [&](const Point3 &X) {
        const Point3 d  = minus(X, P);
        const double dn = dot(d, n);
        const double q  = dn * dn - dot(d, d) + R * R;
        if (dot(d, d) < R * R && q > 0)
          lift = std::max(lift, dn + std::sqrt(q));
      };
      for (const auto &face : faces)
        for (unsigned int i = 0; i < 3; ++i)
          {
            const Point3 &A = x[face.vertices[i]],
                         &B = x[face.vertices[(i + 1) % 3]];
            clear(A);
            clear({{(A[0] + B[0]) / 2, (A[1] + B[1]) / 2, (A[2] + B[2]) / 2}});
          }
      selection.sphere_lift   = lift;
      selection.sphere_center = {
        {P[0] + lift * n[0], P[1] + lift * n[1], P[2] + lift * n[2]}};

      // How far from the sphere's axis (through the anchor, along n) the
      // nearest surface node is (a vertex; @p midpoints: or an edge
      // midpoint, a P2 contact node). Pushed along -n, the sphere cuts the
      // surface in a circle of at most its radius: a smaller sphere never
      // has a node inside, and renders no force at any depth.
      const auto lateral = [&](const Point3 &X) {
        const Point3 d  = minus(X, anchor);
        const double dn = dot(d, n);
        return std::sqrt(std::max(0.0, dot(d, d) - dn * dn));
      };
      double nearest = std::numeric_limits<double>::max();
      for (const auto &face : faces)
        for (unsigned int i = 0; i < 3; ++i)
          {
            const Point3 &A = x[face.vertices[i]],
                         &B = x[face.vertices[(i + 1) % 3]];
            nearest         = std::min(nearest, lateral(A));
            if (midpoints)
              nearest = std::min(nearest,
                                 lateral({{(A[0] + B[0]) / 2,
                                           (A[1] + B[1]) / 2,
                                           (A[2] + B[2]) / 2}}));
          }
      const double hole = nearest;
      return hole;
    }
  } // namespace



  namespace
  {
    /** The fixed nodes a scene selects, and how it selects them. */
    struct FixedRegion
    {
      std::set<unsigned int> fixed;
      /** The scene entry that defines the region, for messages. */
      std::string region_entry;
      /** The nodes in the region, surface or not. */
      unsigned int in_region = 0;
      std::string  description;
    };



    /** The fixed nodes the scene's Fixed nodes section selects. */
    FixedRegion
    select_fixed(const Scene &scene, const Mesh &mesh)
    {
      const auto &f       = scene.parameters.boundary_conditions.fixed_nodes;
      const auto &x       = mesh.vertices();
      const auto &surface = mesh.on_surface();

      std::set<unsigned int> fixed;
      std::string            region_entry;
      unsigned int       in_region = 0; // nodes in the region, surface or not
      std::ostringstream description;

      if (f.selection == "boundary id")
        {
          region_entry = "Boundary conditions/Fixed nodes/Boundary ids";
          const std::set<unsigned int> ids(f.boundary_ids.begin(),
                                           f.boundary_ids.end());
          for (const auto &face : mesh.surface_faces())
            if (ids.count(face.boundary_id))
              fixed.insert(face.vertices.begin(), face.vertices.end());
          in_region = fixed.size();
          description << "nodes on boundary faces with id";
          for (const auto id : f.boundary_ids)
            description << " " << id;
        }
      else if (f.selection == "box" || f.selection == "half-space")
        {
          const bool box = f.selection == "box";
          region_entry   = box ?
                             "Boundary conditions/Fixed nodes/Box lower corner" :
                             "Boundary conditions/Fixed nodes/Half-space point";
          for (unsigned int v = 0; v < x.size(); ++v)
            {
              bool inside = true;
              if (box)
                {
                  for (unsigned int d = 0; d < 3; ++d)
                    inside = inside && x[v][d] >= f.box_lower_corner[d] &&
                             x[v][d] <= f.box_upper_corner[d];
                }
              else
                inside = dot(minus(x[v], f.half_space_point),
                             f.half_space_normal) >= 0;
              if (inside)
                {
                  ++in_region;
                  if (!f.surface_nodes_only || surface[v])
                    fixed.insert(v);
                }
            }
          if (box)
            description << "nodes in the box ["
                        << Utilities::to_string(f.box_lower_corner, 4)
                        << "] - ["
                        << Utilities::to_string(f.box_upper_corner, 4) << "] m";
          else
            description << "nodes x with (x - ("
                        << Utilities::to_string(f.half_space_point, 4)
                        << ")) . ("
                        << Utilities::to_string(f.half_space_normal, 4)
                        << ") >= 0";
          if (f.surface_nodes_only)
            description << ", surface only";
        }
      else // node list
        {
          region_entry = "Boundary conditions/Fixed nodes/Node ids";
          for (const long id : f.node_ids)
            {
              const auto v = mesh.vertex_of_node_id(id);
              if (!v)
                throw scene.error(region_entry,
                                  "the mesh has no node " + std::to_string(id),
                                  "use node numbers as the mesh file numbers "
                                  "them (Gmsh node tags, VTK point indices "
                                  "from 0); the VTU output shows them as "
                                  "'node id'.");
              fixed.insert(*v);
            }
          in_region = fixed.size();
          description << "node list (" << fixed.size() << " nodes)";
        }
      return {fixed, region_entry, in_region, description.str()};
    }



    /**
     * That the fixed nodes of @p region hold the body: there are some, and
     * not all on one line.
     */
    void
    check_fixed(const Scene &scene, const Mesh &mesh, const FixedRegion &region)
    {
      const auto &x            = mesh.vertices();
      const auto &fixed        = region.fixed;
      const auto &region_entry = region.region_entry;
      const auto &in_region    = region.in_region;
      const auto &description  = region.description;

      if (fixed.empty())
        {
          std::string problem =
            "the fixed-node selection (" + description + ") selects no node";
          if (in_region > 0)
            problem += ": the region holds " + std::to_string(in_region) +
                       " nodes, but none on the surface";
          const auto box = mesh.bounding_box();
          throw scene.error(region_entry,
                            problem + ", so nothing holds the body",
                            "move the region onto the body, whose bounding box "
                            "is [" +
                              Utilities::to_string(box.first, 4) + "] - [" +
                              Utilities::to_string(box.second, 4) +
                              "] m, or set Surface nodes only = false.");
        }

      {
        std::vector<Point3> points;
        for (const unsigned int v : fixed)
          points.push_back(x[v]);
        if (!holds_body(points, mesh.diameter()))
          throw scene.error(region_entry,
                            "the " + std::to_string(points.size()) +
                              " fixed node(s) lie on one line, so the body "
                              "could still rotate about it: no equilibrium "
                              "state is unique",
                            "fix at least three nodes that are not on one "
                            "line, e.g. by enlarging the region.");
      }
    }



    /**
     * The effects that depend on the mesh (a traction's faces) check it
     * now, before anything is computed.
     */
    void
    check_effects(const Scene &scene, const Mesh &mesh)
    {
      for (const auto &effect :
           Effect::create_enabled(scene.parameters.effects))
        try
          {
            effect->check(mesh);
          }
        catch (const Plugins::EntryError &e)
          {
            throw scene.error("Effects/" + e.entry, e.problem, e.fix);
          }
    }



    /**
     * The active node: the node of the scene's Node id, or the surface node
     * nearest to its Point (and how far that is, in @p selection).
     */
    void
    select_active_vertex(const Scene   &scene,
                         const Mesh    &mesh,
                         NodeSelection &selection)
    {
      const auto &a       = scene.parameters.boundary_conditions.active_node;
      const auto &x       = mesh.vertices();
      const auto &surface = mesh.on_surface();

      if (a.selection == "node id")
        {
          const auto v = mesh.vertex_of_node_id(a.node_id);
          if (!v)
            throw scene.error(
              "Boundary conditions/Active node/Node id",
              "the mesh has no node " + std::to_string(a.node_id),
              "use a node number as the mesh file numbers it, or "
              "Selection = nearest surface node.");
          if (!surface[*v])
            throw scene.error("Boundary conditions/Active node/Node id",
                              "node " + std::to_string(a.node_id) +
                                " is inside the body, not on its surface",
                              "the haptic probe touches the surface: choose a "
                              "surface node, or Selection = nearest surface "
                              "node with a Point on the skin.");
          selection.active_vertex = *v;
        }
      else
        {
          // (hypot: a Point at 1e300 m is that far, not 'inf', and its
          // nearest node is not an arbitrary one.)
          const auto from_point = [&](const unsigned int v) {
            return std::hypot(x[v][0] - a.point[0],
                              x[v][1] - a.point[1],
                              x[v][2] - a.point[2]);
          };
          double best = std::numeric_limits<double>::infinity();
          for (unsigned int v = 0; v < x.size(); ++v)
            if (surface[v] && from_point(v) < best)
              {
                best                    = from_point(v);
                selection.active_vertex = v;
              }
          selection.active_distance = best;
          // The probe touches the surface where Point is: a Point a quarter
          // of the body away from it (-1, 0.11, 0.1 beside a 25 cm liver:
          // 824 mm) is a mistake, not a place to palpate.
          if (!(best <= 0.25 * mesh.diameter()))
            throw scene.error(
              "Boundary conditions/Active node/Point",
              "the nearest surface node (node " +
                std::to_string(mesh.node_id(selection.active_vertex)) + " at " +
                Utilities::to_string(x[selection.active_vertex], 4) +
                " m) is " + Utilities::to_string(best, 3) +
                " m from Point, more than a quarter of the body's size (" +
                Utilities::to_string(mesh.diameter(), 3) +
                " m across): Point is not on the organ",
              "give a point on (or next to) the surface where the probe "
              "touches, in metres, in the mesh's coordinates after Scale "
              "factor: the body's bounding box is " +
                Utilities::to_string(mesh.bounding_box().first, 3) + " to " +
                Utilities::to_string(mesh.bounding_box().second, 3) + " m.");
        }
    }



    /** That the active node is not one of the fixed nodes. */
    void
    check_active_not_fixed(const Scene                  &scene,
                           const Mesh                   &mesh,
                           const std::set<unsigned int> &fixed,
                           const NodeSelection          &selection)
    {
      const auto &a = scene.parameters.boundary_conditions.active_node;
      const auto &x = mesh.vertices();
      if (fixed.count(selection.active_vertex))
        throw scene.error(
          a.selection == "node id" ? "Boundary conditions/Active node/Node id" :
                                     "Boundary conditions/Active node/Point",
          "the active node (node " +
            std::to_string(mesh.node_id(selection.active_vertex)) + " at " +
            Utilities::to_string(x[selection.active_vertex], 4) +
            " m) is also a fixed node, so it cannot move",
          "choose an active node outside the fixed region, or "
          "shrink the region.");
    }



    /**
     * The longest edge (between contact nodes: @p midpoints halve the
     * edges) of the surface triangles with a vertex within @p reach of
     * the path from @p anchor to @p anchor + @p slide (a move along the
     * surface meets the triangles on its way, not only those at rest).
     */
    double
    longest_edge_near(const Mesh              &mesh,
                      const Utilities::Point3 &anchor,
                      const Utilities::Point3 &slide,
                      const double             reach,
                      const bool               midpoints)
    {
      const auto  &x       = mesh.vertices();
      const double s2      = Utilities::dot(slide, slide);
      const auto   to_path = [&](const Utilities::Point3 &p) {
        const auto   d = Utilities::minus(p, anchor);
        const double t =
          s2 > 0 ? std::clamp(Utilities::dot(d, slide) / s2, 0.0, 1.0) : 0.0;
        Utilities::Point3 q;
        for (unsigned int k = 0; k < 3; ++k)
          q[k] = anchor[k] + t * slide[k];
        return Utilities::distance(p, q);
      };
      double longest = 0;
      for (const auto &face : mesh.surface_faces())
        {
          bool near = false;
          for (const unsigned int v : face.vertices)
            near = near || to_path(x[v]) <= reach;
          if (!near)
            continue;
          for (unsigned int i = 0; i < 3; ++i)
            longest =
              std::max(longest,
                       Utilities::distance(x[face.vertices[i]],
                                           x[face.vertices[(i + 1) % 3]]) /
                         (midpoints ? 2 : 1));
        }
      return longest;
    }



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

    double
    margin_at(const double depth, const double slide, const double R)
    {
      // Pushed along the normal, one radius deep needs no margin yet: a 1
      // cm sphere pushed 1 cm into the beam, clearing its 14 mm edges by
      // 1.06, renders Hertz's force (the study's and the indenter tests).
      if (depth > R)
        return margin;
      if (!(slide > 0.5 * R))
        return 1;
      return 1 + (margin - 1) * std::clamp(2 * depth / R - 1, 0.0, 1.0);
    }

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
               const double         R)
    {
      const auto &a    = scene.parameters.boundary_conditions.active_node;
      const auto &push = a.prescribed_displacement;
      const bool  p2   = scene.displacement_degree() == 2;
      SphereFit   fit;
      fit.placed       = selection;
      const auto place = [&](const bool midpoints) {
        return place_sphere(mesh,
                            R,
                            a.selection == "node id" ? nullptr : &a.point,
                            midpoints,
                            fit.placed);
      };
      // With quadratic elements the edge midpoints are contact nodes too,
      // and halve the spacing the checks measure; but only for a push that
      // needs no margin. Pushed deep, the midpoints do not hold a sphere
      // as the vertices do: with Taylor-Hood on the graded liver of
      // liver-indenter.prm (a 1 cm push), 3 and 4 mm spheres, clearing the
      // midpoints' spacing 1.7 and 2.3 times, are failure points, while
      // 6 mm, clearing the vertices' 1.7 times, converges.
      fit.hole = place(false);
      // A pull presses the sphere no deeper, and a move along the surface
      // only as far as its inward component: the depth. Its sideways part,
      // the slide, takes the sphere over other triangles (below).
      const auto  &n      = fit.placed.active_normal;
      const double inward = -Utilities::dot(push, n);
      fit.depth           = std::max(inward, 0.0);
      Utilities::Point3 slide;
      for (unsigned int d = 0; d < 3; ++d)
        slide[d] = push[d] + inward * n[d];
      fit.required = margin_at(fit.depth, Utilities::norm(slide), R);
      // Placed among the midpoints too (none inside it at rest), but
      // measured on them only when no margin is needed.
      if (p2)
        {
          const double between_midpoints = place(true);
          if (fit.required == 1)
            {
              fit.hole      = between_midpoints;
              fit.midpoints = true;
            }
        }
      // Pushed in by a depth d, the sphere cuts the surface in a circle of
      // radius sqrt(2 R d - d^2), at most R (at d = R): a sphere smaller
      // than the distance never meets a node. On liver501 (the nearest
      // node 4.3 mm away), a 6 mm sphere pushed 1 cm still passes between
      // the nodes (0 N) and a 1 cm one renders 0.27 N: twice the distance
      // makes the first node touch within a quarter of it.
      //
      // Moved along the surface, the sphere meets the triangles around
      // the anchor, not only its nearest node. Pressed onto a triangle of
      // circumradius rho it sinks between the nodes to sqrt(R^2 - rho^2)
      // from them; held by a node it must stay half a radius out
      // (StateSolver: "sphere through the surface"), so rho <= 0.87 R, and
      // an edge L (rho >= L / sqrt(3)) at most 1.5 R. A 1 cm sphere on
      // liver501 (edges up to 2 cm) passes the first check near a node,
      // yet every grid point beside rest is a failure point: without this
      // check the run renders 0 N throughout and exits 0. The triangles
      // within two radii of the anchor's path; with P2 the midpoints halve
      // the edges.
      Utilities::Point3 anchor;
      for (unsigned int d = 0; d < 3; ++d)
        anchor[d] =
          fit.placed.sphere_center[d] - (R + fit.placed.sphere_lift) * n[d];
      fit.longest =
        longest_edge_near(mesh, anchor, slide, 2 * R, fit.midpoints);
      const auto &x  = mesh.vertices();
      const auto &at = x[selection.active_vertex];
      for (const unsigned int v : selection.fixed_vertices)
        fit.support = std::min(fit.support, Utilities::distance(x[v], at));
      for (const auto &[v, component] : selection.fixed_components)
        fit.support = std::min(fit.support, Utilities::distance(x[v], at));
      fit.supported = fit.depth <= towards_support * fit.support;
      fit.meets     = R >= 2 * fit.hole && fit.longest <= 1.5 * R;
      fit.passes    = fit.depth <= deepest_push * R &&
                   R >= fit.required * 2 * fit.hole &&
                   fit.required * fit.longest <= 1.5 * R;
      return fit;
    }

    /**
     * Why @p fit, a sphere of radius @p R, fails place_sphere_tip()'s
     * checks, in words.
     */
    std::string
    sphere_problem(const double R, const SphereFit &fit)
    {
      if (R < 2 * fit.hole)
        return "is too small for the gaps between the surface nodes where "
               "it touches (the nearest is " +
               Utilities::to_string(fit.hole, 3) +
               " m away across the surface): the contact acts at nodes, "
               "so pushed in, the sphere passes between them and renders "
               "no force";
      if (!fit.meets)
        return "is smaller than the surface triangles around where it "
               "touches (edges up to " +
               Utilities::to_string(fit.longest, 3) + " m" +
               (fit.midpoints ? " between contact nodes" : "") +
               "): moved along the surface it sinks between the nodes, "
               "those states are failure points, and the haptic loop "
               "renders no force there";
      if (fit.depth > deepest_push * R)
        return "is pushed " + Utilities::to_string(fit.depth, 3) +
               " m deep (the push's part along the surface's inward normal "
               "at the probe; the push: Prescribed displacement, solve's "
               "--to or a trajectory's farthest point), more than " +
               Utilities::to_string(deepest_push, 3) +
               " times its radius: the tissue closes over the sphere, "
               "its nodes pass behind it and the state is a failure "
               "point (\"sphere through the surface\")";
      return "is pushed " + Utilities::to_string(fit.depth, 3) +
             " m deep (along the surface's inward normal at the probe; the "
             "push: Prescribed displacement, solve's --to or a trajectory's "
             "farthest point), more than its radius, or half of it while "
             "dragged along the surface, and clears the "
             "surface's node spacing where it touches (the nearest node " +
             Utilities::to_string(fit.hole, 3) + " m away, edges up to " +
             Utilities::to_string(fit.longest, 3) +
             " m within two radii of its path) by less than the " +
             Utilities::to_string(fit.required, 3) +
             " times that depth needs: pushed that deep, such a sphere "
             "slips between the nodes and the state is a failure point";
    }



    /** "a, b, c" with 3 digits each. */
    std::string
    list(const std::vector<double> &values)
    {
      std::string text;
      for (const double v : values)
        text += (text.empty() ? "" : ", ") + Utilities::to_string(v, 3);
      return text;
    }

    /** What tried_offer() found: the push to name with the radius ("" for
     * the scene's own), and what the trials said. */
    struct TriedOffer
    {
      std::string push, why;
    };

    /**
     * Where tried_offer() solves: the scene's push, or at rest (@p at_rest)
     * the 26 grid points around rest.
     */
    std::vector<Utilities::Point3>
    trial_targets(const Scene &scene, const bool at_rest)
    {
      // At rest (an interaction's scene) the states first computed are the
      // grid points around it, the corners of the cells that touch it: the
      // 26 one spacing away are tried, the diagonal ones too: on
      // liver-stvk.prm, 0.0171 m at Node id 36 converges at the six along
      // the axes and is a failure point at (0.01, 0, -0.01). The six along
      // the axes first: a radius that fails mostly fails there, and is
      // dropped sooner.
      std::vector<Utilities::Point3> targets;
      if (!at_rest)
        targets.push_back(scene.parameters.boundary_conditions.active_node
                            .prescribed_displacement);
      else
        {
          const double h = scene.parameters.state_space.grid_spacing;
          for (const unsigned int along : {1u, 2u, 3u})
            for (int i = -1; i <= 1; ++i)
              for (int j = -1; j <= 1; ++j)
                for (int k = -1; k <= 1; ++k)
                  if (static_cast<unsigned int>(std::abs(i) + std::abs(j) +
                                                std::abs(k)) == along)
                    targets.push_back({{i * h, j * h, k * h}});
        }
      return targets;
    }

    /** Whether a sphere of radius @p r passes the checks pushed to each of
     * @p targets. */
    bool
    passes_at_all(const Scene                          &scene,
                  const Mesh                           &mesh,
                  const NodeSelection                  &selection,
                  const std::vector<Utilities::Point3> &targets,
                  const double                          r)
    {
      Scene with = scene;
      for (const auto &to : targets)
        {
          with.parameters.boundary_conditions.active_node
            .prescribed_displacement = to;
          if (!fit_sphere(with, mesh, selection, r).passes)
            return false;
        }
      return true;
    }

    /**
     * Try the radius @p offer a refusal names (it passes the checks) by a
     * static solve to the scene's push, or at rest to the 26 grid points
     * around it (where it must pass the checks too); if it does not
     * converge, the next radii 25 % apart that pass, and if none does, a
     * shorter push with the radius that got farthest. @p offer becomes the
     * radius to name. Throws the refusal itself when nothing tried
     * converges.
     */
    template <typename FirstPassing>
    TriedOffer
    tried_offer(const Scene                      &scene,
                const Mesh                       &mesh,
                const NodeSelection              &selection,
                const NodeSelection::SphereTrial &trial,
                double                           &offer,
                const FirstPassing               &first_passing)
    {
      const double largest = 0.25 * mesh.diameter();
      const auto  &push    = scene.parameters.boundary_conditions.active_node
                           .prescribed_displacement;
      const bool at_rest = !(Utilities::norm(push) > 0);
      const std::vector<Utilities::Point3> targets =
        trial_targets(scene, at_rest);
      // The part of @p to a solve with radius r reaches, if r's sphere
      // passes the checks for that push (else -1).
      const auto reached = [&](const double r, const Utilities::Point3 &to) {
        Scene with                                                 = scene;
        with.parameters.boundary_conditions.active_node.tip_radius = r;
        with.parameters.boundary_conditions.active_node
          .prescribed_displacement = to;
        const SphereFit f          = fit_sphere(with, mesh, selection, r);
        return f.passes ? trial(with, mesh, f.placed) : -1.0;
      };
      // At rest a radius is tried only if it passes the checks at all the
      // targets (geometric, milliseconds): solving one that cannot be
      // offered would spend the 10 s the next radii have, and could leave
      // no radius to name where one converges at all 26.
      const auto passes_everywhere = [&](const double r) {
        return passes_at_all(scene, mesh, selection, targets, r);
      };
      const auto next_passing = [&](double r) {
        r = first_passing(r);
        while (at_rest && r <= largest && !passes_everywhere(r))
          r = first_passing(std::ceil(r * 1.02 * 1e4) / 1e4);
        return r;
      };
      offer = next_passing(offer);
      if (at_rest && offer > largest)
        throw scene.error(
          "Boundary conditions/Active node/Tip radius",
          "no sphere found here: no radius up to a quarter of the body (" +
            Utilities::to_string(largest, 3) +
            " m) passes the sphere's checks at all the 26 grid points "
            "around rest (State space / Grid spacing), the states an "
            "interaction computes first",
          "a mesh finer near the probe (Mesh / Source = surface with "
          "Refinement size about a third of the radius), another Point or "
          "Node id, or a smaller Grid spacing");
      // The least of the targets (stopping at the first that fails).
      const auto reached_all = [&](const double r) {
        double least = 1;
        for (const auto &to : targets)
          if ((least = std::min(least, reached(r, to))) < 1)
            break;
        return least;
      };
      // Up to three radii, the next ones only within 10 s: at Node id 27,
      // 0.9 - 2 times the offer all failed within 0.36 - 0.58 of the push,
      // so more would only cost time. A solve takes 2 - 5 s on the graded
      // liver, a minute with Taylor-Hood (whose refusal then tries one
      // radius and one push).
      const auto          start = std::chrono::steady_clock::now();
      double              best = offer, best_reached = -1;
      std::vector<double> radii;
      unsigned int        n_tried = 0;
      double              r       = offer;
      for (; r <= largest && n_tried < 3 &&
             (n_tried == 0 || std::chrono::steady_clock::now() - start <
                                std::chrono::seconds(10));
           r = next_passing(std::ceil(r * 1.25 * 1e4) / 1e4))
        {
          const double part = reached_all(r);
          ++n_tried;
          if (part >= 1)
            {
              offer = r;
              return {"",
                      n_tried == 1 ?
                        std::string() :
                        "; a static solve with it converged" +
                          (radii.empty() ?
                             std::string() :
                             ", with " + list(radii) + " m it did not")};
            }
          if (part >= 0) // (a radius failing the checks is not solved)
            radii.push_back(r);
          if (part > best_reached)
            best = r, best_reached = part;
        }
      const std::string tried = list(radii);
      if (at_rest)
        throw scene.error(
          "Boundary conditions/Active node/Tip radius",
          "no sphere found here: radii that pass the checks (" + tried +
            " m) were tried by static solves to the 26 grid points around "
            "rest (State space / Grid spacing), and with each some "
            "did not converge (failure points, no force there)" +
            // (Taylor-Hood: the first radius's trials may take minutes.)
            (n_tried < 3 && r <= largest ?
               "; larger ones were not tried (after the first radius, "
               "trials go on only within 10 s)" :
               ""),
          "a mesh finer near the probe (Mesh / Source = surface with "
          "Refinement size about a third of the radius), another Point or "
          "Node id, or a smaller Grid spacing" +
            std::string(n_tried < 3 && r <= largest ?
                          ", or try a larger Tip radius yourself, e.g. " +
                            Utilities::to_string(r, 3) +
                            " m (not solved here)" :
                          ""));
      // None converged: a shorter push along the same line, with the
      // radius that got farthest, tried too. (Shorter, it needs no larger
      // a radius: the checks' margin grows with the depth and the slide.)
      offer = best;
      std::vector<double> parts;
      for (double part =
             std::floor(0.9 * std::max(best_reached, 0.0) * 100) / 100;
           part >= 0.05 && parts.size() < 2;
           part = std::floor(0.5 * part * 100) / 100)
        {
          const Utilities::Point3 shorter = {
            {part * push[0], part * push[1], part * push[2]}};
          if (reached(best, shorter) >= 1)
            {
              std::vector<double> others;
              for (const double r : radii)
                if (r != best)
                  others.push_back(r);
              return {" and, as the push (Prescribed displacement, --to, "
                      "the trajectory), " +
                        Utilities::to_string(part, 3) + " times this one: " +
                        Utilities::to_string(shorter, 4) + " m",
                      "; a static solve with these converged, while to this "
                      "push it stopped at " +
                        Utilities::to_string(best_reached, 2) +
                        " of the way, a failure point" +
                        (others.empty() ? std::string() :
                                          ", as with " + list(others) + " m") +
                        " (Newton found no way on where the contact set "
                        "keeps changing)"};
            }
          parts.push_back(part);
        }
      throw scene.error(
        "Boundary conditions/Active node/Tip radius",
        "no sphere found for this push: radii that pass the checks here (" +
          tried +
          " m) were tried by a static solve to it, and none converged (the "
          "farthest got " +
          Utilities::to_string(std::max(best_reached, 0.0), 2) +
          " of the way)" +
          (parts.empty() ? std::string() :
                           ", nor to " + list(parts) + " times the push"),
        "a shorter push (Prescribed displacement, --to, the trajectory), a "
        "mesh finer near the probe (Mesh / Source = surface with Refinement "
        "size about a third of the radius), or other fixed nodes");
    }



    /**
     * Place the sphere (Tip = sphere), and check that it is large enough
     * to meet a node.
     */
    void
    place_sphere_tip(const Scene                      &scene,
                     const Mesh                       &mesh,
                     NodeSelection                    &selection,
                     const NodeSelection::SphereTrial &trial)
    {
      const auto     &a   = scene.parameters.boundary_conditions.active_node;
      const double    R   = a.tip_radius;
      const SphereFit fit = fit_sphere(scene, mesh, selection, R);
      if (fit.passes)
        {
          selection = fit.placed;
          return;
        }
      // Beyond towards_support no radius is offered: the one the checks
      // find can be a failure point there (above); the push is what to
      // change.
      const double no_deeper =
        std::floor(towards_support * fit.support * 1e4) / 1e4;
      if (!fit.supported)
        throw scene.error(
          "Boundary conditions/Active node/Tip radius",
          "a sphere of " + Utilities::to_string(R, 3) + " m radius " +
            sphere_problem(R, fit),
          "a push no deeper than " + Utilities::to_string(no_deeper, 3) +
            " m along the surface's inward normal (Prescribed displacement, "
            "--to, the trajectory), for which a radius is then offered. None "
            "is for this push, " +
            Utilities::to_string_apart(fit.depth, no_deeper) +
            " m deep, more than " + Utilities::to_string(towards_support, 3) +
            " of the way to the nearest fixed node (" +
            Utilities::to_string(fit.support, 3) +
            " m from the active node): the radius these checks find for so "
            "deep a push was measured to fail at some sites, Newton "
            "stagnating as the contact patch grows or the tissue squeezed "
            "against the fixed nodes (on the liver of liver-indenter.prm "
            "every push to 0.25 of the way converged, failure points from "
            "0.26; such a push already asks 5 - 8 N, about what a haptic "
            "device renders). Or fixed nodes farther from the probe "
            "(Boundary conditions / Fixed nodes).");
      // The radius to offer: the smallest that passes, found by trying
      // radii 2 % apart from what the figures at R ask for. R's figures
      // alone do not say what another radius needs: it touches another
      // patch, with another normal (worked out from them, about one offer
      // in six fails the checks when used). Nor is the rule monotonic (a
      // larger sphere looks at more triangles), so the offer is "a radius
      // that passes", not "at least".
      const double largest = 0.25 * mesh.diameter();
      double       offer =
        std::ceil(
          std::max(
            {2 * fit.hole, fit.longest / 1.5, fit.depth / deepest_push, 1e-4}) *
          1e4) /
        1e4;
      const auto first_passing = [&](double r) {
        while (r <= largest && !fit_sphere(scene, mesh, selection, r).passes)
          r = std::ceil(r * 1.02 * 1e4) / 1e4;
        return r;
      };
      offer = first_passing(offer);
      // Not the smallest that passes but the first from 10 % above it: the
      // smallest just clears the spacing and can be a failure point where
      // 1.1 times it converges (liver-stvk.prm, Node id 32, pushed (-2, 0,
      // -2) cm: 0.0159 m fails; 0.0175, 0.02 and 0.024 m converge).
      if (offer <= largest)
        if (const double above =
              first_passing(std::ceil(offer * 1.1 * 1e4) / 1e4);
            above <= largest)
          offer = above;
      // Tried by a static solve where one can be, so that what is offered
      // has converged: the checks are geometric and cannot foresee where
      // the contact Newton stagnates (about 2 % of the offers that pass
      // them are failure points; at Node id 27 of liver-indenter.prm every
      // radius from 0.9 to 2 times the offer stagnates at 0.4 of the push).
      const TriedOffer tried =
        offer <= largest && trial ?
          tried_offer(scene, mesh, selection, trial, offer, first_passing) :
          TriedOffer();
      // A push no deeper than half the radius needs no margin.
      const double shallow_enough = std::floor(0.5 * R * 1e4) / 1e4;
      const bool   p2             = scene.displacement_degree() == 2;
      throw scene.error(
        "Boundary conditions/Active node/Tip radius",
        "a sphere of " + Utilities::to_string(R, 3) + " m radius " +
          sphere_problem(R, fit),
        (offer <= largest ?
           "use a radius of " + Utilities::to_string(offer, 6) + " m" +
             tried.push +
             " (it passes these checks here, 10 % or more above the "
             "smallest that does: found by trying radii" :
           std::string("no radius up to a quarter of the "
                       "body passes these checks here (") +
             "tried radii") +
          " 2 % apart; a sphere must be at least twice the nearest node's "
          "distance and two thirds of the longest edge within two radii of "
          "its path, up to " +
          Utilities::to_string(margin, 2) +
          " times those when pushed deeper than its radius (dragged along "
          "the surface: rising from half a radius deep), where a sphere "
          "that just clears them slips between the nodes, "
          "and at least the depth over " +
          Utilities::to_string(deepest_push, 3) +
          ", as one pushed nearly its diameter deep goes through the "
          "surface" +
          tried.why +
          "), or a mesh finer near the probe (Mesh / Source = "
          "surface with Refinement size about a third of the radius)" +
          (!fit.meets ? std::string() :
                        ", or a push (Prescribed displacement, --to, the "
                        "trajectory) no longer than " +
                          Utilities::to_string(shallow_enough, 3) + " m") +
          (p2 || fit.required > 1 ?
             std::string(".") :
             std::string(", or Polynomial degree = 2 (the edge "
                         "midpoints become contact nodes).")));
    }



    /**
     * The surface nodes glued to the active node (Tip = glued nodes): those
     * within the tip's radius, not fixed.
     */
    void
    glue_tip_nodes(const Scene                  &scene,
                   const Mesh                   &mesh,
                   const std::set<unsigned int> &fixed,
                   NodeSelection                &selection)
    {
      const auto &a       = scene.parameters.boundary_conditions.active_node;
      const auto &x       = mesh.vertices();
      const auto &surface = mesh.on_surface();
      selection.tip_neighbour_distance = std::numeric_limits<double>::max();
      for (unsigned int v = 0; v < x.size(); ++v)
        if (v != selection.active_vertex && surface[v] && !fixed.count(v))
          {
            const double d =
              Utilities::distance(x[v], x[selection.active_vertex]);
            selection.tip_neighbour_distance =
              std::min(selection.tip_neighbour_distance, d);
            if (d <= a.tip_radius)
              selection.tip_vertices.push_back(v);
          }
    }
  } // namespace



  NodeSelection
  NodeSelection::create(const Scene       &scene,
                        const Mesh        &mesh,
                        const SphereTrial &trial)
  {
    const auto &a = scene.parameters.boundary_conditions.active_node;

    NodeSelection     selection;
    const FixedRegion region = select_fixed(scene, mesh);
    check_fixed(scene, mesh, region);
    selection.fixed_vertices.assign(region.fixed.begin(), region.fixed.end());
    selection.fixed_description = region.description;

    check_effects(scene, mesh);

    select_active_vertex(scene, mesh, selection);
    check_active_not_fixed(scene, mesh, region.fixed, selection);
    if (a.tip == Parameters::ActiveNode::Tip::sphere)
      place_sphere_tip(scene, mesh, selection, trial);
    if (a.tip == Parameters::ActiveNode::Tip::glued_nodes)
      glue_tip_nodes(scene, mesh, region.fixed, selection);
    return selection;
  }



  void
  NodeSelection::check_sphere_push(const Scene             &scene,
                                   const Mesh              &mesh,
                                   const Utilities::Point3 &push,
                                   const SphereTrial       &trial) const
  {
    Scene pushed = scene;
    pushed.parameters.boundary_conditions.active_node.prescribed_displacement =
      push;
    NodeSelection selection;
    selection.fixed_vertices   = fixed_vertices;
    selection.fixed_components = fixed_components;
    select_active_vertex(pushed, mesh, selection);
    place_sphere_tip(pushed, mesh, selection, trial);
  }
} // namespace palpate
