// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

#include <palpate/mesh/mesh.h>
#include <palpate/mesh/node_selection_impl.h>
#include <palpate/scene/scene.h>

#include <algorithm>
#include <cmath>
#include <limits>

namespace palpate
{
  namespace internal
  {
    namespace
    {
      using Utilities::Point3;

      using Utilities::cross;
      using Utilities::dot;
      using Utilities::minus;

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
              clear(
                {{(A[0] + B[0]) / 2, (A[1] + B[1]) / 2, (A[2] + B[2]) / 2}});
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
    } // namespace



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
  } // namespace internal
} // namespace palpate
