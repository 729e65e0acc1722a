// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

#ifndef palpate_mesh_surface_repair_h
#define palpate_mesh_surface_repair_h

#include <palpate/mesh/surface.h>

#include <string>
#include <vector>

namespace palpate
{
  /**
   * What repair_surface() changed. Each repair is one that cannot change
   * the organ's shape: merging vertices that coincide, dropping triangles
   * without area or twice present, orienting the triangles consistently and
   * outward, removing closed shells of (almost) no volume, and closing small
   * holes with a fan of triangles.
   */
  struct SurfaceRepair
  {
    unsigned int merged_vertices      = 0;
    unsigned int unused_vertices      = 0;
    unsigned int degenerate_triangles = 0;
    unsigned int duplicate_triangles  = 0;
    unsigned int reoriented_triangles = 0;
    bool         turned_outward       = false;
    unsigned int removed_shells       = 0;
    unsigned int removed_triangles    = 0;
    double       removed_volume       = 0; // m^3
    unsigned int filled_holes         = 0;
    unsigned int fill_triangles       = 0;

    /** One line per repair made, for the user ("merged 2496 coincident
     * vertices (STL stores each triangle's own)"); empty if none. */
    std::vector<std::string>
    lines() const;
  };

  /**
   * Repair @p surface in place (see SurfaceRepair) and return what was
   * done. What is not safe to repair throws an InputError that names
   * @p filename, says where and what to do: an open surface (a hole larger
   * than @p max_hole_edges boundary edges or a rim of a quarter of the body's size), edges
   * shared by more than two triangles, a surface that cannot be oriented,
   * or two bodies of comparable volume.
   */
  SurfaceRepair
  repair_surface(Surface           &surface,
                 const std::string &filename,
                 const unsigned int max_hole_edges = 30);

  /**
   * The number of pairs of triangles of @p surface that intersect (pairs
   * sharing a vertex are not tested), and in @p where the centroid of one
   * such pair's first triangle. A broad phase on a uniform grid keeps it
   * about linear in the number of triangles.
   */
  unsigned int
  count_self_intersections(const Surface &surface, Utilities::Point3 &where);
} // namespace palpate

#endif
