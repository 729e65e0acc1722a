// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

#include <palpate/base/exceptions.h>
#include <palpate/mesh/mesh.h>
#include <palpate/mesh/mesh_file.h>

#include <deal.II/grid/tria.h>
#include <deal.II/grid/tria_description.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <memory>
#include <numeric>
#include <sstream>
#include <unordered_map>

namespace palpate
{
  namespace
  {
    using FaceKey = std::array<unsigned int, 3>;

    /**
     * A face's sorted vertices -> (the number of tetrahedra it belongs to,
     * its vertices oriented outward from the first of them).
     */
    using Faces = std::map<FaceKey, std::pair<unsigned int, FaceKey>>;
  } // namespace



  struct Mesh::Impl
  {
    dealii::Triangulation<3>                 tria;
    std::vector<Utilities::Point3>           vertices;
    std::vector<long>                        node_ids;
    std::unordered_map<long, unsigned int>   vertex_of_id;
    std::vector<std::array<unsigned int, 4>> cells;
    std::vector<SurfaceFace>                 surface_faces;
    std::vector<bool>                        on_surface;
    unsigned int                             n_surface_vertices = 0;
    double                                   volume             = 0;
    double                                   min_volume         = 0;
    Utilities::Point3                        lower, upper;
    std::string                              description;
    unsigned int                             n_dropped = 0;
    unsigned int                             n_merged  = 0;

    std::vector<int>
    take_nodes(const MeshData &data, const double scale);

    void
    compute_bounding_box();

    void
    take_cells(const MeshData         &data,
               const std::vector<int> &new_index,
               const double            scale,
               const std::string      &file);

    Faces
    find_faces(const MeshData &data, const std::string &file) const;

    void
    take_surface(const Faces                           &faces,
                 const std::map<FaceKey, unsigned int> &ids);

    void
    check_connected(const std::string &file) const;

    void
    build_triangulation(const MeshData &data, const std::string &file);
  };

  namespace
  {
    double
    signed_volume(const Utilities::Point3 &a,
                  const Utilities::Point3 &b,
                  const Utilities::Point3 &c,
                  const Utilities::Point3 &d)
    {
      const double u[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]};
      const double v[3] = {c[0] - a[0], c[1] - a[1], c[2] - a[2]};
      const double w[3] = {d[0] - a[0], d[1] - a[1], d[2] - a[2]};
      return (u[0] * (v[1] * w[2] - v[2] * w[1]) -
              u[1] * (v[0] * w[2] - v[2] * w[0]) +
              u[2] * (v[0] * w[1] - v[1] * w[0])) /
             6.0;
    }

    FaceKey
    sorted(std::array<unsigned int, 3> f)
    {
      std::sort(f.begin(), f.end());
      return f;
    }

    /** Union-find root with path halving. */
    unsigned int
    root(std::vector<unsigned int> &parent, unsigned int i)
    {
      while (parent[i] != i)
        {
          parent[i] = parent[parent[i]];
          i         = parent[i];
        }
      return i;
    }

    std::string
    element_name(const MeshData &data, const unsigned int c)
    {
      if (data.tetrahedron_lines[c] > 0)
        return "element " + std::to_string(data.tetrahedron_ids[c]);
      return "tetrahedron " + std::to_string(c);
    }



    /**
     * That @p data has tetrahedra and no node far away from all others
     * (@p file names the source).
     */
    void
    check_nodes(const MeshData &data, const std::string &file)
    {
      if (data.tetrahedra.empty())
        throw InputError(
          file,
          0,
          "mesh file",
          "the mesh has no tetrahedra",
          "palpate needs a volume mesh of linear tetrahedra; a "
          "surface mesh must first be meshed, e.g. with TetGen.");

      // One wild coordinate (1e308) would make every size below nonsense,
      // and the first element using it look degenerate: name the node.
      if (const long far = far_outlier(data.nodes); far >= 0)
        throw InputError(
          file,
          0,
          "node " + std::to_string(far < long(data.node_ids.size()) ?
                                     data.node_ids[far] :
                                     far + 1),
          "the node at (" + Utilities::to_string(data.nodes[far], 6) +
            ") (file units) lies more than 1000 times farther from "
            "the body's centre than the median node: a mistyped or "
            "corrupted coordinate",
          "correct that node's coordinates in the file, or export "
          "the mesh again.");
    }



    /** Diagonal of the bounding box of the nodes tetrahedra use, in the
     * file's units. */
    double
    diameter_in_file_units(const MeshData &data)
    {
      Utilities::Point3 file_lower = data.nodes[data.tetrahedra[0][0]],
                        file_upper = file_lower;
      for (const auto &t : data.tetrahedra)
        for (const unsigned int v : t)
          for (unsigned int d = 0; d < 3; ++d)
            {
              file_lower[d] = std::min(file_lower[d], data.nodes[v][d]);
              file_upper[d] = std::max(file_upper[d], data.nodes[v][d]);
            }
      return Utilities::distance(file_lower, file_upper);
    }



    /**
     * That tetrahedron @p c of @p data, whose merged vertices are @p t, has
     * four distinct nodes.
     */
    void
    check_distinct_nodes(const MeshData                    &data,
                         const unsigned int                 c,
                         const std::array<unsigned int, 4> &t,
                         const std::string                 &file)
    {
      std::array<unsigned int, 4> s = t;
      std::sort(s.begin(), s.end());
      if (std::adjacent_find(s.begin(), s.end()) == s.end())
        return;
      // The same node number twice, or two numbers whose nodes are
      // at the same point (merged above): said apart, since the fix
      // differs.
      const auto &raw = data.tetrahedra[c];
      for (unsigned int i = 0; i < 4; ++i)
        for (unsigned int j = i + 1; j < 4; ++j)
          if (t[i] == t[j] && raw[i] == raw[j])
            throw InputError(file,
                             data.tetrahedron_lines[c],
                             element_name(data, c),
                             "the tetrahedron uses node " +
                               std::to_string(data.node_ids[raw[i]]) + " twice",
                             "the mesh is broken; regenerate it (TetGen, "
                             "Gmsh).");
          else if (t[i] == t[j])
            throw InputError(file,
                             data.tetrahedron_lines[c],
                             element_name(data, c),
                             "two of the tetrahedron's nodes, " +
                               std::to_string(data.node_ids[raw[i]]) + " and " +
                               std::to_string(data.node_ids[raw[j]]) +
                               ", are at the same point (" +
                               Utilities::to_string(data.nodes[raw[i]]) +
                               "): the element has no volume",
                             "the mesh has duplicate nodes; merge them (Gmsh: "
                             "Coherence) or regenerate the mesh.");
    }



    /**
     * The boundary ids of surface faces, from the file's triangles (checked
     * to be faces of the tetrahedra).
     */
    std::map<FaceKey, unsigned int>
    boundary_ids(const MeshData         &data,
                 const std::vector<int> &new_index,
                 const Faces            &faces,
                 const std::string      &file)
    {
      std::map<FaceKey, unsigned int> ids;
      for (unsigned int k = 0; k < data.triangles.size(); ++k)
        {
          std::array<unsigned int, 3> f;
          for (unsigned int i = 0; i < 3; ++i)
            {
              const int v = new_index[data.triangles[k][i]];
              if (v < 0)
                throw InputError(
                  file,
                  data.triangle_lines[k],
                  "boundary triangle " + std::to_string(k),
                  "the triangle uses a node that no tetrahedron "
                  "uses",
                  "boundary triangles must be faces of the "
                  "tetrahedra; export the volume and its surface "
                  "from the same mesh.");
              f[i] = v;
            }
          const auto it = faces.find(sorted(f));
          if (it == faces.end())
            throw InputError(
              file,
              data.triangle_lines[k],
              "boundary triangle " + std::to_string(k),
              "the triangle is not a face of any tetrahedron",
              "boundary triangles must be faces of the "
              "tetrahedra; export the volume and its surface from "
              "the same mesh.");
          if (it->second.first == 1)
            ids[it->first] = data.triangle_boundary_ids[k];
          // Triangles on interior faces (e.g. between two materials) carry
          // no boundary condition and are ignored.
        }
      return ids;
    }
  } // namespace



  /**
   * Keep only the nodes that tetrahedra use, in file order, one of each set
   * with identical coordinates, scaled by @p scale. Returns each file node's
   * vertex, -1 for the dropped ones.
   */
  std::vector<int>
  Mesh::Impl::take_nodes(const MeshData &data, const double scale)
  {
    // Nodes with identical coordinates are one node: files written cell by
    // cell (deal.II's GridOut and DataOut, some VTU exporters) repeat every
    // vertex once per cell.
    std::vector<unsigned int> canonical(data.nodes.size());
    {
      std::map<Utilities::Point3, unsigned int> first_at;
      for (unsigned int i = 0; i < data.nodes.size(); ++i)
        {
          const auto it = first_at.emplace(data.nodes[i], i).first;
          canonical[i]  = it->second;
          if (it->second != i)
            ++n_merged;
        }
    }

    // Keep only the nodes that tetrahedra use, in file order.
    std::vector<int> new_index(data.nodes.size(), -1);
    for (const auto &t : data.tetrahedra)
      for (const unsigned int v : t)
        new_index[canonical[v]] = 0;
    for (unsigned int i = 0; i < data.nodes.size(); ++i)
      if (new_index[i] == 0)
        {
          new_index[i] = vertices.size();
          vertices.push_back({{scale * data.nodes[i][0],
                               scale * data.nodes[i][1],
                               scale * data.nodes[i][2]}});
          node_ids.push_back(data.node_ids[i]);
          vertex_of_id[data.node_ids[i]] = new_index[i];
        }
      else if (canonical[i] == i)
        ++n_dropped;
    for (unsigned int i = 0; i < data.nodes.size(); ++i)
      new_index[i] = new_index[canonical[i]];
    return new_index;
  }



  /** The bounding box of the vertices. */
  void
  Mesh::Impl::compute_bounding_box()
  {
    lower = upper = vertices[0];
    for (const auto &x : vertices)
      for (unsigned int d = 0; d < 3; ++d)
        {
          lower[d] = std::min(lower[d], x[d]);
          upper[d] = std::max(upper[d], x[d]);
        }
  }



  /**
   * Check and keep the tetrahedra of @p data (their nodes numbered by
   * @p new_index), with the body's volume and the smallest one.
   */
  void
  Mesh::Impl::take_cells(const MeshData         &data,
                         const std::vector<int> &new_index,
                         const double            scale,
                         const std::string      &file)
  {
    const double file_diameter = diameter_in_file_units(data);

    // Every tetrahedron must have four distinct nodes and a positive
    // volume. deal.II would silently re-orient inverted ones; we do not,
    // because an inverted element in a file means a broken mesher or a
    // wrong node-order convention, and the user must know.
    min_volume = std::numeric_limits<double>::max();
    // Each tetrahedron's sorted nodes: the same four twice is a duplicated
    // element (its faces are all shared by two, so the face check below
    // would take two copies for a body without surface, and the stiffness
    // there would count twice).
    std::map<std::array<unsigned int, 4>, unsigned int> cell_with_nodes;
    for (unsigned int c = 0; c < data.tetrahedra.size(); ++c)
      {
        std::array<unsigned int, 4> t;
        for (unsigned int i = 0; i < 4; ++i)
          t[i] = new_index[data.tetrahedra[c][i]];
        check_distinct_nodes(data, c, t, file);
        std::array<unsigned int, 4> s = t;
        std::sort(s.begin(), s.end());
        if (const auto [earlier, first] = cell_with_nodes.emplace(s, c); !first)
          throw InputError(file,
                           data.tetrahedron_lines[c],
                           element_name(data, c),
                           "the tetrahedron has the same four nodes as " +
                             element_name(data, earlier->second) +
                             " (a duplicated element, or nodes at the same "
                             "points)",
                           "the mesh is broken; remove the duplicate or "
                           "regenerate the mesh (TetGen, Gmsh).");
        // In the file's units: with a wild scale factor (1e-300) the
        // volumes in metres underflow to 0 and every element would look
        // flat; the scale factor's own check names the scale instead.
        const auto        &raw    = data.tetrahedra[c];
        const double       v_file = signed_volume(data.nodes[raw[0]],
                                            data.nodes[raw[1]],
                                            data.nodes[raw[2]],
                                            data.nodes[raw[3]]);
        const double       v      = v_file * scale * scale * scale;
        std::ostringstream nodes;
        nodes << data.node_ids[data.tetrahedra[c][0]] << ", "
              << data.node_ids[data.tetrahedra[c][1]] << ", "
              << data.node_ids[data.tetrahedra[c][2]] << ", "
              << data.node_ids[data.tetrahedra[c][3]];
        if (std::abs(v_file) <=
            1e-14 * file_diameter * file_diameter * file_diameter)
          throw InputError(file,
                           data.tetrahedron_lines[c],
                           element_name(data, c) + " (nodes " + nodes.str() +
                             ")",
                           "the tetrahedron is degenerate: its four nodes are "
                           "(nearly) in one plane, volume " +
                             Utilities::to_string(v, 3) + " m^3",
                           "remesh with a quality bound (TetGen -q, Gmsh "
                           "optimisation) so that no element is flat.");
        if (v_file < 0)
          throw InputError(
            file,
            data.tetrahedron_lines[c],
            element_name(data, c) + " (nodes " + nodes.str() + ")",
            "the tetrahedron is inverted: its nodes are ordered "
            "so that its volume is negative (" +
              Utilities::to_string(v, 3) + " m^3)",
            "write the nodes of every tetrahedron in the standard "
            "order ((n1-n0) x (n2-n0)) . (n3-n0) > 0, e.g. swap "
            "its last two nodes; TetGen and Gmsh do this when the "
            "mesh is regenerated.");
        cells.push_back(t);
        volume += v;
        min_volume = std::min(min_volume, v);
      }
  }



  /**
   * The faces of the tetrahedra. A face of one tetrahedron is on the
   * surface, of two is interior, of more is a broken (non-manifold) mesh.
   */
  Faces
  Mesh::Impl::find_faces(const MeshData &data, const std::string &file) const
  {
    Faces                     faces;
    static const unsigned int face_vertices[4][3] = {{1, 2, 3},
                                                     {0, 3, 2},
                                                     {0, 1, 3},
                                                     {0, 2, 1}};
    for (unsigned int c = 0; c < cells.size(); ++c)
      for (const auto &fv : face_vertices)
        {
          const std::array<unsigned int, 3> f = {
            {cells[c][fv[0]], cells[c][fv[1]], cells[c][fv[2]]}};
          auto &entry = faces[sorted(f)];
          if (++entry.first == 1)
            entry.second = f; // outward orientation from its cell
          if (entry.first > 2)
            throw InputError(file,
                             data.tetrahedron_lines[c],
                             element_name(data, c),
                             "a face of this tetrahedron is shared by more "
                             "than two tetrahedra (overlapping elements)",
                             "the mesh is broken; regenerate it.");
        }
    return faces;
  }



  /** The surface faces (with boundary ids @p ids) and vertices. */
  void
  Mesh::Impl::take_surface(const Faces                           &faces,
                           const std::map<FaceKey, unsigned int> &ids)
  {
    on_surface.assign(vertices.size(), false);
    for (const auto &[key, entry] : faces)
      if (entry.first == 1)
        {
          const auto it = ids.find(key);
          surface_faces.push_back(
            {entry.second, it == ids.end() ? 0u : it->second});
          for (const unsigned int v : entry.second)
            on_surface[v] = true;
        }
    n_surface_vertices = std::count(on_surface.begin(), on_surface.end(), true);
  }



  /** That the body is in one piece. */
  void
  Mesh::Impl::check_connected(const std::string &file) const
  {
    // A body in several pieces cannot be held by one set of fixed nodes.
    std::vector<unsigned int> parent(vertices.size());
    std::iota(parent.begin(), parent.end(), 0);
    for (const auto &t : cells)
      for (unsigned int i = 1; i < 4; ++i)
        parent[root(parent, t[i])] = root(parent, t[0]);
    std::map<unsigned int, unsigned int> pieces;
    for (unsigned int v = 0; v < parent.size(); ++v)
      ++pieces[root(parent, v)];
    if (pieces.size() > 1)
      throw InputError(file,
                       0,
                       "mesh file",
                       "the body consists of " + std::to_string(pieces.size()) +
                         " disconnected pieces; every piece not held by fixed "
                         "nodes would float away (singular system)",
                       "mesh one connected body, or remove the extra pieces.");
  }



  /** Hand the checked mesh to deal.II. */
  void
  Mesh::Impl::build_triangulation(const MeshData &data, const std::string &file)
  {
    std::vector<dealii::Point<3>> points;
    for (const auto &x : vertices)
      points.emplace_back(x[0], x[1], x[2]);
    std::vector<dealii::CellData<3>> cell_data(cells.size());
    for (unsigned int c = 0; c < cells.size(); ++c)
      {
        cell_data[c].vertices.assign(cells[c].begin(), cells[c].end());
        cell_data[c].material_id = data.tetrahedron_material_ids[c];
      }
    dealii::SubCellData boundary;
    for (const auto &face : surface_faces)
      if (face.boundary_id != 0)
        {
          dealii::CellData<2> quad;
          quad.vertices.assign(face.vertices.begin(), face.vertices.end());
          quad.boundary_id = face.boundary_id;
          boundary.boundary_quads.push_back(quad);
        }
    try
      {
        tria.create_triangulation(points, cell_data, boundary);
      }
    catch (const std::exception &e)
      {
        throw InputError(file,
                         0,
                         "mesh file",
                         std::string("deal.II cannot build a triangulation "
                                     "from the mesh: ") +
                           e.what(),
                         "check the mesh with the mesher's own tools.");
      }
  }



  Mesh::Mesh(const MeshData &data, const double scale, const std::string &file)
    : impl(std::make_unique<Impl>())
  {
    check_nodes(data, file);
    const std::vector<int> new_index = impl->take_nodes(data, scale);
    impl->compute_bounding_box();
    impl->take_cells(data, new_index, scale, file);
    const Faces faces = impl->find_faces(data, file);
    impl->take_surface(faces, boundary_ids(data, new_index, faces, file));
    impl->check_connected(file);
    impl->build_triangulation(data, file);
    impl->description = data.tetrahedron_lines[0] == 0 &&
                            data.format.find("generator") != std::string::npos ?
                          "the " + data.format :
                          "'" + file + "' (" + data.format + ")";
  }



  Mesh::Mesh(Mesh &&) noexcept = default;
  Mesh::~Mesh()                = default;



  const dealii::Triangulation<3, 3> &
  Mesh::triangulation() const
  {
    return impl->tria;
  }



  unsigned int
  Mesh::n_vertices() const
  {
    return impl->vertices.size();
  }



  unsigned int
  Mesh::n_cells() const
  {
    return impl->cells.size();
  }



  const std::vector<Utilities::Point3> &
  Mesh::vertices() const
  {
    return impl->vertices;
  }



  const std::vector<std::array<unsigned int, 4>> &
  Mesh::cells() const
  {
    return impl->cells;
  }



  const std::vector<SurfaceFace> &
  Mesh::surface_faces() const
  {
    return impl->surface_faces;
  }



  const std::vector<bool> &
  Mesh::on_surface() const
  {
    return impl->on_surface;
  }



  unsigned int
  Mesh::n_surface_vertices() const
  {
    return impl->n_surface_vertices;
  }



  long
  Mesh::node_id(const unsigned int v) const
  {
    return impl->node_ids[v];
  }



  std::string
  Mesh::node_name(const unsigned int v) const
  {
    return "node " + std::to_string(node_id(v));
  }



  std::optional<unsigned int>
  Mesh::vertex_of_node_id(const long id) const
  {
    const auto it = impl->vertex_of_id.find(id);
    if (it == impl->vertex_of_id.end())
      return std::nullopt;
    return it->second;
  }



  double
  Mesh::volume() const
  {
    return impl->volume;
  }



  double
  Mesh::min_cell_volume() const
  {
    return impl->min_volume;
  }



  std::pair<Utilities::Point3, Utilities::Point3>
  Mesh::bounding_box() const
  {
    return {impl->lower, impl->upper};
  }



  double
  Mesh::diameter() const
  {
    // Without under- or overflow of the squares, so that a mesh read at a
    // wild scale factor (1e-300, 1e300) is said to be that size.
    return std::hypot(impl->upper[0] - impl->lower[0],
                      impl->upper[1] - impl->lower[1],
                      impl->upper[2] - impl->lower[2]);
  }



  std::string
  Mesh::farther_than_across(const Utilities::Point3 &motion) const
  {
    // (hypot: a push of 1e300 m is said to be that, not 'inf').
    const double length = std::hypot(motion[0], motion[1], motion[2]);
    if (!(length > diameter()))
      return "";
    return Utilities::to_string_apart(length, diameter()) +
           " m, more than the body is across (" +
           Utilities::to_string_apart(diameter(), length) +
           " m, its bounding box's diagonal)";
  }



  const std::string &
  Mesh::description() const
  {
    return impl->description;
  }



  unsigned int
  Mesh::n_dropped_nodes() const
  {
    return impl->n_dropped;
  }



  unsigned int
  Mesh::n_merged_nodes() const
  {
    return impl->n_merged;
  }
} // namespace palpate
