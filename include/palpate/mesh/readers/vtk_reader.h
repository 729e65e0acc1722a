// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

#ifndef palpate_mesh_readers_vtk_reader_h
#define palpate_mesh_readers_vtk_reader_h

#include <palpate/mesh/mesh_file.h>
#include <palpate/mesh/readers/line_reader.h>

#include <string>
#include <vector>

namespace palpate
{
  namespace mesh_readers
  {
    /**
     * Read a legacy VTK .vtk file: ASCII UNSTRUCTURED_GRID, its POINTS and
     * its CELLS, classic or VTK 5.1's OFFSETS/CONNECTIVITY, with their
     * CELL_TYPES. A surface (POLYDATA) is refused before anything else.
     * Every problem throws an InputError naming the line.
     */
    MeshData
    read_vtk(const std::string &filename);

    /**
     * Turn VTK cells (a list of point indices each, with its VTK cell type
     * in @p types and its file line in @p lines) into the tetrahedra and
     * triangles of @p data, whose nodes they index. Vertices and lines are
     * skipped; any other cell type is refused. Shared by the legacy and
     * the XML readers; @p reader names the file in the errors.
     */
    void
    add_vtk_cells(LineReader                           &reader,
                  const std::vector<std::vector<long>> &cells,
                  const std::vector<int>               &types,
                  const std::vector<unsigned int>      &lines,
                  MeshData                             &data);
  } // namespace mesh_readers
} // namespace palpate

#endif
