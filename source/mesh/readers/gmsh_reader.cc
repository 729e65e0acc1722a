// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

// Gmsh (.msh), format 2.2 and the legacy format 1, ASCII.

#include <palpate/mesh/readers/gmsh_reader.h>
#include <palpate/mesh/readers/line_reader.h>

#include <map>
#include <vector>

namespace palpate
{
  namespace mesh_readers
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
              throw reader.error(
                "this is a binary .msh file",
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
            const long id = parse_number<long>(reader, t[0], "element number");
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
    } // namespace

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
  } // namespace mesh_readers
} // namespace palpate
