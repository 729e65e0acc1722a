// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

#include <palpate/mesh/surface_impl.h>

#include <cstdint>
#include <cstring>
#include <sstream>

namespace palpate
{
  namespace internal
  {
    using Utilities::Point3;

    // ---------------------------------------------------------------- STL

    /**
     * STL keeps no shared vertices: each triangle has its own three. The
     * repair merges coincident vertices afterwards.
     */
    Surface
    read_stl(const std::string &filename)
    {
      const std::string data = contents(filename);
      Surface           s;
      // Binary STL: an 80-byte header, a triangle count, 50 bytes each. An
      // ASCII file starts with "solid", but so do some binary headers: the
      // size decides.
      if (data.size() >= 84)
        {
          std::uint32_t n;
          std::memcpy(&n, data.data() + 80, 4);
          if (data.size() == 84 + 50 * std::uint64_t(n))
            {
              s.format = "binary STL";
              Bytes bytes(filename, data, 84, false);
              for (std::uint32_t t = 0; t < n; ++t)
                {
                  for (unsigned int k = 0; k < 3; ++k)
                    bytes.get<float>(); // the normal: recomputed
                  for (unsigned int v = 0; v < 3; ++v)
                    {
                      Point3 x;
                      for (unsigned int d = 0; d < 3; ++d)
                        x[d] = bytes.get<float>();
                      s.vertices.push_back(x);
                    }
                  bytes.get<std::uint16_t>();
                  const unsigned int i = 3 * t;
                  s.triangles.push_back({{i, i + 1, i + 2}});
                }
              return s;
            }
        }
      if (lower(data.substr(0, 5)) != "solid")
        throw bad(filename,
                  0,
                  "this is neither an ASCII STL file (it does not start "
                  "with 'solid') nor a binary one (its size is not 84 + 50 "
                  "bytes per triangle)",
                  damaged);
      s.format = "ASCII STL";
      std::istringstream     in(data);
      std::string            line;
      unsigned int           line_number = 0;
      std::vector<long long> polygon;
      while (std::getline(in, line))
        {
          ++line_number;
          std::istringstream words(line);
          std::string        word;
          if (!(words >> word))
            continue;
          word = lower(word);
          if (word == "vertex")
            {
              Point3 x;
              if (!(words >> x[0] >> x[1] >> x[2]))
                throw bad(filename,
                          line_number,
                          "a 'vertex' line without three numbers",
                          damaged);
              polygon.push_back(s.vertices.size());
              s.vertices.push_back(x);
            }
          else if (word == "endloop")
            {
              if (polygon.size() < 3)
                throw bad(filename,
                          line_number,
                          "a facet with fewer than three vertices",
                          damaged);
              add_polygon(s, polygon, filename, line_number);
              polygon.clear();
            }
        }
      return s;
    }

    // ---------------------------------------------------------------- OBJ

    Surface
    read_obj(const std::string &filename)
    {
      const std::string data = contents(filename);
      Surface           s;
      s.format = "OBJ";
      std::istringstream in(data);
      std::string        line;
      unsigned int       line_number = 0;
      while (std::getline(in, line))
        {
          ++line_number;
          std::istringstream words(line);
          std::string        word;
          if (!(words >> word))
            continue;
          if (word == "v")
            {
              Point3 x;
              if (!(words >> x[0] >> x[1] >> x[2]))
                throw bad(filename,
                          line_number,
                          "a 'v' line without three numbers",
                          damaged);
              s.vertices.push_back(x);
            }
          else if (word == "f")
            {
              // "f 1 2 3", "f 1/1/1 2/2/2 3/3/3", "f -3 -2 -1" (relative).
              std::vector<long long> polygon;
              std::string            token;
              while (words >> token)
                {
                  long long v;
                  try
                    {
                      v = std::stoll(token.substr(0, token.find('/')));
                    }
                  catch (const std::exception &)
                    {
                      throw bad(filename,
                                line_number,
                                Utilities::quoted_excerpt(token) +
                                  " is not a vertex number",
                                damaged);
                    }
                  polygon.push_back(
                    v < 0 ? static_cast<long long>(s.vertices.size()) + v :
                            v - 1);
                }
              if (polygon.size() < 3)
                throw bad(filename,
                          line_number,
                          "a face with fewer than three vertices",
                          damaged);
              add_polygon(s, polygon, filename, line_number);
            }
        }
      return s;
    }

    // ---------------------------------------------------------------- PLY

    namespace
    {
      struct Property
      {
        std::string name, type, count_type; // count_type: lists only
      };
      struct Element
      {
        std::string           name;
        std::size_t           count = 0;
        std::vector<Property> properties;
      };

      /** A PLY header's format and elements. */
      struct PlyHeader
      {
        std::string          format;
        std::vector<Element> elements;
      };



      /**
       * The header of the PLY file @p filename (its text @p data, the
       * header ending at @p header_end), checked.
       */
      PlyHeader
      read_ply_header(const std::string &filename,
                      const std::string &data,
                      const std::size_t  header_end)
      {
        PlyHeader ply;
        auto     &elements = ply.elements;
        auto     &format   = ply.format;
        {
          std::istringstream header(data.substr(0, header_end));
          std::string        line;
          unsigned int       line_number = 0;
          while (std::getline(header, line))
            {
              ++line_number;
              std::istringstream words(line);
              std::string        word;
              words >> word;
              if (word == "format")
                words >> format;
              else if (word == "element")
                {
                  Element e;
                  if (!(words >> e.name >> e.count))
                    throw bad(filename,
                              line_number,
                              "an 'element' line without a name and count",
                              damaged);
                  elements.push_back(e);
                }
              else if (word == "property")
                {
                  if (elements.empty())
                    throw bad(filename,
                              line_number,
                              "a property before any element",
                              damaged);
                  Property p;
                  words >> p.type;
                  if (p.type == "list")
                    words >> p.count_type >> p.type;
                  words >> p.name;
                  elements.back().properties.push_back(p);
                }
            }
        }
        if (format != "ascii" && format != "binary_little_endian" &&
            format != "binary_big_endian")
          throw bad(filename,
                    2,
                    "unknown PLY format '" + format + "'",
                    "export as ascii or binary PLY.");
        return ply;
      }



      /**
       * The vertices and faces of the PLY file @p filename (its text
       * @p data, its data from @p body on), as @p ply's elements say.
       */
      Surface
      read_ply_data(const std::string &filename,
                    const std::string &data,
                    const std::size_t  body,
                    const PlyHeader   &ply)
      {
        const auto &elements = ply.elements;
        const auto &format   = ply.format;
        Surface     s;
        s.format                 = "PLY " + format;
        const bool         ascii = format == "ascii";
        std::istringstream text(ascii ? data.substr(body) : std::string());
        Bytes      bytes(filename, data, body, format == "binary_big_endian");
        const auto value = [&](const std::string &type) {
          if (!ascii)
            return bytes.get_typed(type);
          double x;
          if (!(text >> x))
            throw bad(filename, 0, "the PLY data end early", damaged);
          return x;
        };
        for (const auto &e : elements)
          for (std::size_t i = 0; i < e.count; ++i)
            {
              Point3                 x{{0, 0, 0}};
              std::vector<long long> polygon;
              for (const auto &p : e.properties)
                {
                  if (!p.count_type.empty())
                    {
                      const auto n =
                        static_cast<long long>(value(p.count_type));
                      for (long long k = 0; k < n; ++k)
                        {
                          const double v = value(p.type);
                          if (p.name == "vertex_indices" ||
                              p.name == "vertex_index")
                            polygon.push_back(static_cast<long long>(v));
                        }
                      continue;
                    }
                  const double v = value(p.type);
                  if (e.name == "vertex" && p.name.size() == 1 &&
                      p.name[0] >= 'x' && p.name[0] <= 'z')
                    x[p.name[0] - 'x'] = v;
                }
              if (e.name == "vertex")
                s.vertices.push_back(x);
              else if (e.name == "face")
                {
                  if (polygon.size() < 3)
                    throw bad(filename,
                              0,
                              "face " + std::to_string(i) +
                                " has fewer than three vertices",
                              damaged);
                  add_polygon(s, polygon, filename, 0);
                }
            }
        return s;
      }
    } // namespace



    Surface
    read_ply(const std::string &filename)
    {
      const std::string data = contents(filename);
      if (data.compare(0, 3, "ply") != 0)
        throw bad(filename,
                  1,
                  "this is not a PLY file: it does not start with 'ply'",
                  "check the file name and extension.");
      const auto header_end = data.find("end_header");
      if (header_end == std::string::npos)
        throw bad(filename, 0, "the PLY header has no 'end_header'", damaged);
      std::size_t body = data.find('\n', header_end);
      if (body == std::string::npos)
        throw bad(filename, 0, "the file ends after its header", damaged);
      ++body;

      const PlyHeader ply = read_ply_header(filename, data, header_end);
      return read_ply_data(filename, data, body, ply);
    }
  } // namespace internal
} // namespace palpate
