// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

// Writers of every mesh format palpate reads (Gmsh 2.2 and 1, legacy VTK
// classic and 5.1, VTU ascii / base64 / base64+zlib / appended raw), for
// the tests that read them back: mesh_formats and fuzz_inputs.

#ifndef palpate_tests_mesh_writers_h
#define palpate_tests_mesh_writers_h

#include <palpate/mesh/generators.h>
#include <palpate/mesh/mesh_file.h>
#include <palpate/scene/scene.h>

#include <zlib.h>

#include <cstdint>
#include <cstring>
#include <fstream>
#include <iomanip>
#include <string>
#include <vector>

namespace
{
  using palpate::MeshData;

  std::string
  base64(const std::vector<unsigned char> &bytes)
  {
    static const char *a =
      "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    std::string out;
    for (std::size_t i = 0; i < bytes.size(); i += 3)
      {
        const unsigned int n = (bytes[i] << 16) |
                               (i + 1 < bytes.size() ? bytes[i + 1] << 8 : 0) |
                               (i + 2 < bytes.size() ? bytes[i + 2] : 0);
        out += a[(n >> 18) & 63];
        out += a[(n >> 12) & 63];
        out += i + 1 < bytes.size() ? a[(n >> 6) & 63] : '=';
        out += i + 2 < bytes.size() ? a[n & 63] : '=';
      }
    return out;
  }

  template <typename T>
  std::vector<unsigned char>
  raw(const std::vector<T> &v)
  {
    std::vector<unsigned char> b(v.size() * sizeof(T));
    std::memcpy(b.data(), v.data(), b.size());
    return b;
  }

  std::vector<unsigned char>
  uint32(const std::uint32_t x)
  {
    return raw(std::vector<std::uint32_t>{x});
  }

  std::vector<unsigned char>
  concat(std::vector<unsigned char> a, const std::vector<unsigned char> &b)
  {
    a.insert(a.end(), b.begin(), b.end());
    return a;
  }

  void
  write_gmsh(const MeshData &d, const std::string &name, const bool legacy)
  {
    std::ofstream f(name);
    f << std::setprecision(17);
    if (!legacy)
      f << "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n";
    f << (legacy ? "$NOD\n" : "$Nodes\n") << d.nodes.size() << "\n";
    for (unsigned int i = 0; i < d.nodes.size(); ++i) // 1-based tags
      f << i + 1 << " " << d.nodes[i][0] << " " << d.nodes[i][1] << " "
        << d.nodes[i][2] << "\n";
    f << (legacy ? "$ENDNOD\n$ELM\n" : "$EndNodes\n$Elements\n")
      << d.triangles.size() + d.tetrahedra.size() << "\n";
    unsigned int n = 1;
    for (unsigned int i = 0; i < d.triangles.size(); ++i, ++n)
      {
        f << n << " 2 ";
        const unsigned int id = d.triangle_boundary_ids[i];
        f << (legacy ? std::to_string(id) + " " + std::to_string(id) + " 3" :
                       "2 " + std::to_string(id) + " " + std::to_string(id));
        for (const auto v : d.triangles[i])
          f << " " << v + 1;
        f << "\n";
      }
    for (const auto &t : d.tetrahedra)
      {
        f << n++ << " 4 " << (legacy ? "7 7 4" : "2 7 7");
        for (const auto v : t)
          f << " " << v + 1;
        f << "\n";
      }
    f << (legacy ? "$ENDELM\n" : "$EndElements\n");
  }

  void
  write_vtk(const MeshData &d, const std::string &name, const bool v51)
  {
    std::ofstream f(name);
    f << std::setprecision(17) << "# vtk DataFile Version "
      << (v51 ? "5.1" : "3.0") << "\nbeam\nASCII\nDATASET UNSTRUCTURED_GRID\n"
      << "POINTS " << d.nodes.size() << " double\n";
    for (const auto &x : d.nodes)
      f << x[0] << " " << x[1] << " " << x[2] << "\n";
    const std::size_t n = d.tetrahedra.size();
    if (v51)
      {
        f << "CELLS " << n + 1 << " " << 4 * n << "\nOFFSETS vtktypeint64\n";
        for (std::size_t c = 0; c <= n; ++c)
          f << 4 * c << "\n";
        f << "CONNECTIVITY vtktypeint64\n";
        for (const auto &t : d.tetrahedra)
          f << t[0] << " " << t[1] << " " << t[2] << " " << t[3] << "\n";
      }
    else
      {
        f << "CELLS " << n << " " << 5 * n << "\n";
        for (const auto &t : d.tetrahedra)
          f << "4 " << t[0] << " " << t[1] << " " << t[2] << " " << t[3]
            << "\n";
      }
    f << "CELL_TYPES " << n << "\n";
    for (std::size_t c = 0; c < n; ++c)
      f << "10\n";
  }

  enum class Vtu
  {
    ascii,
    base64,
    zlib,
    appended
  };

  void
  write_vtu(const MeshData &d, const std::string &name, const Vtu mode)
  {
    std::vector<double>       points;
    std::vector<std::int32_t> connectivity, offsets;
    std::vector<std::uint8_t> types;
    for (const auto &x : d.nodes)
      points.insert(points.end(), x.begin(), x.end());
    for (const auto &t : d.tetrahedra)
      {
        connectivity.insert(connectivity.end(), t.begin(), t.end());
        offsets.push_back(connectivity.size());
        types.push_back(10);
      }
    const std::vector<std::vector<unsigned char>> arrays = {raw(points),
                                                            raw(connectivity),
                                                            raw(offsets),
                                                            raw(types)};
    const char *type_names[] = {"Float64", "Int32", "Int32", "UInt8"};
    const char *names[]      = {"", "connectivity", "offsets", "types"};

    std::ofstream f(name, std::ios::binary);
    f << std::setprecision(17)
      << "<?xml version=\"1.0\"?>\n<VTKFile type=\"UnstructuredGrid\" "
         "version=\"0.1\" byte_order=\"LittleEndian\" header_type=\"UInt32\""
      << (mode == Vtu::zlib ? " compressor=\"vtkZLibDataCompressor\"" : "")
      << ">\n<UnstructuredGrid>\n<Piece NumberOfPoints=\"" << d.nodes.size()
      << "\" NumberOfCells=\"" << d.tetrahedra.size() << "\">\n";
    std::string appended;
    std::size_t offset = 0;
    for (unsigned int a = 0; a < 4; ++a)
      {
        if (a == 0)
          f << "<Points>\n";
        if (a == 1)
          f << "<Cells>\n";
        f << "<DataArray type=\"" << type_names[a] << "\""
          << (a == 0 ? " NumberOfComponents=\"3\"" : "")
          << (a > 0 ? std::string(" Name=\"") + names[a] + "\"" : "");
        if (mode == Vtu::ascii)
          {
            f << " format=\"ascii\">\n";
            if (a == 0)
              for (const double x : points)
                f << x << " ";
            else if (a == 1)
              for (const auto x : connectivity)
                f << x << " ";
            else if (a == 2)
              for (const auto x : offsets)
                f << x << " ";
            else
              for (const auto x : types)
                f << int(x) << " ";
            f << "\n</DataArray>\n";
          }
        else if (mode == Vtu::base64)
          f << " format=\"binary\">\n"
            << base64(concat(uint32(arrays[a].size()), arrays[a]))
            << "\n</DataArray>\n";
        else if (mode == Vtu::zlib)
          {
            // One block; header and data encoded separately, as VTK does.
            uLongf                     size = compressBound(arrays[a].size());
            std::vector<unsigned char> packed(size);
            compress(packed.data(), &size, arrays[a].data(), arrays[a].size());
            packed.resize(size);
            const std::vector<std::uint32_t> header = {
              1,
              std::uint32_t(arrays[a].size()),
              std::uint32_t(arrays[a].size()),
              std::uint32_t(size)};
            f << " format=\"binary\">\n"
              << base64(raw(header)) << base64(packed) << "\n</DataArray>\n";
          }
        else
          {
            f << " format=\"appended\" offset=\"" << offset << "\"/>\n";
            const auto block = concat(uint32(arrays[a].size()), arrays[a]);
            appended.append(block.begin(), block.end());
            offset += block.size();
          }
        if (a == 0)
          f << "</Points>\n";
        if (a == 3)
          f << "</Cells>\n";
      }
    f << "</Piece>\n</UnstructuredGrid>\n";
    if (mode == Vtu::appended)
      f << "<AppendedData encoding=\"raw\">\n_" << appended
        << "\n</AppendedData>\n";
    f << "</VTKFile>\n";
  }
  /** The default beam with 4 x 2 x 2 blocks (45 nodes, 80 tetrahedra):
   * the mesh the format tests write and read back. */
  MeshData
  small_beam()
  {
    palpate::Scene scene;
    auto          &p           = scene.parameters.mesh;
    p.beam_subdivisions_length = 4;
    p.beam_subdivisions_width  = 2;
    p.beam_subdivisions_height = 2;
    return palpate::generate_beam(p);
  }
  /** Write @p d in every format palpate reads (Gmsh 2.2 and 1, VTK
   * classic and 5.1, VTU ascii / base64 / zlib / appended) as NAME.EXT
   * files; their names, in that order. */
  std::vector<std::string>
  write_every_format(const MeshData &d)
  {
    write_gmsh(d, "beam22.msh", false);
    write_gmsh(d, "beam1.msh", true);
    write_vtk(d, "beam30.vtk", false);
    write_vtk(d, "beam51.vtk", true);
    write_vtu(d, "beam-ascii.vtu", Vtu::ascii);
    write_vtu(d, "beam-base64.vtu", Vtu::base64);
    write_vtu(d, "beam-zlib.vtu", Vtu::zlib);
    write_vtu(d, "beam-appended.vtu", Vtu::appended);
    return {"beam22.msh",
            "beam1.msh",
            "beam30.vtk",
            "beam51.vtk",
            "beam-ascii.vtu",
            "beam-base64.vtu",
            "beam-zlib.vtu",
            "beam-appended.vtu"};
  }
} // namespace

#endif
