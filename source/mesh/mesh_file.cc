// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

#include <palpate/base/exceptions.h>
#include <palpate/mesh/mesh_file.h>

#include <zlib.h>

#include <algorithm>
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
            line = Utilities::trim(raw);
            if (!line.empty())
              return true;
          }
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
        throw reader.error("'" + token + "' is not a valid " + what,
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

    MeshData
    read_gmsh(const std::string &filename)
    {
      LineReader reader(filename);
      MeshData   data;

      std::string line;
      if (!reader.next(line))
        throw reader.error("the file is empty",
                           "write the mesh again from Gmsh or TetGen.");

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
              const long n = parse_number<long>(reader,
                                                reader.expect("the node count"),
                                                "node count");
              for (long i = 0; i < n; ++i)
                {
                  const auto t = tokens_of(reader.expect("a node"));
                  if (t.size() < 4)
                    throw reader.error("a node line needs 'number x y z'",
                                       "the file is damaged; export it "
                                       "again.");
                  const long tag =
                    parse_number<long>(reader, t[0], "node number");
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
              have_nodes = true;
            }
          else if (line == elements_begin)
            {
              if (!have_nodes)
                throw reader.error("the elements come before the nodes",
                                   "export the file again.");
              const long n =
                parse_number<long>(reader,
                                   reader.expect("the element count"),
                                   "element count");
              for (long i = 0; i < n; ++i)
                {
                  const auto t = tokens_of(reader.expect("an element"));
                  if (t.size() < 3)
                    throw reader.error("an element line is too short",
                                       "the file is damaged.");
                  const long id =
                    parse_number<long>(reader, t[0], "element number");
                  const int type =
                    parse_number<int>(reader, t[1], "element type");
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
                      physical   = parse_number<unsigned int>(reader,
                                                            t[2],
                                                            "physical tag");
                      first_node = 5;
                    }
                  else
                    {
                      // number type n-tags tags... nodes...
                      const unsigned int n_tags =
                        parse_number<unsigned int>(reader, t[2], "tag count");
                      if (n_tags > 0 && t.size() > 3)
                        physical = parse_number<unsigned int>(reader,
                                                              t[3],
                                                              "physical tag");
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
                throw reader.error("expected " + elements_end +
                                     " after the elements",
                                   "the element count does not match the "
                                   "elements; export the file again.");
              have_elements = true;
            }
          else if (!line.empty() && line[0] == '$')
            {
              // Skip any other section ($PhysicalNames, $NodeData, ...).
              const std::string end =
                legacy ? "$END" + line.substr(1) : "$End" + line.substr(1);
              std::string skip;
              while (reader.next(skip) && skip != end)
                ;
            }
          else
            throw reader.error("unexpected line '" + line +
                                 "' between sections",
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

    MeshData
    read_vtk(const std::string &filename)
    {
      LineReader reader(filename);
      MeshData   data;

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

      TokenReader tokens(reader);
      if (tokens.next("DATASET") != "DATASET" ||
          tokens.next("the data set type") != "UNSTRUCTURED_GRID")
        throw reader.error("the data set is not an UNSTRUCTURED_GRID",
                           "write the tetrahedral mesh as an unstructured "
                           "grid.");

      std::vector<std::vector<long>> cells;
      std::vector<int>               types;
      std::vector<unsigned int>      cell_lines;
      while (!tokens.at_end())
        {
          const std::string keyword = tokens.next("a section keyword");
          if (keyword == "POINTS")
            {
              const long n = tokens.number<long>("point count");
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
            {
              const long n    = tokens.number<long>("cell count");
              const long size = tokens.number<long>("cell list size");
              if (tokens.at_end())
                throw reader.error("the CELLS section is empty",
                                   "the file is truncated.");
              if (tokens.tokens[tokens.position] == "OFFSETS")
                {
                  // VTK 5.1: CELLS n_offsets n_connectivity, then arrays.
                  tokens.next("OFFSETS");
                  tokens.next("the offset type");
                  std::vector<long> offsets(n);
                  for (auto &o : offsets)
                    o = tokens.number<long>("offset");
                  if (tokens.next("CONNECTIVITY") != "CONNECTIVITY")
                    throw reader.error("expected CONNECTIVITY after OFFSETS",
                                       "the file is damaged.");
                  tokens.next("the connectivity type");
                  std::vector<long> connectivity(size);
                  for (auto &c : connectivity)
                    c = tokens.number<long>("point index");
                  for (long c = 0; c + 1 < n; ++c)
                    {
                      cells.emplace_back(connectivity.begin() + offsets[c],
                                         connectivity.begin() + offsets[c + 1]);
                      cell_lines.push_back(reader.number);
                    }
                }
              else
                for (long c = 0; c < n; ++c)
                  {
                    const long        k = tokens.number<long>("cell size");
                    std::vector<long> cell(k);
                    for (auto &p : cell)
                      p = tokens.number<long>("point index");
                    cells.push_back(cell);
                    cell_lines.push_back(reader.number);
                  }
            }
          else if (keyword == "CELL_TYPES")
            {
              const long n = tokens.number<long>("cell type count");
              for (long c = 0; c < n; ++c)
                types.push_back(tokens.number<int>("cell type"));
            }
          else if (keyword == "POINT_DATA" || keyword == "CELL_DATA" ||
                   keyword == "FIELD")
            break; // palpate needs no data arrays
          else
            throw reader.error("unexpected keyword '" + keyword + "'",
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

    struct VtuContext
    {
      std::string filename;
      bool        header_64  = false;
      bool        compressed = false;
      std::string appended; // raw bytes, or base64 text
      bool        appended_base64 = false;
    };

    std::uint64_t
    read_header_value(const unsigned char *p, const bool header_64)
    {
      if (header_64)
        {
          std::uint64_t v;
          std::memcpy(&v, p, 8);
          return v;
        }
      std::uint32_t v;
      std::memcpy(&v, p, 4);
      return v;
    }

    /**
     * The data bytes of one binary array, given its decoded VTK header
     * (byte count, or block table if zlib-compressed) and the decoded bytes
     * that follow it.
     */
    std::vector<unsigned char>
    decode_block_data(const VtuContext                 &ctx,
                      const std::vector<unsigned char> &header,
                      const std::vector<unsigned char> &payload,
                      const std::string                &name)
    {
      const std::size_t hs = ctx.header_64 ? 8 : 4;
      if (!ctx.compressed)
        {
          const std::uint64_t n =
            read_header_value(header.data(), ctx.header_64);
          if (payload.size() < n)
            throw InputError(ctx.filename,
                             0,
                             "DataArray " + name,
                             "the array is shorter than its header says",
                             "the file is damaged; write it again.");
          return std::vector<unsigned char>(payload.begin(),
                                            payload.begin() + n);
        }
      const std::uint64_t n_blocks =
        read_header_value(header.data(), ctx.header_64);
      const std::uint64_t block =
        read_header_value(header.data() + hs, ctx.header_64);
      const std::uint64_t last =
        read_header_value(header.data() + 2 * hs, ctx.header_64);
      std::vector<unsigned char> out;
      std::size_t                offset = 0;
      for (std::uint64_t b = 0; b < n_blocks; ++b)
        {
          const std::uint64_t csize =
            read_header_value(header.data() + (3 + b) * hs, ctx.header_64);
          uLongf size = (b + 1 == n_blocks && last != 0) ? last : block;
          const std::size_t start = out.size();
          out.resize(start + size);
          if (offset + csize > payload.size() ||
              uncompress(out.data() + start,
                         &size,
                         payload.data() + offset,
                         csize) != Z_OK)
            throw InputError(ctx.filename,
                             0,
                             "DataArray " + name,
                             "a zlib-compressed block cannot be decompressed",
                             "the file is damaged; write it again.");
          out.resize(start + size);
          offset += csize;
        }
      return out;
    }

    /** Header length in bytes, given the first header value(s). */
    std::size_t
    header_length(const VtuContext                 &ctx,
                  const std::vector<unsigned char> &first)
    {
      const std::size_t hs = ctx.header_64 ? 8 : 4;
      if (!ctx.compressed)
        return hs;
      return (3 + read_header_value(first.data(), ctx.header_64)) * hs;
    }

    /** The raw bytes of a binary (inline base64) or appended data array. */
    std::vector<unsigned char>
    binary_array_bytes(const VtuContext  &ctx,
                       const std::string &encoded, // inline: base64 text
                       const bool         is_inline,
                       const std::size_t  appended_offset,
                       const std::string &name)
    {
      const std::size_t hs = ctx.header_64 ? 8 : 4;
      if (is_inline || ctx.appended_base64)
        {
          const std::string &text  = is_inline ? encoded : ctx.appended;
          const std::size_t  start = is_inline ? 0 : appended_offset;
          // VTK encodes header and data separately when compressing, and
          // writers differ otherwise: try "separately" first, then
          // "together".
          const std::size_t first_chars = 4 * ((hs + 2) / 3);
          auto              first =
            base64_decode(text,
                          start,
                          std::min(text.size(), start + first_chars));
          if (first.size() < hs)
            throw InputError(ctx.filename,
                             0,
                             "DataArray " + name,
                             "the binary array is empty",
                             "the file is damaged; write it again.");
          const std::size_t hl           = header_length(ctx, first);
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
            throw InputError(ctx.filename,
                             0,
                             "DataArray " + name,
                             "the binary array is shorter than its header",
                             "the file is damaged; write it again.");
          return decode_block_data(
            ctx,
            std::vector<unsigned char>(all.begin(), all.begin() + hl),
            std::vector<unsigned char>(all.begin() + hl, all.end()),
            name);
        }
      // raw appended data
      const auto *p =
        reinterpret_cast<const unsigned char *>(ctx.appended.data());
      if (appended_offset + hs > ctx.appended.size())
        throw InputError(ctx.filename,
                         0,
                         "DataArray " + name,
                         "the offset points past the appended data",
                         "the file is damaged; write it again.");
      const std::vector<unsigned char> first(p + appended_offset,
                                             p + appended_offset + hs);
      const std::size_t                hl = header_length(ctx, first);
      const std::vector<unsigned char> header(p + appended_offset,
                                              p + appended_offset + hl);
      const std::vector<unsigned char> payload(p + appended_offset + hl,
                                               p + ctx.appended.size());
      return decode_block_data(ctx, header, payload, name);
    }

    template <typename T>
    std::vector<double>
    bytes_to_doubles(const std::vector<unsigned char> &bytes)
    {
      std::vector<double> v(bytes.size() / sizeof(T));
      for (std::size_t i = 0; i < v.size(); ++i)
        {
          T x;
          std::memcpy(&x, bytes.data() + i * sizeof(T), sizeof(T));
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
      const std::string name   = attribute(tag, "Name");
      if (format == "ascii")
        {
          std::istringstream  s(content);
          std::vector<double> v;
          double              x;
          while (s >> x)
            v.push_back(x);
          if (!s.eof())
            throw InputError(ctx.filename,
                             0,
                             "DataArray " + name,
                             "the ascii array holds something that is not a "
                             "number",
                             "the file is damaged; write it again.");
          return v;
        }
      std::vector<unsigned char> bytes;
      if (format == "binary")
        bytes = binary_array_bytes(ctx, strip_space(content), true, 0, name);
      else if (format == "appended")
        bytes = binary_array_bytes(
          ctx, "", false, std::stoul(attribute(tag, "offset")), name);
      else
        throw InputError(ctx.filename,
                         0,
                         "DataArray " + name,
                         "unknown format '" + format + "'",
                         "write the file again as ascii or binary.");
      if (type == "Float64")
        return bytes_to_doubles<double>(bytes);
      if (type == "Float32")
        return bytes_to_doubles<float>(bytes);
      if (type == "Int64")
        return bytes_to_doubles<std::int64_t>(bytes);
      if (type == "UInt64")
        return bytes_to_doubles<std::uint64_t>(bytes);
      if (type == "Int32")
        return bytes_to_doubles<std::int32_t>(bytes);
      if (type == "UInt32")
        return bytes_to_doubles<std::uint32_t>(bytes);
      if (type == "Int16")
        return bytes_to_doubles<std::int16_t>(bytes);
      if (type == "UInt16")
        return bytes_to_doubles<std::uint16_t>(bytes);
      if (type == "Int8")
        return bytes_to_doubles<std::int8_t>(bytes);
      if (type == "UInt8")
        return bytes_to_doubles<std::uint8_t>(bytes);
      throw InputError(ctx.filename,
                       0,
                       "DataArray " + name,
                       "unknown data type '" + type + "'",
                       "write the file again with standard VTK types.");
    }

    MeshData
    read_vtu(const std::string &filename)
    {
      std::ifstream     in(filename, std::ios::binary);
      std::stringstream buffer;
      buffer << in.rdbuf();
      std::string text = buffer.str();

      MeshData   data;
      VtuContext ctx;
      ctx.filename = filename;

      const auto file_tag_begin = text.find("<VTKFile");
      if (file_tag_begin == std::string::npos)
        throw InputError(filename,
                         1,
                         "mesh file",
                         "this is not a VTK XML file: there is no <VTKFile> "
                         "element",
                         "check the file name and extension (.msh, .vtk, "
                         ".vtu).");
      const std::string file_tag =
        text.substr(file_tag_begin,
                    text.find('>', file_tag_begin) - file_tag_begin);
      if (attribute(file_tag, "type") != "UnstructuredGrid")
        throw InputError(filename,
                         1,
                         "mesh file",
                         "the VTK XML file is not an UnstructuredGrid",
                         "save the tetrahedral mesh as a .vtu unstructured "
                         "grid.");
      if (attribute(file_tag, "byte_order") == "BigEndian")
        throw InputError(filename,
                         1,
                         "mesh file",
                         "big-endian binary data is not supported",
                         "save it as ascii (ParaView: Data mode Ascii).");
      ctx.header_64 = attribute(file_tag, "header_type") == "UInt64";
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

      // Appended data: everything after the '_' marker up to the closing
      // tag (raw bytes may contain anything, so search from the end).
      const auto appended_tag = text.find("<AppendedData");
      if (appended_tag != std::string::npos)
        {
          const std::string tag =
            text.substr(appended_tag,
                        text.find('>', appended_tag) - appended_tag);
          ctx.appended_base64 = attribute(tag, "encoding") == "base64";
          const auto start    = text.find('_', appended_tag) + 1;
          const auto end      = text.rfind("</AppendedData>");
          ctx.appended        = text.substr(start, end - start);
          if (ctx.appended_base64)
            ctx.appended = strip_space(ctx.appended);
          text = text.substr(0, appended_tag); // keep the XML part
        }

      const auto piece = text.find("<Piece");
      if (piece == std::string::npos)
        throw InputError(filename,
                         1,
                         "mesh file",
                         "the file has no <Piece>",
                         "write the mesh again.");
      const std::string piece_tag =
        text.substr(piece, text.find('>', piece) - piece);
      const long n_points =
        std::stol("0" + attribute(piece_tag, "NumberOfPoints"));
      const long n_cells =
        std::stol("0" + attribute(piece_tag, "NumberOfCells"));

      // Collect the data arrays of the <Points> and <Cells> sections.
      std::map<std::string, std::vector<double>> arrays;
      for (const std::string section : {"Points", "Cells"})
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
              const auto        tag_end = text.find('>', a);
              const std::string tag     = text.substr(a, tag_end - a);
              std::string       content;
              std::size_t       next = tag_end + 1;
              if (text[tag_end - 1] != '/')
                {
                  const auto close = text.find("</DataArray>", tag_end);
                  content = text.substr(tag_end + 1, close - tag_end - 1);
                  next    = close;
                }
              const std::string key =
                section == "Points" ? "points" : attribute(tag, "Name");
              arrays[key] = data_array_values(ctx, tag, content);
              pos         = next;
            }
        }
      for (const std::string key :
           {"points", "connectivity", "offsets", "types"})
        if (arrays.count(key) == 0)
          throw InputError(filename,
                           1,
                           "mesh file",
                           "the file has no '" + key + "' data array",
                           "write the mesh again as an unstructured grid.");
      const auto &points = arrays["points"];
      if (static_cast<long>(points.size()) != 3 * n_points)
        throw InputError(filename,
                         1,
                         "mesh file",
                         "the Points array holds " +
                           std::to_string(points.size()) + " numbers for " +
                           std::to_string(n_points) + " points",
                         "write the mesh again with 3-D points.");
      for (long i = 0; i < n_points; ++i)
        {
          data.nodes.push_back(
            {{points[3 * i], points[3 * i + 1], points[3 * i + 2]}});
          data.node_ids.push_back(i);
        }
      const auto &connectivity = arrays["connectivity"];
      const auto &offsets      = arrays["offsets"];
      const auto &types_d      = arrays["types"];
      if (static_cast<long>(offsets.size()) != n_cells ||
          static_cast<long>(types_d.size()) != n_cells)
        throw InputError(filename,
                         1,
                         "mesh file",
                         "the offsets or types arrays do not have one entry "
                         "per cell",
                         "the file is damaged; write it again.");
      std::vector<std::vector<long>> cells;
      std::vector<int>               types;
      std::size_t                    begin = 0;
      for (long c = 0; c < n_cells; ++c)
        {
          const std::size_t end = static_cast<std::size_t>(offsets[c]);
          if (end > connectivity.size() || end < begin)
            throw InputError(filename,
                             1,
                             "mesh file, cell " + std::to_string(c),
                             "the offsets array is inconsistent",
                             "the file is damaged; write it again.");
          cells.emplace_back();
          for (std::size_t k = begin; k < end; ++k)
            cells.back().push_back(static_cast<long>(connectivity[k]));
          types.push_back(static_cast<int>(types_d[c]));
          begin = end;
        }
      LineReader reader(filename);
      add_vtk_cells(
        reader, cells, types, std::vector<unsigned int>(cells.size(), 0), data);
      return data;
    }
  } // namespace



  MeshData
  read_mesh_file(const std::string &filename)
  {
    if (!std::filesystem::exists(filename))
      throw InputError(
        filename, 0, "mesh file", "the file does not exist", "check the path.");
    if (std::filesystem::is_directory(filename))
      throw InputError(filename,
                       0,
                       "mesh file",
                       "this is a directory, not a mesh file",
                       "name the mesh file itself.");
    {
      std::ifstream probe(filename);
      if (!probe)
        throw InputError(filename,
                         0,
                         "mesh file",
                         "the file cannot be read (permissions?)",
                         "make it readable.");
    }
    const std::string extension =
      std::filesystem::path(filename).extension().string();
    if (extension == ".msh")
      return read_gmsh(filename);
    if (extension == ".vtk")
      return read_vtk(filename);
    if (extension == ".vtu")
      return read_vtu(filename);
    throw InputError(filename,
                     0,
                     "mesh file",
                     "palpate does not know the extension '" + extension + "'",
                     "use a Gmsh .msh (2.2 or v1), a legacy .vtk or a .vtu "
                     "file.");
  }
} // namespace palpate
