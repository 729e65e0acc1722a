// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

#include <palpate/base/exceptions.h>
#include <palpate/mesh/surface_impl.h>

#include <algorithm>
#include <cerrno>
#include <cstdint>
#include <cstring>
#include <fstream>

namespace palpate
{
  namespace
  {
    /**
     * @p raw in base64, after its 32-bit byte count: a binary VTK XML
     * array.
     */
    std::string
    base64_with_size(const std::string &raw)
    {
      static const char *table =
        "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
      std::string   text;
      std::uint32_t n = raw.size();
      std::string   bytes(reinterpret_cast<const char *>(&n), 4);
      bytes += raw;
      for (std::size_t i = 0; i < bytes.size(); i += 3)
        {
          const unsigned int b0 = static_cast<unsigned char>(bytes[i]);
          const unsigned int b1 =
            i + 1 < bytes.size() ? static_cast<unsigned char>(bytes[i + 1]) : 0;
          const unsigned int b2 =
            i + 2 < bytes.size() ? static_cast<unsigned char>(bytes[i + 2]) : 0;
          text += table[b0 >> 2];
          text += table[((b0 & 3) << 4) | (b1 >> 4)];
          text +=
            i + 1 < bytes.size() ? table[((b1 & 15) << 2) | (b2 >> 6)] : '=';
          text += i + 2 < bytes.size() ? table[b2 & 63] : '=';
        }
      return text;
    }



    /** Writes a surface, in file units, to a stream in one format. */
    class SurfaceWriter
    {
    public:
      SurfaceWriter(const Surface &s,
                    std::ofstream &out,
                    const bool     binary,
                    const double   scale)
        : s(s)
        , out(out)
        , binary(binary)
        , scale(scale)
      {}

      /** STL, binary or text. */
      void
      write_stl();

      /** Wavefront OBJ. */
      void
      write_obj();

      /** PLY, binary (little endian) or ascii. */
      void
      write_ply();

      /** Legacy VTK POLYDATA, binary (big endian) or ASCII. */
      void
      write_vtk();

      /** VTK XML PolyData (.vtp). */
      void
      write_vtp();

    private:
      /** Coordinate @p d of vertex @p v, in file units. */
      double
      x(const unsigned int v, const unsigned int d) const
      {
        return s.vertices[v][d] / scale;
      }

      /** @p value's bytes, in the byte order asked for. */
      template <typename T>
      void
      put(const T value, const bool big_endian)
      {
        unsigned char b[sizeof(value)];
        std::memcpy(b, &value, sizeof(value));
        if (big_endian)
          std::reverse(b, b + sizeof(value));
        out.write(reinterpret_cast<const char *>(b), sizeof(value));
      }

      // PLY and legacy VTK list the vertices, then each triangle as its
      // count (3) and its vertices: as text, or binary in the file's byte
      // order.

      /** The vertices, one a line or binary. */
      void
      put_vertices(const bool big_endian)
      {
        for (unsigned int v = 0; v < s.vertices.size(); ++v)
          if (binary)
            for (unsigned int d = 0; d < 3; ++d)
              put(x(v, d), big_endian);
          else
            out << x(v, 0) << ' ' << x(v, 1) << ' ' << x(v, 2) << '\n';
      }

      /** The triangles, each as @p count and its vertices. */
      template <typename Count>
      void
      put_triangles(const bool big_endian, const Count count)
      {
        for (const auto &t : s.triangles)
          if (binary)
            {
              put(count, big_endian);
              for (const unsigned int v : t)
                put(static_cast<std::int32_t>(v), big_endian);
            }
          else
            out << "3 " << t[0] << ' ' << t[1] << ' ' << t[2] << '\n';
      }

      /** A <DataArray> of a .vtp. */
      void
      put_array(const std::string         &name,
                const std::string         &type,
                const unsigned int         components,
                const std::vector<double> &values)
      {
        out << "    <DataArray type=\"" << type << "\" Name=\"" << name
            << "\" NumberOfComponents=\"" << components << "\" format=\""
            << (binary ? "binary" : "ascii") << "\">\n";
        if (binary)
          {
            std::string raw;
            for (const double v : values)
              if (type == "Float64")
                raw.append(reinterpret_cast<const char *>(&v), 8);
              else
                {
                  const std::int64_t i = static_cast<std::int64_t>(v);
                  raw.append(reinterpret_cast<const char *>(&i), 8);
                }
            out << base64_with_size(raw) << '\n';
          }
        else
          for (const double v : values)
            out << v << ' ';
        out << "\n    </DataArray>\n";
      }

      const Surface &s;
      std::ofstream &out;
      const bool     binary;
      const double   scale;
    };



    void
    SurfaceWriter::write_stl()
    {
      if (binary)
        {
          out << std::string(80, ' ');
          put(static_cast<std::uint32_t>(s.triangles.size()), false);
          for (const auto &t : s.triangles)
            {
              for (unsigned int k = 0; k < 3; ++k)
                put(0.0f, false);
              for (const unsigned int v : t)
                for (unsigned int d = 0; d < 3; ++d)
                  put(static_cast<float>(x(v, d)), false);
              put(static_cast<std::uint16_t>(0), false);
            }
        }
      else
        {
          out << "solid palpate\n";
          for (const auto &t : s.triangles)
            {
              out << "facet normal 0 0 0\n outer loop\n";
              for (const unsigned int v : t)
                out << "  vertex " << x(v, 0) << ' ' << x(v, 1) << ' '
                    << x(v, 2) << '\n';
              out << " endloop\nendfacet\n";
            }
          out << "endsolid palpate\n";
        }
    }



    void
    SurfaceWriter::write_obj()
    {
      out << "# written by palpate\n";
      for (unsigned int v = 0; v < s.vertices.size(); ++v)
        out << "v " << x(v, 0) << ' ' << x(v, 1) << ' ' << x(v, 2) << '\n';
      for (const auto &t : s.triangles)
        out << "f " << t[0] + 1 << ' ' << t[1] + 1 << ' ' << t[2] + 1 << '\n';
    }



    void
    SurfaceWriter::write_ply()
    {
      out << "ply\nformat " << (binary ? "binary_little_endian" : "ascii")
          << " 1.0\ncomment written by palpate\nelement vertex "
          << s.vertices.size()
          << "\nproperty double x\nproperty double y\nproperty double "
             "z\nelement face "
          << s.triangles.size()
          << "\nproperty list uchar int vertex_indices\nend_header\n";
      put_vertices(false);
      put_triangles(false, static_cast<std::uint8_t>(3));
    }



    void
    SurfaceWriter::write_vtk()
    {
      out << "# vtk DataFile Version 3.0\nwritten by palpate\n"
          << (binary ? "BINARY" : "ASCII") << "\nDATASET POLYDATA\nPOINTS "
          << s.vertices.size() << " double\n";
      put_vertices(true);
      out << (binary ? "\n" : "") << "POLYGONS " << s.triangles.size() << ' '
          << 4 * s.triangles.size() << '\n';
      put_triangles(true, static_cast<std::int32_t>(3));
      if (binary)
        out << '\n';
    }



    void
    SurfaceWriter::write_vtp()
    {
      // ascii, or base64 binary with a 32-bit byte-count header.
      std::vector<double> points, connectivity, offsets;
      for (unsigned int v = 0; v < s.vertices.size(); ++v)
        for (unsigned int d = 0; d < 3; ++d)
          points.push_back(x(v, d));
      for (const auto &t : s.triangles)
        {
          for (const unsigned int v : t)
            connectivity.push_back(v);
          offsets.push_back(connectivity.size());
        }
      out << "<?xml version=\"1.0\"?>\n<VTKFile type=\"PolyData\" "
             "version=\"1.0\" byte_order=\"LittleEndian\" "
             "header_type=\"UInt32\">\n<PolyData>\n<Piece "
             "NumberOfPoints=\""
          << s.vertices.size() << "\" NumberOfPolys=\"" << s.triangles.size()
          << "\">\n<Points>\n";
      put_array("Points", "Float64", 3, points);
      out << "</Points>\n<Polys>\n";
      put_array("connectivity", "Int64", 1, connectivity);
      put_array("offsets", "Int64", 1, offsets);
      out << "</Polys>\n</Piece>\n</PolyData>\n</VTKFile>\n";
    }
  } // namespace



  void
  write_surface(const Surface     &s,
                const std::string &filename,
                const bool         binary,
                const double       scale)
  {
    const std::string e = internal::extension_of(filename);
    std::ofstream     out(filename, std::ios::binary);
    if (!out)
      throw OutputError("cannot write '" + filename +
                        "': " + std::strerror(errno));
    out.precision(17);
    SurfaceWriter writer(s, out, binary, scale);
    if (e == ".stl")
      writer.write_stl();
    else if (e == ".obj")
      writer.write_obj();
    else if (e == ".ply")
      writer.write_ply();
    else if (e == ".vtk")
      writer.write_vtk();
    else if (e == ".vtp")
      writer.write_vtp();
    else
      throw OutputError("palpate does not write the surface extension '" + e +
                        "' (use .stl, .obj, .ply, .vtk or .vtp)");
    if (!out)
      throw OutputError("writing '" + filename + "' failed");
  }
} // namespace palpate
