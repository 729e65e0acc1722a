// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

#ifndef palpate_mesh_readers_gmsh_reader_h
#define palpate_mesh_readers_gmsh_reader_h

#include <palpate/mesh/mesh_file.h>

#include <string>

namespace palpate
{
  namespace mesh_readers
  {
    /**
     * Read a Gmsh .msh file, format 2.2 or the legacy format 1, ASCII:
     * its nodes, linear tetrahedra (with their physical tags as material
     * ids) and triangles (with their physical tags as boundary ids). Other
     * sections are skipped; other elements of dimension 2 or 3 are
     * refused. Every problem throws an InputError naming the line.
     */
    MeshData
    read_gmsh(const std::string &filename);
  } // namespace mesh_readers
} // namespace palpate

#endif
