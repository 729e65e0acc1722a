// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

// The built-in meshes: the beam's volume is L W H exactly and its faces
// carry the ids 0..5; the blob is a closed, positively oriented body whose
// volume is close to that of its ellipsoid (4/3 pi a b c) and whose box is
// the semi-axes' box.

#include <palpate/mesh/generators.h>
#include <palpate/mesh/mesh.h>
#include <palpate/scene/scene.h>

#include <cmath>
#include <map>

#include "../tests.h"

int
main(int argc, char **argv)
{
  palpate::Environment env(argc, argv);
  initlog();

  palpate::Scene scene;
  auto          &p = scene.parameters.mesh;

  p.beam_length = 0.1, p.beam_width = 0.02, p.beam_height = 0.03;
  p.beam_subdivisions_length = 5, p.beam_subdivisions_width = 2,
  p.beam_subdivisions_height = 3;
  {
    const palpate::Mesh beam(palpate::generate_beam(p), 1.0, "beam");
    std::map<unsigned int, unsigned int> faces_per_id;
    for (const auto &f : beam.surface_faces())
      ++faces_per_id[f.boundary_id];
    deallog << "beam: " << beam.n_vertices() << " nodes (expected " << 6 * 3 * 4
            << "), " << beam.n_cells() << " tetrahedra" << std::endl;
    deallog << "beam volume error relative to L W H: "
            << std::abs(beam.volume() - 0.1 * 0.02 * 0.03) / (0.1 * 0.02 * 0.03)
            << std::endl;
    deallog << "beam boundary triangles per id:";
    for (const auto &[id, n] : faces_per_id)
      deallog << " " << id << ":" << n;
    deallog << std::endl;
  }

  for (const unsigned int refinements : {0u, 1u})
    {
      p.blob_semi_axes   = {{0.125, 0.09, 0.07}};
      p.blob_refinements = refinements;
      const palpate::Mesh blob(palpate::generate_blob(p), 1.0, "blob");
      const double        ellipsoid = 4. / 3. * M_PI * 0.125 * 0.09 * 0.07;
      const auto          box       = blob.bounding_box();
      deallog << "blob, " << refinements
              << " refinements: " << blob.n_vertices() << " nodes ("
              << blob.n_surface_vertices() << " on the surface), "
              << blob.n_cells() << " tetrahedra" << std::endl;
      deallog << "  volume / ellipsoid volume " << blob.volume() / ellipsoid
              << ", box [" << palpate::Utilities::to_string(box.first, 4)
              << "] - [" << palpate::Utilities::to_string(box.second, 4) << "]"
              << std::endl;
    }
}
