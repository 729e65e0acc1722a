// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

#include <palpate/mesh/fixed_region.h>
#include <palpate/mesh/mesh.h>
#include <palpate/mesh/node_selection.h>
#include <palpate/mesh/node_selection_impl.h>
#include <palpate/mesh/probe_tip.h>
#include <palpate/scene/scene.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <set>
#include <vector>

namespace palpate
{
  namespace
  {
    using Utilities::Point3;

    using Utilities::cross;
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
  } // namespace



  namespace
  {
    /** The fixed nodes a scene selects, and how it selects them. */
    struct FixedSelection
    {
      std::set<unsigned int> fixed;
      /** The scene entry that defines the region, for messages. */
      std::string region_entry;
      /** The nodes in the region, surface or not. */
      unsigned int in_region = 0;
      std::string  description;
    };



    /** The fixed nodes the scene's fixed region (Fixed nodes / Selection,
     * mesh/fixed_regions/) selects. */
    FixedSelection
    select_fixed(const Scene &scene, const Mesh &mesh)
    {
      const auto region   = FixedRegion::create(scene);
      const auto selected = region->select(scene, mesh);
      return {selected.fixed,
              region->entry(),
              selected.in_region,
              region->description(selected)};
    }



    /**
     * That the fixed nodes of @p region hold the body: there are some, and
     * not all on one line.
     */
    void
    check_fixed(const Scene          &scene,
                const Mesh           &mesh,
                const FixedSelection &region)
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
                              Utilities::to_string(box.second, 4) + "] m" +
                              // Inner nodes help only if the region has
                              // some, and only if they are excluded now.
                              (in_region > 0 ?
                                 ", or set Surface nodes only = false." :
                                 "."));
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



    /** The checks of the mesh that the layers above it added. */
    std::vector<MeshCheck> &
    mesh_checks()
    {
      // A function-local static: filled at static initialisation.
      static std::vector<MeshCheck> checks;
      return checks;
    }

  } // namespace



  namespace internal
  {
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
              "the nearest surface node (" +
                mesh.node_name(selection.active_vertex) + " at " +
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
  } // namespace internal



  namespace
  {
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
          "the active node (" + mesh.node_name(selection.active_vertex) +
            " at " + Utilities::to_string(x[selection.active_vertex], 4) +
            " m) is also a fixed node, so it cannot move",
          "choose an active node outside the fixed region, or "
          "shrink the region.");
    }
  } // namespace



  bool
  add_mesh_check(const MeshCheck check)
  {
    mesh_checks().push_back(check);
    return true;
  }



  NodeSelection
  NodeSelection::create(const Scene        &scene,
                        const Mesh         &mesh,
                        const SphereSizing &sizing)
  {
    NodeSelection        selection;
    const FixedSelection region = select_fixed(scene, mesh);
    check_fixed(scene, mesh, region);
    selection.fixed_vertices.assign(region.fixed.begin(), region.fixed.end());
    selection.fixed_description = region.description;

    for (const MeshCheck check : mesh_checks())
      check(scene, mesh);

    internal::select_active_vertex(scene, mesh, selection);
    check_active_not_fixed(scene, mesh, region.fixed, selection);
    // The tip puts itself at the active node: the nodes that move with it,
    // or a sphere resting on the surface.
    ProbeTip::create(scene)->place(
      scene, mesh, region.fixed, selection, sizing);
    return selection;
  }



  void
  NodeSelection::check_sphere_push(const Scene             &scene,
                                   const Mesh              &mesh,
                                   const Utilities::Point3 &push,
                                   const SphereSizing      &sizing) const
  {
    Scene pushed = scene;
    pushed.parameters.boundary_conditions.active_node.prescribed_displacement =
      push;
    NodeSelection selection;
    selection.fixed_vertices   = fixed_vertices;
    selection.fixed_components = fixed_components;
    internal::select_active_vertex(pushed, mesh, selection);
    internal::place_sphere_tip(pushed, mesh, selection, sizing);
  }
} // namespace palpate
