// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

#include <palpate/mesh/mesh_file.h>
#include <palpate/mesh/surface_impl.h>

#include <cmath>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <limits>
#include <map>
#include <sstream>

namespace palpate
{
  using Utilities::Point3;

  double
  Surface::volume() const
  {
    double v = 0;
    for (const auto &t : triangles)
      v += Utilities::dot(vertices[t[0]],
                          Utilities::cross(vertices[t[1]], vertices[t[2]]));
    return v / 6;
  }



  double
  Surface::area() const
  {
    double a = 0;
    for (const auto &t : triangles)
      a +=
        0.5 *
        Utilities::norm(
          Utilities::cross(Utilities::minus(vertices[t[1]], vertices[t[0]]),
                           Utilities::minus(vertices[t[2]], vertices[t[0]])));
    return a;
  }



  std::array<Point3, 2>
  Surface::bounding_box() const
  {
    const double          big = std::numeric_limits<double>::max();
    std::array<Point3, 2> box{{{{big, big, big}}, {{-big, -big, -big}}}};
    for (const auto &x : vertices)
      for (unsigned int d = 0; d < 3; ++d)
        {
          box[0][d] = std::min(box[0][d], x[d]);
          box[1][d] = std::max(box[1][d], x[d]);
        }
    return box;
  }



  double
  Surface::diameter() const
  {
    if (vertices.empty())
      return 0;
    const auto box = bounding_box();
    return Utilities::distance(box[0], box[1]);
  }



  void
  subdivide(Surface &s)
  {
    std::map<std::pair<unsigned int, unsigned int>, unsigned int> middle;
    const auto mid = [&](const unsigned int a, const unsigned int b) {
      const auto key = std::minmax(a, b);
      const auto it  = middle.find(key);
      if (it != middle.end())
        return it->second;
      Point3 m;
      for (unsigned int d = 0; d < 3; ++d)
        m[d] = 0.5 * (s.vertices[a][d] + s.vertices[b][d]);
      s.vertices.push_back(m);
      return middle[key] = s.vertices.size() - 1;
    };
    std::vector<std::array<unsigned int, 3>> finer;
    finer.reserve(4 * s.triangles.size());
    for (const auto &t : s.triangles)
      {
        const unsigned int a = mid(t[0], t[1]), b = mid(t[1], t[2]),
                           c = mid(t[2], t[0]);
        finer.push_back({{t[0], a, c}});
        finer.push_back({{t[1], b, a}});
        finer.push_back({{t[2], c, b}});
        finer.push_back({{a, b, c}});
      }
    s.triangles = std::move(finer);
  }



  namespace internal
  {
    std::string
    lower(std::string s)
    {
      for (char &c : s)
        c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
      return s;
    }



    std::string
    extension_of(const std::string &filename)
    {
      return lower(std::filesystem::path(filename).extension().string());
    }



    InputError
    bad(const std::string &filename,
        const unsigned int line,
        const std::string &problem,
        const std::string &fix)
    {
      return InputError(filename, line, "surface file", problem, fix);
    }



    std::string
    contents(const std::string &filename)
    {
      check_file_size(filename,
                      "surface file",
                      max_mesh_file_bytes,
                      "an organ's surface of 100,000 triangles has about "
                      "5 MiB");
      std::ifstream in(filename, std::ios::binary);
      if (!in)
        {
          const std::string why = why_cannot_open(filename);
          throw bad(filename,
                    0,
                    "the file cannot be read: " +
                      (why.empty() ? std::string("the system refused it") :
                                     why),
                    "check the path, the links on the way and the "
                    "permissions.");
        }
      std::ostringstream s;
      s << in.rdbuf();
      return s.str();
    }



    double
    Bytes::get_typed(const std::string &type)
    {
      if (type == "float" || type == "float32")
        return get<float>();
      if (type == "double" || type == "float64")
        return get<double>();
      if (type == "uchar" || type == "uint8" || type == "unsigned_char")
        return get<std::uint8_t>();
      if (type == "char" || type == "int8")
        return get<std::int8_t>();
      if (type == "ushort" || type == "uint16" || type == "unsigned_short")
        return get<std::uint16_t>();
      if (type == "short" || type == "int16")
        return get<std::int16_t>();
      if (type == "uint" || type == "uint32" || type == "unsigned_int")
        return get<std::uint32_t>();
      if (type == "int" || type == "int32")
        return get<std::int32_t>();
      if (type == "vtktypeint64" || type == "long")
        return static_cast<double>(get<std::int64_t>());
      if (type == "vtktypeuint64" || type == "unsigned_long")
        return static_cast<double>(get<std::uint64_t>());
      throw bad(filename,
                0,
                "palpate does not know the data type '" + type + "'",
                "export the surface as ASCII.");
    }



    void
    add_polygon(Surface                      &s,
                const std::vector<long long> &polygon,
                const std::string            &filename,
                const unsigned int            line)
    {
      for (const long long v : polygon)
        if (v < 0 || static_cast<std::size_t>(v) >= s.vertices.size())
          throw bad(filename,
                    line,
                    "a face refers to vertex " + std::to_string(v) +
                      ", but there are " + std::to_string(s.vertices.size()) +
                      " vertices",
                    damaged);
      for (std::size_t k = 1; k + 1 < polygon.size(); ++k)
        s.triangles.push_back({{static_cast<unsigned int>(polygon[0]),
                                static_cast<unsigned int>(polygon[k]),
                                static_cast<unsigned int>(polygon[k + 1])}});
    }
  } // namespace internal



  namespace
  {
    /** A VTK XML PolyData file's surface, read as the volume readers do. */
    Surface
    read_vtp_surface(const std::string &filename)
    {
      const MeshData data = read_vtp(filename);
      Surface        s;
      s.vertices  = data.nodes;
      s.triangles = data.triangles;
      s.format    = data.format;
      return s;
    }
  } // namespace



  bool
  is_surface_file_name(const std::string &filename)
  {
    const std::string e = internal::extension_of(filename);
    return e == ".stl" || e == ".obj" || e == ".ply" || e == ".vtk" ||
           e == ".vtp";
  }



  Surface
  read_surface(const std::string &filename, const double scale)
  {
    if (std::filesystem::is_directory(filename))
      throw internal::bad(
        filename,
        0,
        "this is a directory, not a surface file",
        "name the surface file itself (.stl, .obj, .ply, .vtk, .vtp).");
    const std::string e = internal::extension_of(filename);
    Surface           s;
    if (e == ".stl")
      s = internal::read_stl(filename);
    else if (e == ".obj")
      s = internal::read_obj(filename);
    else if (e == ".ply")
      s = internal::read_ply(filename);
    else if (e == ".vtk")
      s = internal::read_vtk_polydata(filename);
    else if (e == ".vtp")
      s = read_vtp_surface(filename);
    else if (e == ".msh" || e == ".vtu")
      throw internal::bad(filename,
                          0,
                          "this is a volume mesh format (" + e +
                            "), not a surface",
                          "use it directly: Mesh / Source = file.");
    else
      throw internal::bad(
        filename,
        0,
        "palpate does not know the surface extension '" + e + "'",
        "export the surface as .stl, .obj, .ply, .vtk (POLYDATA) or "
        ".vtp.");
    if (s.triangles.empty())
      throw internal::bad(
        filename,
        0,
        "the file holds no triangles (" + std::to_string(s.vertices.size()) +
          " vertices)",
        "export the organ's surface as triangles (or polygons).");
    for (auto &x : s.vertices)
      for (double &c : x)
        {
          if (!std::isfinite(c))
            throw internal::bad(filename,
                                0,
                                "a vertex coordinate is not a finite number",
                                internal::damaged);
          c *= scale;
        }
    return s;
  }
} // namespace palpate
