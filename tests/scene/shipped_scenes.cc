// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

// Every scene shipped in parameters/ parses, passes the scene checks, loads
// its mesh and selects its fixed and active nodes.

#include <palpate/mesh/mesh.h>
#include <palpate/mesh/node_selection.h>
#include <palpate/scene/scene.h>

#include <algorithm>
#include <filesystem>

#include "../tests.h"

int
main(int argc, char **argv)
{
  palpate::Environment env(argc, argv);
  initlog();

  const auto scenes = shipped_scenes();
  for (const auto &file : scenes)
    {
      const auto  scene = palpate::Scene::read(file.string());
      const auto  mesh  = palpate::Mesh::create(scene);
      const auto  nodes = palpate::NodeSelection::create(scene, mesh);
      const auto &p     = scene.parameters;
      deallog << file.filename().string() << ": " << p.material_model.model_name
              << ", " << mesh.n_vertices() << " nodes, " << mesh.n_cells()
              << " tetrahedra, " << nodes.fixed_vertices.size()
              << " fixed nodes, active node "
              << mesh.node_id(nodes.active_vertex) << std::endl;
    }
  deallog << scenes.size() << " scenes checked" << std::endl;
}
