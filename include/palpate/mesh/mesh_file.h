// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

#ifndef palpate_mesh_mesh_file_h
#define palpate_mesh_mesh_file_h

#include <palpate/base/utilities.h>

#include <array>
#include <cstdint>
#include <string>
#include <vector>

namespace palpate
{
  /**
   * A tetrahedral mesh exactly as a file (or a generator) describes it,
   * before any checking: the raw material that Mesh validates and turns into
   * a deal.II triangulation. Keeping the raw connectivity lets palpate
   * reject inverted tetrahedra that deal.II's readers would silently
   * re-orient, and report the file line of every problem.
   */
  struct MeshData
  {
    /** Node coordinates, in file units. */
    std::vector<Utilities::Point3> nodes;
    /** The number the file gives each node (Gmsh tag, VTK index). */
    std::vector<long> node_ids;
    /** Tetrahedra as indices into @p nodes, in the file's vertex order. */
    std::vector<std::array<unsigned int, 4>> tetrahedra;
    /** Material/physical id of each tetrahedron. */
    std::vector<unsigned int> tetrahedron_material_ids;
    /** Where each tetrahedron is defined: file line, 0 if not a file. */
    std::vector<unsigned int> tetrahedron_lines;
    /** The file's number of each tetrahedron (Gmsh element tag). */
    std::vector<long> tetrahedron_ids;
    /** Surface triangles that carry a boundary id, indices into @p nodes. */
    std::vector<std::array<unsigned int, 3>> triangles;
    /** Boundary id of each triangle (Gmsh physical tag). */
    std::vector<unsigned int> triangle_boundary_ids;
    /** File line of each triangle. */
    std::vector<unsigned int> triangle_lines;
    /** A short description of the format, e.g. "Gmsh 2.2 ASCII". */
    std::string format;
  };

  /**
   * The largest mesh or surface file palpate reads (bytes): 512 MiB, about
   * two million nodes as .msh, far beyond what a state can be computed on
   * at haptic rates; a device or a mistaken file is refused before
   * anything is allocated (check_file_size()).
   */
  constexpr std::uintmax_t max_mesh_file_bytes = std::uintmax_t(512) << 20;

  /**
   * The index of a point far away from all the others - a coordinate
   * mistyped or corrupted (1e308 in a mesh of a liver), more than 1000
   * times farther from the points' median than the median point is, or
   * not finite - or -1 if there is none. Such a point makes the bounding
   * box, and every message about the body's size, nonsense: the readers'
   * callers name it instead.
   */
  long
  far_outlier(const std::vector<Utilities::Point3> &points);

  /**
   * Read a mesh file: Gmsh .msh (format 2.2 or the old v1, ASCII), legacy
   * VTK .vtk (ASCII UNSTRUCTURED_GRID, classic or OFFSETS/CONNECTIVITY
   * cells) or VTK XML .vtu (ascii, base64 binary or appended data, raw or
   * zlib-compressed; binary data little- or big-endian, with UInt32 or
   * UInt64 headers, ascii data whatever byte_order the file declares). The
   * format follows from the extension.
   *
   * Every problem (unreadable file, unsupported format or element type, a
   * node number that is not defined, a truncated section) throws an
   * InputError naming the file, the line and the fix.
   */
  MeshData
  read_mesh_file(const std::string &filename);

  /**
   * Read a VTK XML PolyData file (.vtp, the same encodings as .vtu): its
   * points, and its polygons split into triangles (boundary id 0). For the
   * surface reader.
   */
  MeshData
  read_vtp(const std::string &filename);
} // namespace palpate

#endif
