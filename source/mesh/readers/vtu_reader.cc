// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

// VTK XML unstructured grids (.vtu) and polygon data (.vtp): the XML
// structure; the arrays' encodings are read by vtk_xml_data.cc.

#include <palpate/mesh/readers/line_reader.h>
#include <palpate/mesh/readers/vtk_reader.h>
#include <palpate/mesh/readers/vtk_xml_data.h>
#include <palpate/mesh/readers/vtu_reader.h>

#include <cerrno>
#include <cmath>
#include <cstdint>
#include <fstream>
#include <map>
#include <utility>
#include <vector>

namespace palpate
{
  namespace mesh_readers
  {
    namespace
    {
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

      VtkXmlReader::VtkXmlReader(const std::string &filename,
                                 const bool         polydata)
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
            "the VTK XML file is a " + attribute(file_tag, "type") +
              ", not a " + expected,
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
                      throw InputError(
                        filename,
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
            if (end < 0 ||
                static_cast<std::size_t>(end) > connectivity.size() ||
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

    } // namespace

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
  } // namespace mesh_readers
} // namespace palpate
