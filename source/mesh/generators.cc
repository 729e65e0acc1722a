// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

#include <palpate/mesh/generators.h>

#include <deal.II/grid/grid_generator.h>
#include <deal.II/grid/grid_tools.h>
#include <deal.II/grid/tria.h>

#include <cmath>

namespace palpate
{
  namespace
  {
    /** The raw description of a simplex triangulation. */
    MeshData
    to_mesh_data(const dealii::Triangulation<3> &tria,
                 const std::string              &format)
    {
      MeshData data;
      data.format = format;
      for (unsigned int v = 0; v < tria.n_vertices(); ++v)
        {
          const auto &p = tria.get_vertices()[v];
          data.nodes.push_back({{p[0], p[1], p[2]}});
          data.node_ids.push_back(v);
        }
      for (const auto &cell : tria.active_cell_iterators())
        {
          std::array<unsigned int, 4> t;
          for (unsigned int i = 0; i < 4; ++i)
            t[i] = cell->vertex_index(i);
          // deal.II stores some generated tetrahedra with negative
          // orientation; the raw description follows the usual convention
          // (positive volume), which Mesh checks.
          const auto &x = data.nodes;
          const auto  e = [&](unsigned int a, unsigned int d) {
            return x[t[a]][d] - x[t[0]][d];
          };
          const double det = e(1, 0) * (e(2, 1) * e(3, 2) - e(2, 2) * e(3, 1)) -
                             e(1, 1) * (e(2, 0) * e(3, 2) - e(2, 2) * e(3, 0)) +
                             e(1, 2) * (e(2, 0) * e(3, 1) - e(2, 1) * e(3, 0));
          if (det < 0)
            std::swap(t[2], t[3]);
          data.tetrahedra.push_back(t);
          data.tetrahedron_material_ids.push_back(cell->material_id());
          data.tetrahedron_lines.push_back(0);
          data.tetrahedron_ids.push_back(cell->active_cell_index());
          for (const unsigned int f : cell->face_indices())
            if (cell->face(f)->at_boundary())
              {
                const auto face = cell->face(f);
                data.triangles.push_back({{face->vertex_index(0),
                                           face->vertex_index(1),
                                           face->vertex_index(2)}});
                data.triangle_boundary_ids.push_back(face->boundary_id());
                data.triangle_lines.push_back(0);
              }
        }
      return data;
    }
  } // namespace



  MeshData
  generate_beam(const Parameters::Mesh &p)
  {
    dealii::Triangulation<3> tria;
    dealii::GridGenerator::subdivided_hyper_rectangle_with_simplices(
      tria,
      {p.beam_subdivisions_length,
       p.beam_subdivisions_width,
       p.beam_subdivisions_height},
      dealii::Point<3>(0, -p.beam_width / 2, -p.beam_height / 2),
      dealii::Point<3>(p.beam_length, p.beam_width / 2, p.beam_height / 2));

    // deal.II 9.4 cannot colorize simplex rectangles; set the ids by the
    // position of each boundary face's centre.
    const double half[3]   = {p.beam_length / 2,
                              p.beam_width / 2,
                              p.beam_height / 2};
    const double centre[3] = {p.beam_length / 2, 0, 0};
    for (const auto &cell : tria.active_cell_iterators())
      for (const unsigned int f : cell->face_indices())
        if (cell->face(f)->at_boundary())
          {
            const auto c = cell->face(f)->center();
            for (unsigned int d = 0; d < 3; ++d)
              {
                const double t = (c[d] - centre[d]) / half[d];
                if (std::abs(t + 1) < 1e-10)
                  cell->face(f)->set_boundary_id(2 * d);
                else if (std::abs(t - 1) < 1e-10)
                  cell->face(f)->set_boundary_id(2 * d + 1);
              }
          }
    return to_mesh_data(tria, "beam generator");
  }



  Utilities::Point3
  blob_shape(const Utilities::Point3 &x, const Utilities::Point3 &a) noexcept
  {
    // A liver-like shape: an ellipsoid whose +x lobe is thicker and wider
    // than the -x lobe, with a flatter underside. The map is smooth and its
    // Jacobian stays positive on the ball (all factors are within
    // [0.75, 1.25]).
    const double lobe = 1.0 + 0.25 * x[0];
    const double flat = 0.15 * (1.0 - x[0] * x[0] - x[1] * x[1]);
    const double z    = x[2] < 0 ? x[2] * (1.0 - flat) : x[2];
    return {{a[0] * x[0], a[1] * x[1] * (1.0 + 0.15 * x[0]), a[2] * z * lobe}};
  }



  MeshData
  generate_blob(const Parameters::Mesh &p)
  {
    // A cube of n^3 blocks of tetrahedra, mapped onto the unit ball by the
    // smooth cube-to-sphere map: every face of the cube becomes a sixth of
    // the sphere, so the surface nodes are spread evenly (unlike a
    // converted hexahedral ball, whose surface is coarse).
    const unsigned int       n = 3 * (p.blob_refinements + 1);
    dealii::Triangulation<3> tria;
    dealii::GridGenerator::subdivided_hyper_rectangle_with_simplices(
      tria, {n, n, n}, dealii::Point<3>(-1, -1, -1), dealii::Point<3>(1, 1, 1));
    dealii::GridTools::transform(
      [](const dealii::Point<3> &c) {
        const double x2 = c[0] * c[0], y2 = c[1] * c[1], z2 = c[2] * c[2];
        return dealii::Point<3>(
          c[0] * std::sqrt(1 - y2 / 2 - z2 / 2 + y2 * z2 / 3),
          c[1] * std::sqrt(1 - z2 / 2 - x2 / 2 + z2 * x2 / 3),
          c[2] * std::sqrt(1 - x2 / 2 - y2 / 2 + x2 * y2 / 3));
      },
      tria);

    const auto a = p.blob_semi_axes;
    dealii::GridTools::transform(
      [a](const dealii::Point<3> &x) {
        const Utilities::Point3 y = blob_shape({{x[0], x[1], x[2]}}, a);
        return dealii::Point<3>(y[0], y[1], y[2]);
      },
      tria);
    for (const auto &cell : tria.active_cell_iterators())
      for (const unsigned int f : cell->face_indices())
        if (cell->face(f)->at_boundary())
          cell->face(f)->set_boundary_id(0);
    return to_mesh_data(tria, "blob generator");
  }



  MeshData
  generate_tensor_block(const std::vector<double> &x,
                        const std::vector<double> &y,
                        const std::vector<double> &z)
  {
    MeshData           data;
    const unsigned int nx = x.size(), ny = y.size(), nz = z.size();
    data.format     = "tensor block generator";
    const auto node = [&](unsigned int i, unsigned int j, unsigned int k) {
      return (k * ny + j) * nx + i;
    };
    for (unsigned int k = 0; k < nz; ++k)
      for (unsigned int j = 0; j < ny; ++j)
        for (unsigned int i = 0; i < nx; ++i)
          {
            data.nodes.push_back({{x[i], y[j], z[k]}});
            data.node_ids.push_back(data.node_ids.size());
          }
    // Kuhn: the six paths from corner 000 to 111 along the edges, one per
    // order of the three axes.
    static const unsigned int order[6][3] = {
      {0, 1, 2}, {0, 2, 1}, {1, 0, 2}, {1, 2, 0}, {2, 0, 1}, {2, 1, 0}};
    for (unsigned int k = 0; k + 1 < nz; ++k)
      for (unsigned int j = 0; j + 1 < ny; ++j)
        for (unsigned int i = 0; i + 1 < nx; ++i)
          for (const auto &o : order)
            {
              std::array<unsigned int, 3> at = {{i, j, k}};
              std::array<unsigned int, 4> t;
              t[0] = node(i, j, k);
              for (unsigned int step = 0; step < 3; ++step)
                {
                  ++at[o[step]];
                  t[step + 1] = node(at[0], at[1], at[2]);
                }
              const auto &p = data.nodes;
              const auto  e = [&](unsigned int a, unsigned int d) {
                return p[t[a]][d] - p[t[0]][d];
              };
              const double det =
                e(1, 0) * (e(2, 1) * e(3, 2) - e(2, 2) * e(3, 1)) -
                e(1, 1) * (e(2, 0) * e(3, 2) - e(2, 2) * e(3, 0)) +
                e(1, 2) * (e(2, 0) * e(3, 1) - e(2, 1) * e(3, 0));
              if (det < 0)
                std::swap(t[2], t[3]);
              data.tetrahedra.push_back(t);
              data.tetrahedron_material_ids.push_back(0);
              data.tetrahedron_lines.push_back(0);
              data.tetrahedron_ids.push_back(data.tetrahedron_ids.size());
            }
    return data;
  }



  std::vector<double>
  graded_coordinates(const double       length,
                     const double       h,
                     const double       fine_length,
                     const double       growth,
                     const unsigned int split)
  {
    std::vector<double> coarse = {0};
    double              step   = h;
    while (coarse.back() + step < length * (1 - 1e-9))
      {
        // The last interval would be less than half a step: stretch the
        // one before to the end instead.
        if (length - (coarse.back() + step) < 0.5 * step)
          break;
        coarse.push_back(coarse.back() + step);
        if (coarse.back() >= fine_length * (1 - 1e-9))
          step *= growth;
      }
    coarse.push_back(length);
    std::vector<double> t = {0};
    for (unsigned int i = 0; i + 1 < coarse.size(); ++i)
      for (unsigned int s = 1; s <= split; ++s)
        t.push_back(coarse[i] + (coarse[i + 1] - coarse[i]) * s / split);
    return t;
  }
} // namespace palpate
