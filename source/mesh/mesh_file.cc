// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

#include <palpate/base/exceptions.h>
#include <palpate/mesh/mesh_file.h>

#include <zlib.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <regex>
#include <sstream>

namespace palpate
{
  namespace
  {
    /** Gmsh element types: number of nodes, and a name for messages. */
    struct GmshType
    {
      int         n_nodes;
      int         dimension;
      const char *name;
    };

    const std::map<int, GmshType> &
    gmsh_types()
    {
      static const std::map<int, GmshType> types = {
        {1, {2, 1, "2-node line"}},
        {2, {3, 2, "3-node triangle"}},
        {3, {4, 2, "4-node quadrangle"}},
        {4, {4, 3, "4-node tetrahedron"}},
        {5, {8, 3, "8-node hexahedron"}},
        {6, {6, 3, "6-node prism"}},
        {7, {5, 3, "5-node pyramid"}},
        {8, {3, 1, "3-node line"}},
        {9, {6, 2, "6-node triangle"}},
        {10, {9, 2, "9-node quadrangle"}},
        {11, {10, 3, "10-node tetrahedron"}},
        {12, {27, 3, "27-node hexahedron"}},
        {13, {18, 3, "18-node prism"}},
        {14, {14, 3, "14-node pyramid"}},
        {15, {1, 0, "point"}},
        {16, {8, 2, "8-node quadrangle"}},
        {17, {20, 3, "20-node hexahedron"}},
        {18, {15, 3, "15-node prism"}},
        {19, {13, 3, "13-node pyramid"}}};
      return types;
    }

    /**
     * The error for a file that exists but cannot be read: not "empty" and
     * not "not a mesh file", which would send the user looking for the
     * wrong problem. @p reason is the system's, e.g. "Permission denied".
     */
    InputError
    unreadable(const std::string &filename, const std::string &reason)
    {
      return InputError(filename,
                        0,
                        "mesh file",
                        "the file cannot be read" + (reason.empty() ?
                                                       std::string() :
                                                       " (" + reason + ")"),
                        "check that the path names the mesh file itself and "
                        "that you may read it (permissions, the disk, a "
                        "network mount).");
    }

    /** Reads a text file line by line, keeping line numbers for messages. */
    class LineReader
    {
    public:
      explicit LineReader(const std::string &filename)
        : filename(filename)
        , in(filename)
      {}

      /** The next non-empty line, trimmed; false at the end of the file. */
      bool
      next(std::string &line)
      {
        std::string raw;
        while (std::getline(in, raw))
          {
            ++number;
            // A byte order mark (some Windows tools begin UTF-8 with one)
            // is not part of the first line; UTF-16 is no mesh text.
            if (number == 1 && raw.rfind("\xEF\xBB\xBF", 0) == 0)
              raw.erase(0, 3);
            else if (number == 1 && (raw.rfind("\xFF\xFE", 0) == 0 ||
                                     raw.rfind("\xFE\xFF", 0) == 0))
              throw error(
                "the file is UTF-16 text (it begins with a UTF-16 "
                "byte order mark); mesh files are ASCII",
                "export it again as ASCII, or convert it: iconv -f "
                "UTF-16 -t UTF-8 '" +
                  filename + "' > mesh" +
                  std::filesystem::path(filename).extension().string());
            line = Utilities::trim(raw);
            if (!line.empty())
              return true;
          }
        // A read error ends getline() as the end of the file does; only
        // the stream state tells them apart.
        if (!in.is_open() || in.bad())
          throw unreadable(filename, errno != 0 ? std::strerror(errno) : "");
        return false;
      }

      /** The next line; an error naming @p what if the file ends. */
      std::string
      expect(const std::string &what)
      {
        std::string line;
        if (!next(line))
          throw error("the file ends where " + what + " was expected",
                      "the file is truncated; write it again from the mesh "
                      "generator.");
        return line;
      }

      InputError
      error(const std::string &problem, const std::string &fix) const
      {
        return InputError(filename, number, "mesh file", problem, fix);
      }

      const std::string filename;
      std::ifstream     in;
      unsigned int      number = 0;
    };

    template <typename T>
    T
    parse_number(LineReader &reader, const std::string &token, const char *what)
    {
      std::istringstream s(token);
      T                  value;
      s >> value;
      if (s.fail() || !s.eof())
        throw reader.error(Utilities::quoted_excerpt(token) +
                             " is not a valid " + what,
                           "check the line; the file may be damaged.");
      return value;
    }

    std::vector<std::string>
    tokens_of(const std::string &line)
    {
      std::istringstream       s(line);
      std::vector<std::string> tokens;
      std::string              t;
      while (s >> t)
        tokens.push_back(t);
      return tokens;
    }

    /** Index of a node tag; error if the tag was never defined. */
    unsigned int
    node_index(LineReader                         &reader,
               const std::map<long, unsigned int> &tags,
               const long                          tag)
    {
      const auto it = tags.find(tag);
      if (it == tags.end())
        throw reader.error("the element uses node " + std::to_string(tag) +
                             ", which the node section does not define",
                           "the file is inconsistent; export it again.");
      return it->second;
    }

    // ------------------------------------------------------------------
    // Gmsh (.msh), format 2.2 and the legacy format 1
    // ------------------------------------------------------------------

    /**
     * Read the header of a Gmsh file whose first line is @p line: the
     * $MeshFormat section, or the legacy format's $NOD line. Returns whether
     * the file is in the legacy format 1.
     */
    bool
    read_gmsh_header(LineReader        &reader,
                     const std::string &line,
                     const std::string &filename,
                     MeshData          &data)
    {
      bool legacy = false;
      if (line == "$MeshFormat")
        {
          const auto header = tokens_of(reader.expect("the format line"));
          if (header.size() < 3)
            throw reader.error("the $MeshFormat line should read "
                               "'version file-type data-size'",
                               "export the mesh again as Gmsh 2.2 ASCII.");
          const double version =
            parse_number<double>(reader, header[0], "version");
          if (version >= 3.0)
            throw reader.error(
              "this is a Gmsh " + header[0] +
                " file; palpate reads the "
                "formats 2.2 and 1",
              "convert it: 'gmsh -save -format msh22 -o out.msh " + filename +
                "', or in Gmsh: File > Export, Version 2 ASCII.");
          if (header[1] != "0")
            throw reader.error("this is a binary .msh file",
                               "export it as ASCII: 'gmsh -save -format msh22 "
                               "-o out.msh " +
                                 filename + "'.");
          data.format = "Gmsh " + header[0] + " ASCII";
          if (reader.expect("$EndMeshFormat") != "$EndMeshFormat")
            throw reader.error("expected $EndMeshFormat",
                               "the file is damaged; export it again.");
        }
      else if (line == "$NOD")
        {
          legacy      = true;
          data.format = "Gmsh 1 ASCII";
        }
      else
        throw reader.error("this is not a Gmsh file: it does not start with "
                           "$MeshFormat or $NOD",
                           "check the file name and extension (.msh, .vtk, "
                           ".vtu).");
      return legacy;
    }



    /**
     * Read a node section (after its first line, @p nodes_begin) into
     * @p data, and the index of each node's tag into @p tags.
     */
    void
    read_gmsh_nodes(LineReader                   &reader,
                    const std::string            &nodes_begin,
                    const std::string            &nodes_end,
                    std::map<long, unsigned int> &tags,
                    MeshData                     &data)
    {
      const long n = parse_number<long>(reader,
                                        reader.expect("the node count"),
                                        "node count");
      for (long i = 0; i < n; ++i)
        {
          const auto t = tokens_of(reader.expect("a node"));
          // The section ended before the count: the header's count
          // is wrong, not the line.
          if (!t.empty() && t[0] == nodes_end)
            throw reader.error(
              "the node section's header says " + std::to_string(n) +
                " nodes, but it ends after " + std::to_string(i),
              "correct the count in the line after " + nodes_begin + " to " +
                std::to_string(i) + ", or export the mesh again.");
          if (t.size() < 4)
            throw reader.error("a node line needs 'number x y z'",
                               "the file is damaged; export it "
                               "again.");
          const long tag = parse_number<long>(reader, t[0], "node number");
          Utilities::Point3 x;
          for (unsigned int d = 0; d < 3; ++d)
            x[d] = parse_number<double>(reader, t[d + 1], "coordinate");
          if (!tags.emplace(tag, data.nodes.size()).second)
            throw reader.error("node " + std::to_string(tag) +
                                 " is defined twice",
                               "the file is damaged; export it "
                               "again.");
          data.nodes.push_back(x);
          data.node_ids.push_back(tag);
        }
      if (reader.expect(nodes_end) != nodes_end)
        throw reader.error("expected " + nodes_end + " after the nodes",
                           "the node count does not match the "
                           "nodes; export the file again.");
    }



    /**
     * Read an element section (after its first line) into @p data: its
     * tetrahedra and triangles.
     */
    void
    read_gmsh_elements(LineReader                         &reader,
                       const bool                          legacy,
                       const std::string                  &elements_end,
                       const std::map<long, unsigned int> &tags,
                       MeshData                           &data)
    {
      const long n = parse_number<long>(reader,
                                        reader.expect("the element count"),
                                        "element count");
      for (long i = 0; i < n; ++i)
        {
          const auto t = tokens_of(reader.expect("an element"));
          if (t.size() < 3)
            throw reader.error("an element line is too short",
                               "the file is damaged.");
          const long id   = parse_number<long>(reader, t[0], "element number");
          const int  type = parse_number<int>(reader, t[1], "element type");
          const auto type_it = gmsh_types().find(type);
          if (type_it == gmsh_types().end())
            throw reader.error("element " + std::to_string(id) +
                                 " has the unknown type " + t[1],
                               "palpate needs linear tetrahedra "
                               "(type 4) and optionally triangles "
                               "(type 2) for boundary ids.");
          unsigned int first_node = 0;
          unsigned int physical   = 0;
          if (legacy)
            {
              // number type physical elementary n-nodes nodes...
              if (t.size() < 5)
                throw reader.error("an element line is too short",
                                   "the file is damaged.");
              physical =
                parse_number<unsigned int>(reader, t[2], "physical tag");
              first_node = 5;
            }
          else
            {
              // number type n-tags tags... nodes...
              const unsigned int n_tags =
                parse_number<unsigned int>(reader, t[2], "tag count");
              if (n_tags > 0 && t.size() > 3)
                physical =
                  parse_number<unsigned int>(reader, t[3], "physical tag");
              first_node = 3 + n_tags;
            }
          const GmshType &gt = type_it->second;
          if (t.size() != first_node + gt.n_nodes)
            throw reader.error("element " + std::to_string(id) + " (" +
                                 gt.name + ") should list " +
                                 std::to_string(gt.n_nodes) + " nodes",
                               "the file is damaged; export it "
                               "again.");
          std::vector<unsigned int> v(gt.n_nodes);
          for (int k = 0; k < gt.n_nodes; ++k)
            v[k] = node_index(reader,
                              tags,
                              parse_number<long>(reader,
                                                 t[first_node + k],
                                                 "node number"));
          if (type == 4)
            {
              data.tetrahedra.push_back({{v[0], v[1], v[2], v[3]}});
              data.tetrahedron_material_ids.push_back(physical);
              data.tetrahedron_lines.push_back(reader.number);
              data.tetrahedron_ids.push_back(id);
            }
          else if (type == 2)
            {
              data.triangles.push_back({{v[0], v[1], v[2]}});
              data.triangle_boundary_ids.push_back(physical);
              data.triangle_lines.push_back(reader.number);
            }
          else if (gt.dimension >= 2)
            throw reader.error(
              "element " + std::to_string(id) + " is a " + gt.name +
                "; palpate's finite elements are linear tetrahedra",
              "mesh the body with 4-node tetrahedra only (Gmsh: "
              "Mesh.ElementOrder = 1, no recombination; TetGen "
              "does this by default).");
          // Points and lines carry nothing palpate needs.
        }
      if (reader.expect(elements_end) != elements_end)
        throw reader.error("expected " + elements_end + " after the elements",
                           "the element count does not match the "
                           "elements; export the file again.");
    }



    /** Skip the section whose first line is @p line. */
    void
    skip_gmsh_section(LineReader        &reader,
                      const std::string &line,
                      const bool         legacy)
    {
      // Skip any other section ($PhysicalNames, $NodeData, ...).
      const std::string end =
        legacy ? "$END" + line.substr(1) : "$End" + line.substr(1);
      std::string skip;
      while (reader.next(skip) && skip != end)
        ;
    }



    MeshData
    read_gmsh(const std::string &filename)
    {
      LineReader reader(filename);
      MeshData   data;

      std::string line;
      if (!reader.next(line))
        throw reader.error("the file is empty",
                           "write the mesh again from Gmsh or TetGen.");
      const bool legacy = read_gmsh_header(reader, line, filename, data);

      std::map<long, unsigned int> tags;
      bool                         have_nodes = false, have_elements = false;
      const std::string            nodes_begin = legacy ? "$NOD" : "$Nodes";
      const std::string            nodes_end = legacy ? "$ENDNOD" : "$EndNodes";
      const std::string elements_begin       = legacy ? "$ELM" : "$Elements";
      const std::string elements_end = legacy ? "$ENDELM" : "$EndElements";

      bool first = legacy; // the legacy header line is the $NOD line
      while (first || reader.next(line))
        {
          first = false;
          if (line == nodes_begin)
            {
              read_gmsh_nodes(reader, nodes_begin, nodes_end, tags, data);
              have_nodes = true;
            }
          else if (line == elements_begin)
            {
              if (!have_nodes)
                throw reader.error("the elements come before the nodes",
                                   "export the file again.");
              read_gmsh_elements(reader, legacy, elements_end, tags, data);
              have_elements = true;
            }
          else if (!line.empty() && line[0] == '$')
            skip_gmsh_section(reader, line, legacy);
          else
            throw reader.error("unexpected line " +
                                 Utilities::quoted_excerpt(line) +
                                 " between sections",
                               "the file is damaged; export it again.");
        }
      if (!have_nodes || !have_elements)
        throw reader.error(std::string("the file has no ") +
                             (have_nodes ? elements_begin : nodes_begin) +
                             " section",
                           "export the volume mesh again.");
      return data;
    }

    // ------------------------------------------------------------------
    // Legacy VTK (.vtk), ASCII unstructured grid
    // ------------------------------------------------------------------

    /** A whitespace tokenizer that remembers the line of each token. */
    class TokenReader
    {
    public:
      explicit TokenReader(LineReader &reader)
        : reader(reader)
      {}

      std::string
      next(const std::string &what)
      {
        while (position >= tokens.size())
          {
            std::string line;
            if (!reader.next(line))
              throw reader.error("the file ends where " + what +
                                   " was expected",
                                 "the file is truncated; write it again.");
            tokens   = tokens_of(line);
            position = 0;
          }
        return tokens[position++];
      }

      bool
      at_end()
      {
        while (position >= tokens.size())
          {
            std::string line;
            if (!reader.next(line))
              return true;
            tokens   = tokens_of(line);
            position = 0;
          }
        return false;
      }

      template <typename T>
      T
      number(const char *what)
      {
        return parse_number<T>(reader, next(what), what);
      }

      LineReader              &reader;
      std::vector<std::string> tokens;
      unsigned int             position = 0;
    };

    /** Turn VTK cells (type + node list) into tetrahedra and triangles. */
    void
    add_vtk_cells(LineReader                           &reader,
                  const std::vector<std::vector<long>> &cells,
                  const std::vector<int>               &types,
                  const std::vector<unsigned int>      &lines,
                  MeshData                             &data)
    {
      for (unsigned int c = 0; c < cells.size(); ++c)
        {
          const auto check = [&](const std::size_t n) {
            if (cells[c].size() != n)
              throw InputError(reader.filename,
                               lines[c],
                               "mesh file, cell " + std::to_string(c),
                               "cell " + std::to_string(c) + " has " +
                                 std::to_string(cells[c].size()) +
                                 " points, its type needs " + std::to_string(n),
                               "the file is damaged; write it again.");
            for (const long p : cells[c])
              if (p < 0 || p >= static_cast<long>(data.nodes.size()))
                throw InputError(reader.filename,
                                 lines[c],
                                 "mesh file, cell " + std::to_string(c),
                                 "cell " + std::to_string(c) + " uses point " +
                                   std::to_string(p) + ", but there are only " +
                                   std::to_string(data.nodes.size()),
                                 "the file is damaged; write it again.");
          };
          switch (types[c])
            {
              case 10: // VTK_TETRA
                check(4);
                data.tetrahedra.push_back(
                  {{static_cast<unsigned int>(cells[c][0]),
                    static_cast<unsigned int>(cells[c][1]),
                    static_cast<unsigned int>(cells[c][2]),
                    static_cast<unsigned int>(cells[c][3])}});
                data.tetrahedron_material_ids.push_back(0);
                data.tetrahedron_lines.push_back(lines[c]);
                data.tetrahedron_ids.push_back(c);
                break;
              case 5: // VTK_TRIANGLE
                check(3);
                data.triangles.push_back(
                  {{static_cast<unsigned int>(cells[c][0]),
                    static_cast<unsigned int>(cells[c][1]),
                    static_cast<unsigned int>(cells[c][2])}});
                data.triangle_boundary_ids.push_back(0);
                data.triangle_lines.push_back(lines[c]);
                break;
              case 1:  // VTK_VERTEX
              case 2:  // VTK_POLY_VERTEX
              case 3:  // VTK_LINE
              case 4:  // VTK_POLY_LINE
              case 21: // VTK_QUADRATIC_EDGE
                break;
              default:
                throw InputError(
                  reader.filename,
                  lines[c],
                  "mesh file, cell " + std::to_string(c),
                  "cell " + std::to_string(c) + " has VTK cell type " +
                    std::to_string(types[c]) +
                    "; palpate's finite elements are linear tetrahedra "
                    "(type 10)",
                  "mesh the body with linear tetrahedra only.");
            }
        }
    }

    /**
     * Refuse a legacy VTK surface (POLYDATA), whatever its encoding, before
     * anything else: it is not a volume mesh.
     */
    void
    check_not_polydata(const std::string &filename)
    {
      std::ifstream head(filename, std::ios::binary);
      std::string   start(512, '\0');
      head.read(&start[0], start.size());
      start.resize(head.gcount());
      if (start.find("DATASET POLYDATA") != std::string::npos)
        throw InputError(filename,
                         0,
                         "mesh file",
                         "this legacy VTK file is a surface (POLYDATA): "
                         "palpate needs a tetrahedral volume mesh here",
                         "make one with 'palpate mesh " + filename +
                           " OUT.msh --scale S' (S = metres per file "
                           "unit, 0.001 for millimetres), or set Mesh / "
                           "Source = surface with this file as File name.");
    }



    /** Read the legacy VTK header into @p data: its version and encoding. */
    void
    read_vtk_header(LineReader &reader, MeshData &data)
    {
      const std::string header = reader.expect("the VTK header");
      std::smatch       m;
      if (!std::regex_match(header,
                            m,
                            std::regex(R"(# vtk DataFile Version (\S+))")))
        throw reader.error("this is not a legacy VTK file: the first line "
                           "should read '# vtk DataFile Version x.y'",
                           "check the file name and extension (.msh, .vtk, "
                           ".vtu).");
      data.format = "VTK " + m[1].str() + " legacy ASCII";
      reader.expect("the title line");
      const std::string encoding = reader.expect("ASCII or BINARY");
      if (encoding != "ASCII")
        throw reader.error("this legacy VTK file is " + encoding +
                             "; palpate reads ASCII legacy files",
                           "save it as ASCII (ParaView: File > Save Data, "
                           "File type Legacy VTK, File type ASCII), or as "
                           ".vtu.");
    }



    /**
     * Read a count, checked before it is trusted: each item it counts takes
     * at least two bytes of the file, which holds at most @p most items.
     */
    long
    read_count(TokenReader &tokens, const long most, const char *what)
    {
      LineReader &reader = tokens.reader;
      const long  n      = tokens.number<long>(what);
      if (n < 0 || n > most)
        throw reader.error(std::string("the ") + what + " " +
                             std::to_string(n) +
                             " cannot be right: it is negative or more "
                             "than the file could hold",
                           "the file is damaged; write it again.");
      return n;
    }



    /**
     * Read the cells of a VTK 5.1 CELLS section (@p n offsets and @p size
     * connectivity entries), after its counts.
     */
    void
    read_vtk_offset_cells(TokenReader                    &tokens,
                          const long                      n,
                          const long                      size,
                          std::vector<std::vector<long>> &cells,
                          std::vector<unsigned int>      &cell_lines)
    {
      LineReader &reader = tokens.reader;
      // VTK 5.1: CELLS n_offsets n_connectivity, then arrays.
      tokens.next("OFFSETS");
      tokens.next("the offset type");
      std::vector<long> offsets;
      for (long i = 0; i < n; ++i)
        {
          offsets.push_back(tokens.number<long>("offset"));
          if (offsets.back() < (i == 0 ? 0 : offsets[i - 1]) ||
              offsets.back() > size)
            throw reader.error("offset " + std::to_string(i) + " (" +
                                 std::to_string(offsets.back()) +
                                 ") is not between the previous offset and the "
                                 "connectivity size " +
                                 std::to_string(size),
                               "the file is damaged; write it again.");
        }
      if (tokens.next("CONNECTIVITY") != "CONNECTIVITY")
        throw reader.error("expected CONNECTIVITY after OFFSETS",
                           "the file is damaged.");
      tokens.next("the connectivity type");
      std::vector<long> connectivity;
      for (long i = 0; i < size; ++i)
        connectivity.push_back(tokens.number<long>("point index"));
      for (long c = 0; c + 1 < n; ++c)
        {
          cells.emplace_back(connectivity.begin() + offsets[c],
                             connectivity.begin() + offsets[c + 1]);
          cell_lines.push_back(reader.number);
        }
    }



    /**
     * Read a CELLS section, after its keyword, into @p cells and the line of
     * each.
     */
    void
    read_vtk_cells(TokenReader                    &tokens,
                   const long                      most,
                   std::vector<std::vector<long>> &cells,
                   std::vector<unsigned int>      &cell_lines)
    {
      LineReader &reader = tokens.reader;
      const long  n      = read_count(tokens, most, "cell count");
      const long  size   = read_count(tokens, most, "cell list size");
      if (tokens.at_end())
        throw reader.error("the CELLS section is empty",
                           "the file is truncated.");
      if (tokens.tokens[tokens.position] == "OFFSETS")
        read_vtk_offset_cells(tokens, n, size, cells, cell_lines);
      else
        for (long c = 0; c < n; ++c)
          {
            const long k = tokens.number<long>("cell size");
            if (k < 0 || k > 64)
              throw reader.error("cell " + std::to_string(c) + " has " +
                                   std::to_string(k) +
                                   " points; a cell has at most 64",
                                 "the file is damaged; write it "
                                 "again.");
            std::vector<long> cell(k);
            for (auto &p : cell)
              p = tokens.number<long>("point index");
            cells.push_back(cell);
            cell_lines.push_back(reader.number);
          }
    }



    MeshData
    read_vtk(const std::string &filename)
    {
      check_not_polydata(filename);
      LineReader reader(filename);
      MeshData   data;
      read_vtk_header(reader, data);

      TokenReader tokens(reader);
      if (tokens.next("DATASET") != "DATASET" ||
          tokens.next("the data set type") != "UNSTRUCTURED_GRID")
        throw reader.error("the data set is not an UNSTRUCTURED_GRID",
                           "write the tetrahedral mesh as an unstructured "
                           "grid.");

      // A count read from the file is checked before it is trusted: each
      // item it counts takes at least two bytes of the file.
      std::error_code ec;
      const auto      bytes = std::filesystem::file_size(filename, ec);
      const long      most  = ec ? 0 : static_cast<long>(bytes / 2);
      const auto      count = [&](const char *what) {
        return read_count(tokens, most, what);
      };

      std::vector<std::vector<long>> cells;
      std::vector<int>               types;
      std::vector<unsigned int>      cell_lines;
      while (!tokens.at_end())
        {
          const std::string keyword = tokens.next("a section keyword");
          if (keyword == "POINTS")
            {
              const long n = count("point count");
              tokens.next("the point data type");
              for (long i = 0; i < n; ++i)
                {
                  Utilities::Point3 x;
                  for (unsigned int d = 0; d < 3; ++d)
                    x[d] = tokens.number<double>("coordinate");
                  data.nodes.push_back(x);
                  data.node_ids.push_back(i);
                }
            }
          else if (keyword == "CELLS")
            read_vtk_cells(tokens, most, cells, cell_lines);
          else if (keyword == "CELL_TYPES")
            {
              const long n = count("cell type count");
              for (long c = 0; c < n; ++c)
                types.push_back(tokens.number<int>("cell type"));
            }
          else if (keyword == "POINT_DATA" || keyword == "CELL_DATA" ||
                   keyword == "FIELD")
            break; // palpate needs no data arrays
          else
            throw reader.error("unexpected keyword " +
                                 Utilities::quoted_excerpt(keyword),
                               "palpate reads POINTS, CELLS and CELL_TYPES "
                               "of an unstructured grid.");
        }
      if (data.nodes.empty() || cells.empty())
        throw reader.error("the file has no POINTS or no CELLS",
                           "write the volume mesh again.");
      if (types.size() != cells.size())
        throw reader.error("CELL_TYPES lists " + std::to_string(types.size()) +
                             " types for " + std::to_string(cells.size()) +
                             " cells",
                           "the file is damaged; write it again.");
      add_vtk_cells(reader, cells, types, cell_lines, data);
      return data;
    }

    // ------------------------------------------------------------------
    // VTK XML unstructured grid (.vtu)
    // ------------------------------------------------------------------

    std::string
    attribute(const std::string &tag, const std::string &name)
    {
      std::smatch m;
      if (std::regex_search(tag,
                            m,
                            std::regex("\\b" + name + "\\s*=\\s*\"([^\"]*)\"")))
        return m[1].str();
      return "";
    }

    std::vector<unsigned char>
    base64_decode(const std::string &text, std::size_t begin, std::size_t end)
    {
      static const std::string alphabet =
        "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
      std::vector<unsigned char> out;
      unsigned int               buffer = 0;
      int                        bits   = 0;
      for (std::size_t i = begin; i < end; ++i)
        {
          const char c = text[i];
          if (c == '=')
            break;
          const auto k = alphabet.find(c);
          if (k == std::string::npos)
            continue; // white space
          buffer = (buffer << 6) | static_cast<unsigned int>(k);
          bits += 6;
          if (bits >= 8)
            {
              bits -= 8;
              out.push_back(
                static_cast<unsigned char>((buffer >> bits) & 0xff));
            }
        }
      return out;
    }

    /** Compact copy of @p text without white space. */
    std::string
    strip_space(const std::string &text)
    {
      std::string s;
      for (const char c : text)
        if (!std::isspace(static_cast<unsigned char>(c)))
          s += c;
      return s;
    }

    /** The system's reason for the last failed call, "" if it gave none. */
    std::string
    system_reason()
    {
      return errno != 0 ? std::strerror(errno) : "";
    }

    /**
     * The whole file, for the XML reader. A read error is "cannot be
     * read", a file without a byte "empty", and neither "not a VTK XML
     * file".
     */
    std::string
    file_contents(const std::string &filename)
    {
      errno = 0;
      std::ifstream in(filename, std::ios::binary);
      if (!in)
        throw unreadable(filename, system_reason());
      std::string       text;
      std::vector<char> buffer(1 << 16);
      while (in.read(buffer.data(), buffer.size()) || in.gcount() > 0)
        text.append(buffer.data(), in.gcount());
      if (in.bad())
        throw unreadable(filename, system_reason());
      if (text.empty())
        throw InputError(filename,
                         0,
                         "mesh file",
                         "the file is empty",
                         "write the mesh again from the mesh generator.");
      return text;
    }

    /** The line (from 1) on which position @p at of @p text lies. */
    unsigned int
    line_at(const std::string &text, const std::size_t at)
    {
      return 1 + std::count(text.begin(),
                            text.begin() + std::min(at, text.size()),
                            '\n');
    }

    /**
     * A count given as an XML attribute (NumberOfPoints, NumberOfCells, an
     * appended array's offset): a whole number, 0 or more. It is checked
     * digit by digit: std::stol would read "-5" as -5 and "12abc" as 12,
     * and a missing or garbled count must not become an empty mesh.
     */
    std::uint64_t
    count_attribute(const std::string &filename,
                    const unsigned int line,
                    const std::string &element,
                    const std::string &tag,
                    const std::string &name)
    {
      const std::string value = Utilities::trim(attribute(tag, name));
      if (value.empty())
        throw InputError(filename,
                         line,
                         element + " " + name,
                         "the " + element + " element does not give its " +
                           name,
                         "the file is damaged or was not written by VTK; "
                         "write it again (ParaView, meshio, deal.II).");
      // 18 digits: far beyond any mesh, and 3 x count stays in 64 bits.
      if (value.size() > 18 ||
          value.find_first_not_of("0123456789") != std::string::npos)
        throw InputError(filename,
                         line,
                         element + " " + name,
                         name + "=\"" + value +
                           "\" is not a count: it must be a whole number, 0 "
                           "or more",
                         "the file is damaged; write it again.");
      return std::stoull(value);
    }

    /** Whether this machine stores numbers little-endian (x86, ARM). */
    bool
    host_is_little_endian()
    {
      const std::uint16_t one = 1;
      unsigned char       first;
      std::memcpy(&first, &one, 1);
      return first == 1;
    }

    /** Reverse the @p size bytes at @p p: one value to the other byte
     * order. */
    void
    reverse_bytes(unsigned char *p, const std::size_t size)
    {
      std::reverse(p, p + size);
    }

    struct VtuContext
    {
      std::string filename;
      bool        header_64  = false;
      bool        compressed = false;
      /**
       * The file's byte order differs from this machine's: every binary
       * value, the UInt32/UInt64 sizes of the array headers included, is
       * byte-swapped as it is read. Ascii arrays are text and need
       * nothing, whatever the file declares.
       */
      bool swap_bytes = false;
      /** The byte_order attribute, if it is neither LittleEndian nor
       * BigEndian: refused when a binary array needs it, and only then. */
      std::string unknown_byte_order;
      /** The line of the <VTKFile> tag, which declares the byte order. */
      unsigned int file_tag_line = 1;
      std::string  appended; // raw bytes, or base64 text
      bool         appended_base64 = false;
      /** The line of the <DataArray> being read, for messages. */
      unsigned int line = 0;

      /** Bytes per header value: UInt32 or UInt64. */
      std::size_t
      header_size() const
      {
        return header_64 ? 8 : 4;
      }

      /** The error for a binary array that does not hold what it says. */
      InputError
      damaged(const std::string &name, const std::string &problem) const
      {
        return InputError(filename,
                          line,
                          "DataArray " + name,
                          problem,
                          "the file is damaged or truncated; write it again.");
      }
    };

    /**
     * Value @p k of a binary array's header. Every number in a header
     * comes from the file, so each read is checked against the bytes that
     * are there.
     */
    std::uint64_t
    header_value(const VtuContext                 &ctx,
                 const std::vector<unsigned char> &header,
                 const std::uint64_t               k,
                 const std::string                &name)
    {
      const std::size_t hs = ctx.header_size();
      if (k >= header.size() / hs)
        throw ctx.damaged(name, "the array's header is cut short");
      // The sizes are in the file's byte order, like the data.
      unsigned char value[8];
      std::memcpy(value, header.data() + k * hs, hs);
      if (ctx.swap_bytes)
        reverse_bytes(value, hs);
      if (ctx.header_64)
        {
          std::uint64_t v;
          std::memcpy(&v, value, 8);
          return v;
        }
      std::uint32_t v;
      std::memcpy(&v, value, 4);
      return v;
    }

    /**
     * The data bytes of one binary array, given its decoded VTK header
     * (byte count, or block table if zlib-compressed) and the decoded bytes
     * that follow it. Every size in the header is checked against the
     * bytes that follow before anything is read or allocated.
     */
    std::vector<unsigned char>
    decode_block_data(const VtuContext                 &ctx,
                      const std::vector<unsigned char> &header,
                      const std::vector<unsigned char> &payload,
                      const std::string                &name)
    {
      if (!ctx.compressed)
        {
          const std::uint64_t n = header_value(ctx, header, 0, name);
          if (n > payload.size())
            throw ctx.damaged(name,
                              "the array's header says it holds " +
                                std::to_string(n) + " bytes, but only " +
                                std::to_string(payload.size()) + " follow it");
          return std::vector<unsigned char>(payload.begin(),
                                            payload.begin() + n);
        }
      // zlib's deflate packs at most 1032 bytes into one (zlib's technical
      // details): a block that claims more is damaged, and this bounds what
      // a damaged header can make us allocate.
      constexpr std::uint64_t    max_deflate_ratio = 1032;
      const std::uint64_t        n_blocks = header_value(ctx, header, 0, name);
      const std::uint64_t        block    = header_value(ctx, header, 1, name);
      const std::uint64_t        last     = header_value(ctx, header, 2, name);
      std::vector<unsigned char> out;
      std::size_t                offset = 0;
      for (std::uint64_t b = 0; b < n_blocks; ++b)
        {
          const std::uint64_t csize = header_value(ctx, header, 3 + b, name);
          const std::uint64_t size =
            (b + 1 == n_blocks && last != 0) ? last : block;
          if (csize > payload.size() - offset)
            throw ctx.damaged(name,
                              "compressed block " + std::to_string(b) +
                                " has " + std::to_string(csize) +
                                " bytes by the array's header, but only " +
                                std::to_string(payload.size() - offset) +
                                " are left");
          if (size > max_deflate_ratio * csize)
            throw ctx.damaged(name,
                              "compressed block " + std::to_string(b) +
                                " is said to unpack to " +
                                std::to_string(size) +
                                " bytes, more than zlib can pack into " +
                                std::to_string(csize) + " bytes");
          const std::size_t start = out.size();
          out.resize(start + size);
          uLongf unpacked = size;
          if (uncompress(out.data() + start,
                         &unpacked,
                         payload.data() + offset,
                         csize) != Z_OK)
            throw ctx.damaged(name,
                              "a zlib-compressed block cannot be "
                              "decompressed");
          out.resize(start + unpacked);
          offset += csize;
        }
      return out;
    }

    /**
     * Header length in bytes, given the first header value(s) and the
     * number of bytes @p available from the header's start to the end of
     * the data. A compressed array's header lists its blocks; a damaged
     * block count (up to 2^64 - 1) is refused before it is multiplied.
     */
    std::size_t
    header_length(const VtuContext                 &ctx,
                  const std::vector<unsigned char> &first,
                  const std::size_t                 available,
                  const std::string                &name)
    {
      const std::size_t hs = ctx.header_size();
      if (!ctx.compressed)
        return hs;
      const std::uint64_t n_blocks = header_value(ctx, first, 0, name);
      if (available / hs < 3 || n_blocks > available / hs - 3)
        throw ctx.damaged(name,
                          "the array's header lists " +
                            std::to_string(n_blocks) +
                            " compressed blocks, but the file holds only " +
                            std::to_string(available) +
                            " bytes from there on, too few for even their "
                            "sizes");
      return (3 + n_blocks) * hs;
    }

    /** The raw bytes of a binary (inline base64) or appended data array. */
    std::vector<unsigned char>
    binary_array_bytes(const VtuContext  &ctx,
                       const std::string &encoded, // inline: base64 text
                       const bool         is_inline,
                       const std::size_t  appended_offset,
                       const std::string &name)
    {
      const std::size_t hs = ctx.header_size();
      if (is_inline || ctx.appended_base64)
        {
          const std::string &text  = is_inline ? encoded : ctx.appended;
          const std::size_t  start = is_inline ? 0 : appended_offset;
          if (!is_inline && start >= text.size())
            throw ctx.damaged(name,
                              "the array's offset " + std::to_string(start) +
                                " points past the end of the appended data (" +
                                std::to_string(text.size()) + " characters)");
          // At most 3 bytes per 4 base64 characters from here on.
          const std::size_t available =
            start < text.size() ? (text.size() - start + 3) / 4 * 3 : 0;
          // VTK encodes header and data separately when compressing, and
          // writers differ otherwise: try "separately" first, then
          // "together".
          const std::size_t first_chars = 4 * ((hs + 2) / 3);
          auto              first =
            base64_decode(text,
                          start,
                          std::min(text.size(), start + first_chars));
          if (first.size() < hs)
            throw ctx.damaged(name, "the binary array is empty");
          const std::size_t hl = header_length(ctx, first, available, name);
          const std::size_t header_chars = 4 * ((hl + 2) / 3);
          // Appended base64 arrays follow each other; decoding stops at
          // the padding of this array's data, and the header says how many
          // bytes are this array's.
          const std::size_t end = text.size();
          const auto        header =
            base64_decode(text,
                          start,
                          std::min(text.size(), start + header_chars));
          if (header.size() >= hl)
            {
              const auto payload =
                base64_decode(text, start + header_chars, end);
              try
                {
                  auto bytes = decode_block_data(ctx, header, payload, name);
                  return bytes;
                }
              catch (const InputError &)
                {
                  // fall through to "together"
                }
            }
          const auto all = base64_decode(text, start, end);
          if (all.size() < hl)
            throw ctx.damaged(name,
                              "the binary array is shorter than its header");
          return decode_block_data(
            ctx,
            std::vector<unsigned char>(all.begin(), all.begin() + hl),
            std::vector<unsigned char>(all.begin() + hl, all.end()),
            name);
        }
      // Raw appended data: the offset and every length come from the file
      // and are checked against the bytes after the '_' marker.
      const std::size_t size = ctx.appended.size();
      if (appended_offset >= size)
        throw ctx.damaged(name,
                          "the array's offset " +
                            std::to_string(appended_offset) +
                            " points past the end of the appended data (" +
                            std::to_string(size) + " bytes)");
      const std::size_t left = size - appended_offset;
      const auto       *p =
        reinterpret_cast<const unsigned char *>(ctx.appended.data()) +
        appended_offset;
      if (left < hs)
        throw ctx.damaged(name,
                          "the appended data end inside the array's header");
      const std::vector<unsigned char> first(p, p + hs);
      const std::size_t hl = header_length(ctx, first, left, name);
      if (hl > left)
        throw ctx.damaged(name,
                          "the appended data end inside the array's header");
      return decode_block_data(ctx,
                               std::vector<unsigned char>(p, p + hl),
                               std::vector<unsigned char>(p + hl, p + left),
                               name);
    }

    /** The values of type @p T in @p bytes, byte-swapped first if
     * @p swap (the file's byte order is not this machine's). */
    template <typename T>
    std::vector<double>
    bytes_to_doubles(const std::vector<unsigned char> &bytes, const bool swap)
    {
      std::vector<double> v(bytes.size() / sizeof(T));
      for (std::size_t i = 0; i < v.size(); ++i)
        {
          unsigned char b[sizeof(T)];
          std::memcpy(b, bytes.data() + i * sizeof(T), sizeof(T));
          if (swap)
            reverse_bytes(b, sizeof(T));
          T x;
          std::memcpy(&x, b, sizeof(T));
          v[i] = static_cast<double>(x);
        }
      return v;
    }

    /** The values of one <DataArray>, whatever its format, as doubles. */
    std::vector<double>
    data_array_values(const VtuContext  &ctx,
                      const std::string &tag,
                      const std::string &content)
    {
      const std::string type   = attribute(tag, "type");
      const std::string format = attribute(tag, "format");
      const std::string name   = attribute(tag, "Name").empty() ?
                                   std::string("Points") :
                                   attribute(tag, "Name");
      if (format == "ascii")
        {
          std::istringstream  s(content);
          std::vector<double> v;
          double              x;
          while (s >> x)
            v.push_back(x);
          if (!s.eof())
            throw InputError(ctx.filename,
                             ctx.line,
                             "DataArray " + name,
                             "the ascii array holds something that is not a "
                             "number",
                             "the file is damaged; write it again.");
          return v;
        }
      if ((format == "binary" || format == "appended") &&
          !ctx.unknown_byte_order.empty())
        throw InputError(ctx.filename,
                         ctx.file_tag_line,
                         "VTKFile byte_order",
                         "byte_order=\"" + ctx.unknown_byte_order +
                           "\" is neither LittleEndian nor BigEndian, so "
                           "the binary data cannot be read",
                         "the file is damaged or was not written by VTK; "
                         "write it again (ParaView, meshio, deal.II).");
      std::vector<unsigned char> bytes;
      if (format == "binary")
        bytes = binary_array_bytes(ctx, strip_space(content), true, 0, name);
      else if (format == "appended")
        bytes = binary_array_bytes(ctx,
                                   "",
                                   false,
                                   count_attribute(ctx.filename,
                                                   ctx.line,
                                                   "DataArray " + name,
                                                   tag,
                                                   "offset"),
                                   name);
      else
        throw InputError(ctx.filename,
                         ctx.line,
                         "DataArray " + name,
                         "unknown format '" + format + "'",
                         "write the file again as ascii or binary.");
      if (type == "Float64")
        return bytes_to_doubles<double>(bytes, ctx.swap_bytes);
      if (type == "Float32")
        return bytes_to_doubles<float>(bytes, ctx.swap_bytes);
      if (type == "Int64")
        return bytes_to_doubles<std::int64_t>(bytes, ctx.swap_bytes);
      if (type == "UInt64")
        return bytes_to_doubles<std::uint64_t>(bytes, ctx.swap_bytes);
      if (type == "Int32")
        return bytes_to_doubles<std::int32_t>(bytes, ctx.swap_bytes);
      if (type == "UInt32")
        return bytes_to_doubles<std::uint32_t>(bytes, ctx.swap_bytes);
      if (type == "Int16")
        return bytes_to_doubles<std::int16_t>(bytes, ctx.swap_bytes);
      if (type == "UInt16")
        return bytes_to_doubles<std::uint16_t>(bytes, ctx.swap_bytes);
      if (type == "Int8")
        return bytes_to_doubles<std::int8_t>(bytes, ctx.swap_bytes);
      if (type == "UInt8")
        return bytes_to_doubles<std::uint8_t>(bytes, ctx.swap_bytes);
      throw InputError(ctx.filename,
                       ctx.line,
                       "DataArray " + name,
                       "unknown data type '" + type + "'",
                       "write the file again with standard VTK types.");
    }

    /** @p x as an index (a whole number in [0, 2^53]), or -1 if it is
     * none: the arrays hold doubles, and a damaged one may hold anything. */
    long
    as_index(const double x)
    {
      return (x >= 0 && x <= 9007199254740992. && x == std::floor(x)) ?
               static_cast<long>(x) :
               -1;
    }

    /**
     * The steps of read_vtk_xml() on one file, and what they share: the
     * file's text, how its arrays are stored, the piece's arrays and the
     * mesh read so far.
     */
    struct VtkXmlReader
    {
      VtkXmlReader(const std::string &filename, const bool polydata);

      /** The text of the XML tag that starts at @p begin, up to its '>'. */
      std::string
      tag_at(const std::size_t begin) const;

      /** Check the <VTKFile> tag and take how the data are stored. */
      void
      read_file_tag();

      /** Take the appended data out of the text. */
      void
      cut_appended_data();

      /** Read the <Piece>'s counts and its arrays. */
      void
      read_piece();

      /** Take the points of the piece's arrays. */
      void
      take_points();

      /** The cells of the piece's arrays: their points and types. */
      void
      read_cells(std::vector<std::vector<long>> &cells,
                 std::vector<int>               &types);

      /** Take the polygons of a .vtp as triangles. */
      void
      take_polygons(const std::vector<std::vector<long>> &cells);

      const std::string                          filename;
      const bool                                 polydata;
      std::string                                text;
      MeshData                                   data;
      VtuContext                                 ctx;
      bool                                       big_endian  = false;
      bool                                       binary_read = false;
      std::uint64_t                              n_points    = 0;
      std::uint64_t                              n_cells     = 0;
      std::map<std::string, std::vector<double>> arrays;
    };



    VtkXmlReader::VtkXmlReader(const std::string &filename, const bool polydata)
      : filename(filename)
      , polydata(polydata)
      , text(file_contents(filename))
    {
      ctx.filename = filename;
    }



    std::string
    VtkXmlReader::tag_at(const std::size_t begin) const
    {
      const auto end = text.find('>', begin);
      if (end == std::string::npos)
        throw InputError(filename,
                         line_at(text, begin),
                         "mesh file",
                         "the file ends inside an XML tag",
                         "the file is truncated; write it again.");
      return text.substr(begin, end - begin);
    }



    void
    VtkXmlReader::read_file_tag()
    {
      const auto file_tag_begin = text.find("<VTKFile");
      if (file_tag_begin == std::string::npos)
        throw InputError(filename,
                         1,
                         "mesh file",
                         "this is not a VTK XML file: there is no <VTKFile> "
                         "element",
                         "check the file name and extension (.msh, .vtk, "
                         ".vtu).");
      const std::string file_tag = tag_at(file_tag_begin);
      const std::string expected = polydata ? "PolyData" : "UnstructuredGrid";
      if (attribute(file_tag, "type") != expected)
        throw InputError(
          filename,
          1,
          polydata ? "surface file" : "mesh file",
          "the VTK XML file is a " + attribute(file_tag, "type") + ", not a " +
            expected,
          polydata ? "save the surface as a .vtp PolyData of triangles." :
          attribute(file_tag, "type") == "PolyData" ?
                     "this is a surface: give it to 'palpate mesh SURFACE "
                     "OUT.msh', or set Mesh / Source = surface, to make a "
                     "tetrahedral mesh of it." :
                     "save the tetrahedral mesh as a .vtu unstructured "
                     "grid.");
      // VTK writes the byte order of the machine that wrote the file;
      // another simulator's examples declare BigEndian even for ascii
      // data. Binary values are swapped to this machine's order.
      const std::string byte_order = attribute(file_tag, "byte_order");
      big_endian                   = byte_order == "BigEndian";
      if (big_endian || byte_order == "LittleEndian")
        ctx.swap_bytes = big_endian == host_is_little_endian();
      else if (!byte_order.empty())
        ctx.unknown_byte_order = byte_order;
      ctx.file_tag_line = line_at(text, file_tag_begin);
      ctx.header_64     = attribute(file_tag, "header_type") == "UInt64";
      const std::string compressor = attribute(file_tag, "compressor");
      if (!compressor.empty() && compressor != "vtkZLibDataCompressor")
        throw InputError(filename,
                         1,
                         "mesh file",
                         "the data are compressed with " + compressor +
                           "; palpate reads uncompressed or zlib data",
                         "save it with ParaView's Compressor Type = None or "
                         "ZLib, or as ascii.");
      ctx.compressed = !compressor.empty();
      data.format    = std::string("VTU ") +
                    (ctx.compressed ? "zlib-compressed" : "uncompressed");
    }



    void
    VtkXmlReader::cut_appended_data()
    {
      // Appended data: everything after the '_' marker up to the closing
      // tag (raw bytes may contain anything, so search from the end). A
      // file without the closing tag was cut short.
      const auto appended_tag = text.find("<AppendedData");
      if (appended_tag != std::string::npos)
        {
          const std::string tag = tag_at(appended_tag);
          ctx.appended_base64   = attribute(tag, "encoding") == "base64";
          const auto marker     = text.find('_', appended_tag + tag.size());
          const auto end        = text.rfind("</AppendedData>");
          if (marker == std::string::npos)
            throw InputError(filename,
                             line_at(text, appended_tag),
                             "mesh file",
                             "the <AppendedData> section has no '_' before "
                             "its data",
                             "the file is damaged; write it again.");
          if (end == std::string::npos || end < marker)
            throw InputError(filename,
                             line_at(text, appended_tag),
                             "mesh file",
                             "the file ends inside the <AppendedData> "
                             "section (there is no </AppendedData>)",
                             "the file is truncated; write it again.");
          ctx.appended = text.substr(marker + 1, end - marker - 1);
          if (ctx.appended_base64)
            ctx.appended = strip_space(ctx.appended);
          text = text.substr(0, appended_tag); // keep the XML part
        }
    }



    void
    VtkXmlReader::read_piece()
    {
      const auto piece = text.find("<Piece");
      if (piece == std::string::npos)
        throw InputError(filename,
                         1,
                         "mesh file",
                         "the file has no <Piece>",
                         "write the mesh again.");
      const std::string  piece_tag  = tag_at(piece);
      const unsigned int piece_line = line_at(text, piece);
      n_points                      = count_attribute(
        filename, piece_line, "Piece", piece_tag, "NumberOfPoints");
      n_cells = count_attribute(filename,
                                piece_line,
                                "Piece",
                                piece_tag,
                                polydata ? "NumberOfPolys" : "NumberOfCells");

      // Collect the data arrays of the <Points> and <Cells> sections.
      for (const std::string &section :
           {std::string("Points"), std::string(polydata ? "Polys" : "Cells")})
        {
          const auto begin = text.find("<" + section + ">", piece);
          const auto end   = text.find("</" + section + ">", piece);
          if (begin == std::string::npos || end == std::string::npos)
            throw InputError(filename,
                             1,
                             "mesh file",
                             "the piece has no <" + section + "> section",
                             "write the mesh again as an unstructured grid.");
          std::size_t pos = begin;
          while (true)
            {
              const auto a = text.find("<DataArray", pos);
              if (a == std::string::npos || a > end)
                break;
              const std::string tag     = tag_at(a);
              const std::size_t tag_end = a + tag.size();
              std::string       content;
              std::size_t       next = tag_end + 1;
              if (text[tag_end - 1] != '/')
                {
                  const auto close = text.find("</DataArray>", tag_end);
                  if (close == std::string::npos)
                    throw InputError(filename,
                                     line_at(text, a),
                                     "DataArray " + attribute(tag, "Name"),
                                     "the <DataArray> is not closed by "
                                     "</DataArray>",
                                     "the file is truncated; write it again.");
                  content = text.substr(tag_end + 1, close - tag_end - 1);
                  next    = close;
                }
              const std::string key =
                section == "Points" ? "points" : attribute(tag, "Name");
              ctx.line    = line_at(text, a);
              arrays[key] = data_array_values(ctx, tag, content);
              binary_read |= attribute(tag, "format") != "ascii";
              pos = next;
            }
        }
    }



    void
    VtkXmlReader::take_points()
    {
      if (polydata)
        arrays["types"].assign(n_cells, 0); // polygons, split below
      for (const std::string key :
           {"points", "connectivity", "offsets", "types"})
        if (arrays.count(key) == 0)
          throw InputError(filename,
                           1,
                           "mesh file",
                           "the file has no '" + key + "' data array",
                           "write the mesh again as an unstructured grid.");
      const auto &points = arrays["points"];
      if (points.size() != 3 * n_points)
        throw InputError(filename,
                         1,
                         "mesh file",
                         "the Points array holds " +
                           std::to_string(points.size()) + " numbers for " +
                           std::to_string(n_points) + " points",
                         "write the mesh again with 3-D points.");
      for (std::size_t i = 0; i < n_points; ++i)
        {
          data.nodes.push_back(
            {{points[3 * i], points[3 * i + 1], points[3 * i + 2]}});
          data.node_ids.push_back(i);
        }
    }



    void
    VtkXmlReader::read_cells(std::vector<std::vector<long>> &cells,
                             std::vector<int>               &types)
    {
      const auto &connectivity = arrays["connectivity"];
      const auto &offsets      = arrays["offsets"];
      const auto &types_d      = arrays["types"];
      if (offsets.size() != n_cells || types_d.size() != n_cells)
        throw InputError(filename,
                         1,
                         "mesh file",
                         "the offsets or types arrays do not have one entry "
                         "per cell",
                         "the file is damaged; write it again.");
      std::size_t begin = 0;
      for (std::size_t c = 0; c < n_cells; ++c)
        {
          const long end = as_index(offsets[c]);
          if (end < 0 || static_cast<std::size_t>(end) > connectivity.size() ||
              static_cast<std::size_t>(end) < begin)
            throw InputError(filename,
                             1,
                             "mesh file, cell " + std::to_string(c),
                             "the offsets array is inconsistent",
                             "the file is damaged; write it again.");
          cells.emplace_back();
          for (std::size_t k = begin; k < static_cast<std::size_t>(end); ++k)
            {
              const long point = as_index(connectivity[k]);
              if (point < 0)
                throw InputError(filename,
                                 1,
                                 "mesh file, cell " + std::to_string(c),
                                 "the connectivity array holds " +
                                   std::to_string(connectivity[k]) +
                                   ", which is not a point index",
                                 "the file is damaged; write it again.");
              cells.back().push_back(point);
            }
          const long type = as_index(types_d[c]);
          types.push_back(type <= 255 ? static_cast<int>(type) : -1);
          begin = end;
        }
    }



    void
    VtkXmlReader::take_polygons(const std::vector<std::vector<long>> &cells)
    {
      // Polygons: split into fans of triangles.
      for (const auto &cell : cells)
        for (std::size_t k = 1; k + 1 < cell.size(); ++k)
          {
            for (const long v : {cell[0], cell[k], cell[k + 1]})
              if (static_cast<std::size_t>(v) >= n_points)
                throw InputError(filename,
                                 1,
                                 "surface file",
                                 "a polygon refers to point " +
                                   std::to_string(v) + " of " +
                                   std::to_string(n_points),
                                 "the file is damaged; write it again.");
            data.triangles.push_back(
              {{static_cast<unsigned int>(cell[0]),
                static_cast<unsigned int>(cell[k]),
                static_cast<unsigned int>(cell[k + 1])}});
            data.triangle_boundary_ids.push_back(0);
            data.triangle_lines.push_back(0);
          }
      data.format = std::string("VTP ") +
                    (ctx.compressed ? "zlib-compressed" : "uncompressed") +
                    (big_endian && binary_read ? ", big-endian" : "");
    }



    MeshData
    read_vtk_xml(const std::string &filename, const bool polydata)
    {
      VtkXmlReader r(filename, polydata);
      r.read_file_tag();
      r.cut_appended_data();
      r.read_piece();
      r.take_points();
      std::vector<std::vector<long>> cells;
      std::vector<int>               types;
      r.read_cells(cells, types);
      if (polydata)
        {
          r.take_polygons(cells);
          return std::move(r.data);
        }
      if (r.big_endian && r.binary_read)
        r.data.format += ", big-endian";
      LineReader reader(filename);
      add_vtk_cells(reader,
                    cells,
                    types,
                    std::vector<unsigned int>(cells.size(), 0),
                    r.data);
      return std::move(r.data);
    }
  } // namespace



  MeshData
  read_vtp(const std::string &filename)
  {
    return read_vtk_xml(filename, true);
  }



  long
  far_outlier(const std::vector<Utilities::Point3> &points)
  {
    if (points.size() < 4)
      return -1;
    for (std::size_t i = 0; i < points.size(); ++i)
      for (const double x : points[i])
        if (!std::isfinite(x))
          return i;
    // The median point, and the median distance from it: robust to a few
    // wild points, unlike the mean and the bounding box.
    Utilities::Point3 centre;
    for (unsigned int d = 0; d < 3; ++d)
      {
        std::vector<double> c(points.size());
        for (std::size_t i = 0; i < points.size(); ++i)
          c[i] = points[i][d];
        std::nth_element(c.begin(), c.begin() + c.size() / 2, c.end());
        centre[d] = c[c.size() / 2];
      }
    std::vector<double> distance(points.size());
    for (std::size_t i = 0; i < points.size(); ++i)
      distance[i] = Utilities::distance(points[i], centre);
    std::vector<double> sorted = distance;
    std::nth_element(sorted.begin(),
                     sorted.begin() + sorted.size() / 2,
                     sorted.end());
    const double typical = sorted[sorted.size() / 2];
    const auto   far     = std::max_element(distance.begin(), distance.end());
    if (typical > 0 && std::isfinite(*far) && *far <= 1000 * typical)
      return -1;
    if (!(typical > 0) && !(*far > 0))
      return -1; // all in one point: another check says so
    return far - distance.begin();
  }



  MeshData
  read_mesh_file(const std::string &filename)
  {
    namespace fs = std::filesystem;
    // std::filesystem's throwing forms would report a path that cannot be
    // examined (a symbolic link loop, a directory on the way that may not
    // be searched) as a std::filesystem_error, not as bad input.
    // Why it cannot be opened is said as every reader says it (a loop of
    // links is no missing file, a link to nowhere names its target).
    bool              missing = false;
    const std::string why     = why_cannot_open(filename, &missing);
    if (missing)
      throw InputError(filename,
                       0,
                       "mesh file",
                       "the file " + why.substr(why.find(' ') + 1),
                       "check the path.");
    if (!why.empty())
      throw unreadable(filename, why);
    std::error_code       ec;
    const fs::file_status status = fs::status(filename, ec);
    if (fs::is_directory(status))
      {
        std::vector<std::string> meshes;
        for (const auto &e : fs::directory_iterator(filename, ec))
          {
            const std::string extension = e.path().extension().string();
            if (extension == ".msh" || extension == ".vtk" ||
                extension == ".vtu")
              meshes.push_back(e.path().string());
          }
        std::sort(meshes.begin(), meshes.end());
        throw InputError(filename,
                         0,
                         "mesh file",
                         "this is a directory, not a mesh file: it cannot be "
                         "read as a mesh",
                         meshes.empty() ?
                           std::string("name the mesh file itself (.msh, "
                                       ".vtk or .vtu).") :
                           "name one of the " + std::to_string(meshes.size()) +
                             " mesh files in it, e.g. '" + meshes.front() +
                             "'.");
      }
    check_file_size(filename,
                    "mesh file",
                    max_mesh_file_bytes,
                    "a liver of 8,000 nodes has about 2 MiB as .msh; 512 MiB "
                    "hold about two million nodes");
    {
      errno = 0;
      std::ifstream probe(filename);
      if (!probe)
        throw unreadable(filename, system_reason());
    }
    const std::string extension =
      std::filesystem::path(filename).extension().string();
    if (extension == ".msh")
      return read_gmsh(filename);
    if (extension == ".vtk")
      return read_vtk(filename);
    if (extension == ".vtu")
      return read_vtk_xml(filename, false);
    if (extension == ".vtp" || extension == ".stl" || extension == ".obj" ||
        extension == ".ply")
      throw InputError(filename,
                       0,
                       "mesh file",
                       "this is a surface file (" + extension +
                         "): palpate needs a tetrahedral volume mesh here",
                       "make one with 'palpate mesh " + filename +
                         " OUT.msh --scale S' (S = metres per file unit, "
                         "0.001 for millimetres), or set Mesh / Source = "
                         "surface with this file as File name.");
    throw InputError(filename,
                     0,
                     "mesh file",
                     "palpate does not know the extension '" + extension + "'",
                     "use a Gmsh .msh (2.2 or v1), a legacy .vtk or a .vtu "
                     "file.");
  }
} // namespace palpate
