// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

// Every mesh format palpate reads gives the same body: a generated beam is
// written as Gmsh 2.2 and 1, legacy VTK (classic and 5.1 cell layout) and
// VTU (ascii, base64, base64+zlib, appended raw, and deal.II's own
// GridOut::write_vtu, which repeats each vertex per cell), read back, and
// compared with the original: node and tetrahedron counts, volume, and (for
// Gmsh) the boundary ids.

#include <palpate/mesh/generators.h>
#include <palpate/mesh/mesh.h>
#include <palpate/mesh/mesh_file.h>
#include <palpate/scene/scene.h>

#include <deal.II/grid/grid_out.h>
#include <deal.II/grid/tria.h>

#include <zlib.h>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <map>

#include "../tests.h"

#include "../mesh_writers.h"


int
main(int argc, char **argv)
{
  palpate::Environment env(argc, argv);
  initlog();

  const MeshData      original = small_beam();
  const palpate::Mesh reference(original, 1.0, "beam");
  deallog << "original: " << reference.n_vertices() << " nodes, "
          << reference.n_cells() << " tetrahedra, volume " << reference.volume()
          << " m^3" << std::endl;

  std::vector<std::string> files = write_every_format(original);
  files.push_back("beam-dealii.vtu");
  {
    std::ofstream f("beam-dealii.vtu");
    dealii::GridOut().write_vtu(reference.triangulation(), f);
  }

  for (const std::string &name : files)
    {
      const MeshData                       data = palpate::read_mesh_file(name);
      const palpate::Mesh                  mesh(data, 1.0, name);
      std::map<unsigned int, unsigned int> ids;
      for (const auto &f : mesh.surface_faces())
        ++ids[f.boundary_id];
      const bool same = mesh.n_vertices() == reference.n_vertices() &&
                        mesh.n_cells() == reference.n_cells() &&
                        // deal.II's GridOut writes Float32 coordinates.
                        std::abs(mesh.volume() - reference.volume()) <
                          1e-6 * reference.volume();
      deallog << name << " (" << data.format << "): " << mesh.n_vertices()
              << " nodes, " << mesh.n_cells()
              << " tetrahedra, same body: " << (same ? "yes" : "NO")
              << ", boundary ids:";
      for (const auto &[id, n] : ids)
        deallog << " " << id << "x" << n;
      deallog << std::endl;
    }
}
