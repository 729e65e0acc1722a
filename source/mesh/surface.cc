// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

#include <palpate/base/exceptions.h>
#include <palpate/mesh/mesh_file.h>
#include <palpate/mesh/surface.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
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



  namespace
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

    /** The problem @p problem in @p filename (at @p line if not 0). */
    InputError
    bad(const std::string &filename,
        const unsigned int line,
        const std::string &problem,
        const std::string &fix)
    {
      return InputError(filename, line, "surface file", problem, fix);
    }

    const char *const damaged = "the file is damaged or truncated; export "
                                "the surface again.";

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

    /** Bytes of a binary file, read in order, checked against its end. */
    class Bytes
    {
    public:
      Bytes(const std::string &filename,
            const std::string &data,
            std::size_t        pos,
            const bool         big_endian)
        : filename(filename)
        , data(data)
        , pos(pos)
        , big_endian(big_endian)
      {}

      template <typename T>
      T
      get()
      {
        if (pos + sizeof(T) > data.size())
          throw bad(filename,
                    0,
                    "the binary data end early (at byte " +
                      std::to_string(pos) + " of " +
                      std::to_string(data.size()) + ")",
                    damaged);
        unsigned char b[sizeof(T)];
        std::memcpy(b, data.data() + pos, sizeof(T));
        if (big_endian)
          std::reverse(b, b + sizeof(T));
        T x;
        std::memcpy(&x, b, sizeof(T));
        pos += sizeof(T);
        return x;
      }

      /** A value of the PLY/VTK type called @p type, as a double. */
      double
      get_typed(const std::string &type)
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

      std::size_t
      position() const
      {
        return pos;
      }

    private:
      const std::string &filename;
      const std::string &data;
      std::size_t        pos;
      const bool         big_endian;
    };

    /** Check a vertex index and add the polygon as a fan of triangles. */
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
      std::vector<Element> elements;
      std::string          format;
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

      Surface s;
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
                    const auto n = static_cast<long long>(value(p.count_type));
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

    // ------------------------------------------------------ legacy VTK

    /**
     * The steps of read_vtk_polydata() on one file, and what they share:
     * the file's text, the position read up to, whether the data are
     * binary, and the surface read so far.
     */
    class VtkLegacyReader
    {
    public:
      explicit VtkLegacyReader(const std::string &filename);

      /**
       * Check the first four lines (version, title, ASCII|BINARY, DATASET)
       * and take whether the data are binary.
       */
      void
      read_header();

      /** Read the sections up to the attributes, and return the surface. */
      Surface
      read_sections();

    private:
      /** The next non-empty line, trimmed; empty at the end of the file. */
      std::string
      next_line();

      /** The bytes left after the position read up to. */
      std::size_t
      bytes_left() const;

      /** @p n values as text, from the position read up to. */
      std::vector<double>
      ascii_values(const std::size_t n);

      /** @p n big-endian values of the VTK type @p type. */
      std::vector<double>
      binary_values(const std::size_t n, const std::string &type);

      /** @p n values of the VTK type @p type, binary or text. */
      std::vector<double>
      values(const std::size_t n, const std::string &type);

      /** Read a POINTS section, whose keyword line held @p words. */
      void
      read_points(std::istringstream &words);

      /**
       * Read a POLYGONS, TRIANGLE_STRIPS, VERTICES or LINES section
       * (@p keyword), whose keyword line held @p words.
       */
      void
      read_cells(const std::string &keyword, std::istringstream &words);

      /**
       * Read @p n cells as the OFFSETS and CONNECTIVITY arrays of VTK 5.1,
       * @p offsets_line being the OFFSETS line.
       */
      void
      read_offsets_and_connectivity(const std::size_t  n,
                                    const std::size_t  size,
                                    const std::string &offsets_line);

      /** Read @p n cells as one list of @p size counts and indices. */
      void
      read_cell_list(const std::size_t n, const std::size_t size);

      /** Add @p cell as the triangles it stands for in this section. */
      void
      add_cell(const std::vector<long long> &cell);

      const std::string filename;
      const std::string data;
      std::size_t       pos      = 0;
      bool              binary   = false;
      bool              polygons = false, strips = false;
      Surface           s;
    };



    VtkLegacyReader::VtkLegacyReader(const std::string &filename)
      : filename(filename)
      , data(contents(filename))
    {}



    void
    VtkLegacyReader::read_header()
    {
      // The first four lines: version, title, ASCII|BINARY, DATASET.
      std::vector<std::string> lines;
      for (unsigned int k = 0; k < 4; ++k)
        {
          const auto end = data.find('\n', pos);
          if (end == std::string::npos)
            throw bad(filename, k + 1, "the VTK header is incomplete", damaged);
          lines.push_back(Utilities::trim(data.substr(pos, end - pos)));
          pos = end + 1;
        }
      if (lines[0].rfind("# vtk DataFile", 0) != 0)
        throw bad(filename,
                  1,
                  "this is not a legacy VTK file: the first line should "
                  "read '# vtk DataFile Version x.y'",
                  "check the file name and extension.");
      binary = lines[2] == "BINARY";
      if (!binary && lines[2] != "ASCII")
        throw bad(filename, 3, "expected ASCII or BINARY", damaged);
      if (lines[3] != "DATASET POLYDATA")
        throw bad(filename,
                  4,
                  "the data set is '" + lines[3] +
                    "', not a surface (DATASET POLYDATA)",
                  lines[3] == "DATASET UNSTRUCTURED_GRID" ?
                    "this is a volume mesh: set Mesh / Source = file and use "
                    "it directly." :
                    "export the surface as POLYDATA.");
      s.format = std::string("VTK legacy ") + (binary ? "binary" : "ASCII");
    }



    std::string
    VtkLegacyReader::next_line()
    {
      while (pos < data.size())
        {
          const auto  end  = data.find('\n', pos);
          std::string line = Utilities::trim(
            data.substr(pos,
                        (end == std::string::npos ? data.size() : end) - pos));
          pos = end == std::string::npos ? data.size() : end + 1;
          if (!line.empty())
            return line;
        }
      return std::string();
    }



    std::size_t
    VtkLegacyReader::bytes_left() const
    {
      return data.size() - std::min(pos, data.size());
    }



    std::vector<double>
    VtkLegacyReader::ascii_values(const std::size_t n)
    {
      // ASCII values are read from a stream positioned at pos.
      std::vector<double> v(n);
      std::istringstream  in(data.substr(pos));
      for (auto &x : v)
        if (!(in >> x))
          throw bad(filename, 0, "the data end early", damaged);
      const auto consumed = in.tellg();
      pos +=
        consumed < 0 ? data.size() - pos : static_cast<std::size_t>(consumed);
      return v;
    }



    std::vector<double>
    VtkLegacyReader::binary_values(const std::size_t n, const std::string &type)
    {
      Bytes               b(filename, data, pos, true);
      std::vector<double> v(n);
      for (auto &x : v)
        x = b.get_typed(type);
      pos = b.position();
      return v;
    }



    std::vector<double>
    VtkLegacyReader::values(const std::size_t n, const std::string &type)
    {
      // Every value takes at least a byte: a count beyond what is left
      // of the file is a damaged header, refused before allocating (a
      // POINTS count of 1e12 ended in std::bad_alloc).
      if (n > bytes_left())
        throw bad(filename,
                  0,
                  "the file says " + std::to_string(n) +
                    " values follow, but only " + std::to_string(bytes_left()) +
                    " bytes are left in it",
                  damaged);
      return binary ? binary_values(n, type) : ascii_values(n);
    }



    Surface
    VtkLegacyReader::read_sections()
    {
      // Sections: a keyword line, then its data (text, or big-endian
      // binary after the line's newline).
      while (true)
        {
          const std::string line = next_line();
          if (line.empty())
            break;
          std::istringstream words(line);
          std::string        keyword;
          words >> keyword;
          if (keyword == "POINTS")
            read_points(words);
          else if (keyword == "POLYGONS" || keyword == "TRIANGLE_STRIPS" ||
                   keyword == "VERTICES" || keyword == "LINES")
            read_cells(keyword, words);
          else if (keyword == "POINT_DATA" || keyword == "CELL_DATA" ||
                   keyword == "METADATA" || keyword == "FIELD")
            break; // attributes: not needed
        }
      return s;
    }



    void
    VtkLegacyReader::read_points(std::istringstream &words)
    {
      std::size_t n = 0;
      std::string type;
      words >> n >> type;
      if (n > bytes_left())
        throw bad(filename,
                  0,
                  "the file says " + std::to_string(n) +
                    " points follow, but only " + std::to_string(bytes_left()) +
                    " bytes are left in it",
                  damaged);
      const auto v = values(3 * n, type);
      for (std::size_t i = 0; i < n; ++i)
        s.vertices.push_back({{v[3 * i], v[3 * i + 1], v[3 * i + 2]}});
    }



    void
    VtkLegacyReader::read_cells(const std::string  &keyword,
                                std::istringstream &words)
    {
      std::size_t n = 0, size = 0;
      words >> n >> size;
      polygons = keyword == "POLYGONS";
      strips   = keyword == "TRIANGLE_STRIPS";
      // VTK 5.1 writes OFFSETS and CONNECTIVITY arrays instead.
      const auto save = pos;
      const auto peek = next_line();
      if (peek.rfind("OFFSETS", 0) == 0)
        {
          read_offsets_and_connectivity(n, size, peek);
          return;
        }
      pos = save;
      read_cell_list(n, size);
    }



    void
    VtkLegacyReader::read_offsets_and_connectivity(
      const std::size_t  n,
      const std::size_t  size,
      const std::string &offsets_line)
    {
      std::istringstream w(offsets_line);
      std::string        k, type;
      w >> k >> type;
      const std::vector<double> offsets = values(n, type);
      const auto                c       = next_line();
      std::istringstream        cw(c);
      cw >> k >> type;
      const auto connectivity = values(size, type);
      for (std::size_t i = 0; i + 1 < offsets.size(); ++i)
        {
          if (offsets[i] < 0 || offsets[i] > offsets[i + 1] ||
              offsets[i + 1] > connectivity.size())
            throw bad(filename,
                      0,
                      "the OFFSETS array is inconsistent",
                      damaged);
          std::vector<long long> cell(connectivity.begin() +
                                        std::size_t(offsets[i]),
                                      connectivity.begin() +
                                        std::size_t(offsets[i + 1]));
          add_cell(cell);
        }
    }



    void
    VtkLegacyReader::read_cell_list(const std::size_t n, const std::size_t size)
    {
      const auto  list = values(size, "int");
      std::size_t k    = 0;
      for (std::size_t c = 0; c < n; ++c)
        {
          if (k >= list.size())
            throw bad(filename, 0, "the cell list ends early", damaged);
          const auto m = static_cast<std::size_t>(list[k++]);
          if (k + m > list.size())
            throw bad(filename, 0, "the cell list ends early", damaged);
          std::vector<long long> cell(list.begin() + k, list.begin() + k + m);
          k += m;
          add_cell(cell);
        }
    }



    void
    VtkLegacyReader::add_cell(const std::vector<long long> &cell)
    {
      // A polygon is a fan of triangles; a strip alternates its
      // orientation; vertices and lines are not part of a surface.
      if (polygons)
        add_polygon(s, cell, filename, 0);
      else if (strips)
        for (std::size_t k = 0; k + 2 < cell.size(); ++k)
          add_polygon(s,
                      {cell[k + k % 2], cell[k + 1 - k % 2], cell[k + 2]},
                      filename,
                      0);
    }

    /** A legacy VTK file's POLYDATA surface. */
    Surface
    read_vtk_polydata(const std::string &filename)
    {
      VtkLegacyReader reader(filename);
      reader.read_header();
      return reader.read_sections();
    }

    // ---------------------------------------------------------------- VTP

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
    const std::string e = extension_of(filename);
    return e == ".stl" || e == ".obj" || e == ".ply" || e == ".vtk" ||
           e == ".vtp";
  }



  Surface
  read_surface(const std::string &filename, const double scale)
  {
    if (std::filesystem::is_directory(filename))
      throw bad(filename,
                0,
                "this is a directory, not a surface file",
                "name the surface file itself (.stl, .obj, .ply, .vtk, .vtp).");
    const std::string e = extension_of(filename);
    Surface           s;
    if (e == ".stl")
      s = read_stl(filename);
    else if (e == ".obj")
      s = read_obj(filename);
    else if (e == ".ply")
      s = read_ply(filename);
    else if (e == ".vtk")
      s = read_vtk_polydata(filename);
    else if (e == ".vtp")
      s = read_vtp_surface(filename);
    else if (e == ".msh" || e == ".vtu")
      throw bad(filename,
                0,
                "this is a volume mesh format (" + e + "), not a surface",
                "use it directly: Mesh / Source = file.");
    else
      throw bad(filename,
                0,
                "palpate does not know the surface extension '" + e + "'",
                "export the surface as .stl, .obj, .ply, .vtk (POLYDATA) or "
                ".vtp.");
    if (s.triangles.empty())
      throw bad(filename,
                0,
                "the file holds no triangles (" +
                  std::to_string(s.vertices.size()) + " vertices)",
                "export the organ's surface as triangles (or polygons).");
    for (auto &x : s.vertices)
      for (double &c : x)
        {
          if (!std::isfinite(c))
            throw bad(filename,
                      0,
                      "a vertex coordinate is not a finite number",
                      damaged);
          c *= scale;
        }
    return s;
  }



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
    const std::string e = extension_of(filename);
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
