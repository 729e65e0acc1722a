// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

// Legacy VTK (.vtk), ASCII unstructured grid.

#include <palpate/mesh/readers/vtk_reader.h>

#include <filesystem>
#include <fstream>
#include <regex>

namespace palpate
{
  namespace mesh_readers
  {
    namespace
    {
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
              throw reader.error(
                "offset " + std::to_string(i) + " (" +
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
    } // namespace

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
  } // namespace mesh_readers
} // namespace palpate
