// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

#ifndef palpate_mesh_mesh_quality_h
#define palpate_mesh_mesh_quality_h

#include <palpate/base/utilities.h>

#include <array>
#include <string>
#include <vector>

namespace palpate
{
  /**
   * The shape quality of a tetrahedral mesh. The radius ratio is 3 r_in /
   * r_circ: 1 for the regular tetrahedron, 0 for a flat one. Dihedral
   * angles are between the faces at each edge: 70.5 degrees for the
   * regular tetrahedron. A sliver is a tetrahedron with a dihedral angle
   * below 5 or above 170 degrees, or a radius ratio below 0.1: its
   * stiffness matrix is badly conditioned and its strains are unreliable,
   * which matters most where the body deforms most (near the active node).
   */
  struct MeshQuality
  {
    double min_radius_ratio = 1, mean_radius_ratio = 1;
    double min_dihedral_degrees = 180, max_dihedral_degrees = 0;
    /** The slivers, as tetrahedron indices. */
    std::vector<unsigned int> slivers;

    /** One line: "radius ratio min 0.21, mean 0.78; dihedral angles 11.2 -
     * 158 degrees; 0 slivers". */
    std::string
    summary() const;
  };

  /** The quality of the tetrahedra @p cells on the points @p x. */
  MeshQuality
  mesh_quality(const std::vector<Utilities::Point3>           &x,
               const std::vector<std::array<unsigned int, 4>> &cells);
} // namespace palpate

#endif
