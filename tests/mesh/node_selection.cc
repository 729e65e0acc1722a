// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

// Fixed and active node selection on a 10 x 2 x 2 beam of 0.1 x 0.02 x
// 0.02 m, whose node counts are known: 3 x 3 nodes per cross-section, 11
// sections, the 9 interior nodes on the axis. Each way of selecting fixed
// nodes, the surface-only rule, the nearest surface node, and the
// selections that must be refused.

#include <palpate/base/exceptions.h>
#include <palpate/mesh/mesh.h>
#include <palpate/mesh/node_selection.h>
#include <palpate/scene/scene.h>

#include "../tests.h"

namespace
{
  void
  report(const std::string    &what,
         const palpate::Scene &scene,
         const palpate::Mesh  &mesh)
  {
    try
      {
        const auto s = palpate::NodeSelection::create(scene, mesh);
        deallog
          << what << ": " << s.fixed_vertices.size() << " fixed, active node "
          << mesh.node_id(s.active_vertex) << " at ("
          << palpate::Utilities::to_string(mesh.vertices()[s.active_vertex], 4)
          << "), " << 1000 * s.active_distance << " mm from Point" << std::endl;
      }
    catch (const palpate::InputError &e)
      {
        deallog << what << ": refused" << std::endl
                << "  entry:   " << e.entry() << std::endl
                << "  problem: " << e.problem() << std::endl;
      }
  }
} // namespace

int
main(int argc, char **argv)
{
  palpate::Environment env(argc, argv);
  initlog(4);

  palpate::Scene scene;
  auto          &p         = scene.parameters;
  p.mesh.source            = "beam";
  const palpate::Mesh mesh = palpate::Mesh::create(scene);
  deallog << "beam: " << mesh.n_vertices() << " nodes, "
          << mesh.n_surface_vertices() << " on the surface" << std::endl;

  auto &f     = p.boundary_conditions.fixed_nodes;
  auto &a     = p.boundary_conditions.active_node;
  a.selection = "nearest surface node";
  a.point     = {{0.105, 0.001, 0.012}}; // just outside the free end's corner

  f.selection    = "boundary id";
  f.boundary_ids = {0};
  report("boundary id 0 (x = 0)", scene, mesh);
  f.boundary_ids = {0, 4};
  report("boundary ids 0 and 4 (x = 0, z = -0.01)", scene, mesh);

  f.selection          = "box";
  f.box_lower_corner   = {{-1, -1, -1}};
  f.box_upper_corner   = {{0.015, 1, 1}};
  f.surface_nodes_only = true;
  report("box x <= 0.015, surface only", scene, mesh);
  f.box_lower_corner   = {{0.005, -0.001, -0.001}};
  f.box_upper_corner   = {{0.095, 0.001, 0.001}};
  f.surface_nodes_only = false;
  report("box around the axis, interior included", scene, mesh);
  f.surface_nodes_only = true;
  report("box around the axis, surface only", scene, mesh);

  f.selection          = "half-space";
  f.half_space_point   = {{0.02, 0, 0}};
  f.half_space_normal  = {{-1, 0, 0}};
  f.surface_nodes_only = true;
  report("half-space x <= 0.02, surface only", scene, mesh);
  f.surface_nodes_only = false;
  report("half-space x <= 0.02, all", scene, mesh);
  f.half_space_point = {{0.2, 0, 0}};
  report("half-space x <= 0.2 (everything)", scene, mesh);
  f.half_space_point = {{-0.5, 0, 0}};
  report("half-space x <= -0.5 (nothing)", scene, mesh);

  f.selection = "node list";
  f.node_ids  = {0, 1, 2};
  report("node list 0 1 2", scene, mesh);
  f.node_ids = {0, 12345};
  report("node list with an unknown node", scene, mesh);

  // Collinear fixed nodes leave a rotation free.
  f.selection          = "box";
  f.box_lower_corner   = {{-1, -0.001, -0.011}};
  f.box_upper_corner   = {{1, 0.001, -0.009}};
  f.surface_nodes_only = true;
  report("the bottom centre line (collinear)", scene, mesh);

  // The active node.
  f.selection    = "boundary id";
  f.boundary_ids = {0};
  a.point        = {{0, 0, 0}};
  report("active node nearest to the clamped face's centre", scene, mesh);
  a.selection = "node id";
  for (unsigned int v = 0; v < mesh.n_vertices(); ++v)
    if (!mesh.on_surface()[v])
      {
        a.node_id = mesh.node_id(v);
        break;
      }
  report("active node in the interior", scene, mesh);
  a.node_id = 999;
  report("active node that does not exist", scene, mesh);
  a.node_id = mesh.node_id(mesh.n_vertices() - 1);
  report("active node by id", scene, mesh);
}
