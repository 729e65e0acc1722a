// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

#ifndef palpate_state_space_state_grid_h
#define palpate_state_space_state_grid_h

#include <palpate/base/utilities.h>

#include <array>
#include <vector>

namespace palpate
{
  /** Integer coordinates (i, j, k) of a grid point. */
  using GridIndex = std::array<int, 3>;

  /**
   * The state space: a regular grid of active-node displacements, centred
   * on the active node's rest position. Point (i, j, k) is the displacement
   * h (i, j, k), with |i|, |j|, |k| <= n = floor(extent / h). Cells are the
   * cubes between neighbouring points; inside a cell, force and shape are
   * interpolated trilinearly from its 8 corners.
   *
   * Pure arithmetic, no allocation: the real-time thread uses it.
   */
  class StateGrid
  {
  public:
    /** @p spacing h and @p extent (half-width), both in metres. */
    StateGrid(const double spacing, const double extent);

    /** Grid spacing h (m). */
    double
    spacing() const noexcept
    {
      return h;
    }

    /** Points per half-axis: indices run from -n to n. */
    int
    half_width() const noexcept
    {
      return n;
    }

    /** Number of grid points, (2n + 1)^3. */
    unsigned int
    size() const noexcept
    {
      return side * side * side;
    }

    /** Whether (i, j, k) is a point of the grid. */
    bool
    contains(const GridIndex &g) const noexcept;

    /** The linear number of point @p g (which must be in the grid). */
    unsigned int
    linear(const GridIndex &g) const noexcept;

    /** The point with linear number @p p. */
    GridIndex
    index(const unsigned int p) const noexcept;

    /** Displacement of the active node at point @p g (m). */
    Utilities::Point3
    position(const GridIndex &g) const noexcept;

    /** Displacement of the active node at point @p p (m). */
    Utilities::Point3
    position(const unsigned int p) const noexcept;

    /**
     * The point behind @p source as seen from @p target: source - (target
     * - source), the next point beyond the source on the grid line from
     * the target through it. False if it is outside the grid.
     */
    bool
    behind(const unsigned int source,
           const unsigned int target,
           unsigned int      &point) const noexcept;

    /** The grid point nearest to @p x (clamped to the grid). */
    GridIndex
    nearest(const Utilities::Point3 &x) const noexcept;

    /**
     * The cell that contains @p x: its lower corner and the local
     * coordinates of @p x in [0, 1]^3. Returns false if @p x lies outside
     * the grid (or is not finite).
     */
    bool
    locate(const Utilities::Point3 &x,
           GridIndex               &lower,
           std::array<double, 3>   &local) const noexcept;

    /**
     * The 8 corners of the cell with lower corner @p lower, as linear
     * numbers; corner c has offsets (c & 1, (c >> 1) & 1, (c >> 2) & 1).
     */
    std::array<unsigned int, 8>
    corners(const GridIndex &lower) const noexcept;

    /** Whether @p point is one of the 26 points around the origin (rest):
     * the corners, other than the origin, of the cells that touch it. */
    bool
    beside_origin(const unsigned int point) const noexcept;

    /** @p point and its (up to 26) neighbours inside the grid: the
     * points whose cross derivatives depend on it, and those its own
     * depend on. Not for the real-time side. */
    std::vector<unsigned int>
    neighbourhood(const unsigned int point) const;

  private:
    double       h;
    int          n;
    unsigned int side;
  };

  /**
   * Trilinear weights of the 8 corners (ordered as StateGrid::corners())
   * at local coordinates @p local in [0, 1]^3. They sum to 1.
   */
  std::array<double, 8>
  trilinear_weights(const std::array<double, 3> &local) noexcept;

  /**
   * The weights of the 8 corners (ordered as StateGrid::corners()) that
   * interpolate linearly on the tetrahedron of the cell's Kuhn
   * triangulation (6 tetrahedra along its main diagonal) holding
   * @p local: at most 4 are not zero, they sum to 1, are continuous
   * across cells and tetrahedra, and are 1 at their own corner.
   *
   * The contact patch blends its corners by them (PatchContact::blend()),
   * so that a tick solves the contact of 4 corners, not 8: against the
   * trilinear weights of all 8 the same accuracy against direct solves
   * for half the work (doc/benchmarks/contact-patch.md).
   */
  std::array<double, 8>
  simplex_weights(const std::array<double, 3> &local) noexcept;

  /**
   * The 4 corners (ordered as StateGrid::corners()) of that tetrahedron,
   * from corner 0 to corner 7, each the one before with one more upper
   * axis: along the axes by decreasing coordinate of @p local.
   */
  std::array<unsigned int, 4>
  simplex_corners(const std::array<double, 3> &local) noexcept;
} // namespace palpate

#endif
