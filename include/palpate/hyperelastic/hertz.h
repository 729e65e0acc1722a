// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

#ifndef palpate_hyperelastic_hertz_h
#define palpate_hyperelastic_hertz_h

#include <palpate/mesh/mesh.h>
#include <palpate/mesh/node_selection.h>
#include <palpate/scene/parameters.h>

#include <memory>
#include <string>

namespace palpate
{
  /**
   * Hertz's force of a rigid sphere of radius @p R (m) pressed @p depth (m)
   * into an elastic half-space of Young's modulus @p E (Pa) and Poisson's
   * ratio @p nu, without friction: F = 4/3 E/(1 - nu^2) R^(1/2) d^(3/2)
   * (N). Valid for small depths (contact radius a = sqrt(R d) << R).
   */
  double
  hertz_force(const double E,
              const double nu,
              const double R,
              const double depth);

  /**
   * The verification problem of the indenter: a quarter of a block, the
   * sphere touching the corner node at the origin from above (+z), so
   * that the block is the quarter x, y >= 0 of a half-space's neighbourhood
   * of the contact. The planes x = 0 and y = 0 are planes of symmetry
   * (their nodes slide on them), the bottom z = -depth is clamped, the
   * sides are free. The mesh is the tensor grid of graded_coordinates():
   * a spacing of @p h over the fine region of 2 contact radii, then
   * growing by 1.5 per element out to @p size, every element split in
   * @p split along each axis (split = 1, 2, 3, ... refines all elements
   * alike). The force on the whole sphere is 4 times the quarter's.
   */
  struct HertzBlock
  {
    /**
     * @p parameters: the material, discretisation and solver settings to
     * use (the tip is set to a sphere of radius @p R); @p contact_radius:
     * the expected contact radius sqrt(R d) (m), which sets the fine
     * region; @p size: the block's width and depth (m).
     */
    HertzBlock(const Parameters::AllParameters &parameters,
               const double                     R,
               const double                     contact_radius,
               const double                     size,
               const double                     h,
               const unsigned int               split);

    Parameters::AllParameters parameters;
    std::unique_ptr<Mesh>     mesh;
    NodeSelection             nodes;
    /** One line: the mesh's nodes, tetrahedra and finest spacing. */
    std::string description;
  };
} // namespace palpate

#endif
