// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

#ifndef palpate_mesh_generators_h
#define palpate_mesh_generators_h

#include <palpate/mesh/mesh_file.h>
#include <palpate/scene/parameters.h>

namespace palpate
{
  /**
   * A rectangular beam [0, L] x [-W/2, W/2] x [-H/2, H/2] (metres) of
   * tetrahedra: each of the Subdivisions hexahedral blocks is split into
   * tetrahedra by deal.II. Faces carry boundary ids 0..5 for x = 0, x = L,
   * y = -W/2, y = W/2, z = -H/2, z = H/2.
   */
  MeshData
  generate_beam(const Parameters::Mesh &parameters);

  /** An organ-like blob (metres): a cube of tetrahedra mapped onto the unit
   * ball (evenly spread surface nodes), then onto an
   * ellipsoid with the given semi-axes and then made asymmetric — one lobe
   * thicker and wider than the other, the underside flatter — so
   * that it behaves like a liver rather than a sphere. All boundary faces
   * get id 0.
   */
  MeshData
  generate_blob(const Parameters::Mesh &parameters);
} // namespace palpate

#endif
