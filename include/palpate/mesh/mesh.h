// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

#ifndef palpate_mesh_mesh_h
#define palpate_mesh_mesh_h

#include <palpate/base/utilities.h>
#include <palpate/mesh/mesh_file.h>

#include <array>
#include <memory>
#include <optional>
#include <string>
#include <vector>

namespace dealii
{
  template <int dim, int spacedim>
  class Triangulation;
}

namespace palpate
{
  class Scene;

  /** A triangle on the surface of the body, with its boundary id. */
  struct SurfaceFace
  {
    std::array<unsigned int, 3> vertices;
    unsigned int                boundary_id;
  };

  /**
   * The body: a checked tetrahedral mesh in metres, as a deal.II
   * triangulation plus the vertex-level facts the rest of palpate needs
   * (which nodes are on the surface, how the file numbers them).
   *
   * Construction rejects, with an InputError naming the file, the line and
   * the element: inverted or degenerate tetrahedra, tetrahedra with repeated
   * nodes, faces shared by more than two tetrahedra, a body in several
   * disconnected pieces (one of them would float), and boundary triangles
   * that are not faces of the surface. Nodes with identical coordinates
   * are merged (files written cell by cell repeat them); nodes no
   * tetrahedron uses are dropped.
   *
   * Vertex index v of this class is vertex v of triangulation().
   */
  class Mesh
  {
  public:
    /**
     * Check @p data, scale it by @p scale_factor (metres per file unit) and
     * build the triangulation. @p file names the source in error messages.
     */
    Mesh(const MeshData    &data,
         const double       scale_factor,
         const std::string &file);

    Mesh(Mesh &&) noexcept;
    ~Mesh();

    /**
     * The mesh a scene describes, made by its mesh source (Mesh / Source,
     * mesh/mesh_source.h: a file, a surface or a generator). Errors about
     * the mesh file name that file; errors about finding it name the scene
     * entry.
     */
    static Mesh
    create(const Scene &scene);

    /** The deal.II triangulation of the body. */
    const dealii::Triangulation<3, 3> &
    triangulation() const;

    /** Number of nodes (vertices). */
    unsigned int
    n_vertices() const;

    /** Number of tetrahedra. */
    unsigned int
    n_cells() const;

    /** Vertex coordinates, metres. */
    const std::vector<Utilities::Point3> &
    vertices() const;

    /** The tetrahedra, positively oriented, as vertex indices. */
    const std::vector<std::array<unsigned int, 4>> &
    cells() const;

    /** The surface triangles (faces of exactly one tetrahedron). */
    const std::vector<SurfaceFace> &
    surface_faces() const;

    /** Whether each vertex lies on the surface. */
    const std::vector<bool> &
    on_surface() const;

    /** Number of surface vertices. */
    unsigned int
    n_surface_vertices() const;

    /** The number the mesh file gives vertex @p v. */
    long
    node_id(const unsigned int v) const;

    /** Vertex @p v as every message names it: "node " and the number the
     * mesh file gives it (node_id()), the number a user finds in the file
     * and in ParaView's node_id field, never the internal index. */
    std::string
    node_name(const unsigned int v) const;

    /** The vertex the file numbers @p id, if there is one. */
    std::optional<unsigned int>
    vertex_of_node_id(const long id) const;

    /** Volume of the body, m^3. */
    double
    volume() const;

    /** Volume of the smallest tetrahedron, m^3. */
    double
    min_cell_volume() const;

    /** Lower and upper corners of the bounding box, metres. */
    std::pair<Utilities::Point3, Utilities::Point3>
    bounding_box() const;

    /** Diagonal of the bounding box, metres: the body's length scale. */
    double
    diameter() const;

    /**
     * Whether a motion to @p motion from rest goes farther than the body
     * is across (a unit mistake: a push or a recording in millimetres read
     * as metres): the words that say so ("0.9 m, more than the body is
     * across (0.36 m, ...)"), or an empty string.
     */
    std::string
    farther_than_across(const Utilities::Point3 &motion) const;

    /** Where the mesh came from, e.g. "liver501.msh (Gmsh 2.2 ASCII)". */
    const std::string &
    description() const;

    /** Number of nodes of the source that no tetrahedron uses (dropped). */
    unsigned int
    n_dropped_nodes() const;

    /** Number of nodes of the source that repeat another node's
     * coordinates and were merged with it. */
    unsigned int
    n_merged_nodes() const;

  private:
    struct Impl;
    std::unique_ptr<Impl> impl;
  };
} // namespace palpate

#endif
