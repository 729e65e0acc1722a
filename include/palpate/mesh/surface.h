// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

#ifndef palpate_mesh_surface_h
#define palpate_mesh_surface_h

#include <palpate/base/utilities.h>

#include <array>
#include <string>
#include <vector>

namespace palpate
{
  /**
   * A triangulated surface: what a segmentation exports for an organ, and
   * what `palpate mesh` (and `Mesh / Source = surface`) turns into a
   * tetrahedral mesh. Coordinates in metres once read (the scale factor
   * applied), triangles as vertex indices.
   */
  struct Surface
  {
    std::vector<Utilities::Point3>           vertices;
    std::vector<std::array<unsigned int, 3>> triangles;
    /** A short description of the file format, e.g. "binary STL". */
    std::string format;

    /** The enclosed volume by the divergence theorem (m^3): positive when
     * the triangles face outward (counter-clockwise seen from outside). */
    double
    volume() const;

    /** The total area (m^2). */
    double
    area() const;

    /** The diagonal of the bounding box of the vertices (m). */
    double
    diameter() const;

    /** The lower and upper corner of the bounding box (m). */
    std::array<Utilities::Point3, 2>
    bounding_box() const;
  };

  /**
   * Split each triangle of @p surface into four at its edge midpoints
   * (shared midpoints once): the same shape with four times the triangles.
   * For tests and benchmarks that need finer surfaces of a known shape.
   */
  void
  subdivide(Surface &surface);

  /**
   * The surface file formats palpate reads and writes, by extension: .stl
   * (ASCII or binary), .obj, .ply (ASCII, binary little or big endian),
   * .vtk (legacy POLYDATA, ASCII or binary), .vtp (VTK XML PolyData: ascii,
   * base64, appended, raw or zlib-compressed).
   */
  bool
  is_surface_file_name(const std::string &filename);

  /**
   * Read a surface file and multiply its coordinates by @p scale (metres per
   * file unit). Polygons are split into triangles. Every problem throws an
   * InputError naming the file, the line if there is one, and the fix; a
   * volume mesh given where a surface is expected, or the other way round,
   * says so.
   */
  Surface
  read_surface(const std::string &filename, const double scale = 1);

  /**
   * Write @p surface (coordinates divided by @p scale) in the format of the
   * extension of @p filename; @p binary chooses binary STL, PLY, VTK and
   * base64 VTP. For tests and for `palpate mesh --repaired`.
   */
  void
  write_surface(const Surface     &surface,
                const std::string &filename,
                const bool         binary = false,
                const double       scale  = 1);
} // namespace palpate

#endif
