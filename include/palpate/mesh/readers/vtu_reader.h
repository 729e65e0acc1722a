// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

#ifndef palpate_mesh_readers_vtu_reader_h
#define palpate_mesh_readers_vtu_reader_h

#include <palpate/mesh/mesh_file.h>

#include <string>

namespace palpate
{
  namespace mesh_readers
  {
    /**
     * Read a VTK XML file: an UnstructuredGrid (.vtu; @p polydata false),
     * its points and tetrahedra (and triangles), or a PolyData (.vtp;
     * @p polydata true), its points and its polygons split into
     * triangles. Its arrays may be stored in any way
     * data_array_values() reads. Every problem throws an InputError naming
     * the line.
     */
    MeshData
    read_vtk_xml(const std::string &filename, const bool polydata);
  } // namespace mesh_readers
} // namespace palpate

#endif
