// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

#ifndef palpate_mesh_generators_h
#define palpate_mesh_generators_h

#include <palpate/mesh/mesh_file.h>
#include <palpate/scene/parameters.h>

#include <vector>

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

  /**
   * Where generate_blob() maps the point @p x of the unit ball, for
   * @p semi_axes (m): on |x| = 1, a point of the blob's surface. A surface
   * sampled with it can be meshed (Mesh / Source = surface) finer where a
   * probe works than the generator's uniform tetrahedra.
   */
  Utilities::Point3
  blob_shape(const Utilities::Point3 &x,
             const Utilities::Point3 &semi_axes) noexcept;

  /**
   * A block of tetrahedra on the tensor grid of the node coordinates
   * @p x, @p y, @p z (m, increasing), each grid brick split into six
   * tetrahedra along its main diagonal (Kuhn's subdivision, conforming
   * because every brick is split alike). Graded coordinates make a mesh
   * fine where something happens (under an indenter) and coarse far from
   * it; graded_coordinates() makes such a grid. All boundary faces get
   * id 0.
   */
  MeshData
  generate_tensor_block(const std::vector<double> &x,
                        const std::vector<double> &y,
                        const std::vector<double> &z);

  /**
   * Node coordinates 0 = t_0 < t_1 < ... = @p length (m): spacing @p h
   * up to @p fine_length, then growing by the factor @p growth per
   * interval (the last interval is stretched to end at @p length), and
   * then every interval split into @p split equal parts, so that
   * split = 1, 2, 3, ... is a sequence of nested meshes whose every
   * element shrinks alike: what a convergence study needs.
   */
  std::vector<double>
  graded_coordinates(const double       length,
                     const double       h,
                     const double       fine_length,
                     const double       growth,
                     const unsigned int split);
} // namespace palpate

#endif
