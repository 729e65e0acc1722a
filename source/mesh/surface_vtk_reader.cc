// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

#include <palpate/mesh/surface_impl.h>

#include <algorithm>
#include <sstream>

namespace palpate
{
  namespace internal
  {
    namespace
    {
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
              throw bad(filename,
                        k + 1,
                        "the VTK header is incomplete",
                        damaged);
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
            std::string line = Utilities::trim(data.substr(
              pos, (end == std::string::npos ? data.size() : end) - pos));
            pos              = end == std::string::npos ? data.size() : end + 1;
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
      VtkLegacyReader::binary_values(const std::size_t  n,
                                     const std::string &type)
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
                      " values follow, but only " +
                      std::to_string(bytes_left()) + " bytes are left in it",
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
                      " points follow, but only " +
                      std::to_string(bytes_left()) + " bytes are left in it",
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
      VtkLegacyReader::read_cell_list(const std::size_t n,
                                      const std::size_t size)
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
    } // namespace



    Surface
    read_vtk_polydata(const std::string &filename)
    {
      VtkLegacyReader reader(filename);
      reader.read_header();
      return reader.read_sections();
    }
  } // namespace internal
} // namespace palpate
