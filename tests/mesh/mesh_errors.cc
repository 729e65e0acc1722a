// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

// Broken mesh files are refused with the file, the line and a fix, never a
// crash and never a silently repaired mesh: an inverted tetrahedron, a
// degenerate one, a repeated node, two nodes at one point, a duplicated
// tetrahedron, an undefined node, a hexahedron, a second-order tetrahedron,
// a Gmsh 4 file, a binary file, UTF-16, a wrong node count, a truncated
// file, two disconnected bodies, a boundary triangle that is no face, and an
// unknown extension. A UTF-8 byte order mark is skipped.

#include <palpate/base/exceptions.h>
#include <palpate/mesh/mesh.h>
#include <palpate/mesh/mesh_file.h>

#include "../tests.h"

namespace
{
  const std::string nodes = "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n"
                            "$Nodes\n5\n"
                            "1 0 0 0\n2 1 0 0\n3 0 1 0\n4 0 0 1\n5 1 1 1\n"
                            "$EndNodes\n";

  std::string
  elements(const std::vector<std::string> &lines)
  {
    std::string s = "$Elements\n" + std::to_string(lines.size()) + "\n";
    for (const auto &l : lines)
      s += l + "\n";
    return s + "$EndElements\n";
  }

  void
  check(const std::string &what,
        const std::string &file,
        const std::string &text)
  {
    write_file(file, text);
    try
      {
        const palpate::Mesh mesh(palpate::read_mesh_file(file), 1.0, file);
        deallog << what << ": accepted, " << mesh.n_cells() << " tetrahedra"
                << std::endl;
      }
    catch (const palpate::InputError &e)
      {
        deallog << what << ": refused" << std::endl << e.what() << std::endl;
      }
  }
} // namespace

int
main(int argc, char **argv)
{
  palpate::Environment env(argc, argv);
  initlog();

  check("a valid tetrahedron",
        "good.msh",
        nodes + elements({"1 4 2 1 1 1 2 3 4"}));
  // Encodings: a UTF-8 byte order mark (some Windows tools write one) is
  // skipped; UTF-16 is named, not "does not start with $MeshFormat".
  check("a valid tetrahedron after a UTF-8 byte order mark",
        "bom.msh",
        "\xEF\xBB\xBF" + nodes + elements({"1 4 2 1 1 1 2 3 4"}));
  {
    const std::string text  = nodes + elements({"1 4 2 1 1 1 2 3 4"});
    std::string       utf16 = "\xFF\xFE";
    for (const char c : text)
      utf16 += std::string(1, c) + '\0';
    check("a mesh file in UTF-16", "utf16.msh", utf16);
  }
  // A node count larger than the section: the count is named.
  check("a node count larger than the node section",
        "count.msh",
        "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$Nodes\n999999999\n"
        "1 0 0 0\n2 1 0 0\n3 0 1 0\n4 0 0 1\n$EndNodes\n" +
          elements({"1 4 2 1 1 1 2 3 4"}));
  check("an inverted tetrahedron",
        "inverted.msh",
        nodes + elements({"7 4 2 1 1 1 2 4 3"}));
  check("a degenerate tetrahedron",
        "flat.msh",
        "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$Nodes\n4\n1 0 0 0\n2 1 0 0\n"
        "3 0 1 0\n4 1 1 0\n$EndNodes\n" +
          elements({"1 4 2 1 1 1 2 3 4"}));
  check("a repeated node",
        "repeated.msh",
        nodes + elements({"1 4 2 1 1 1 2 2 4"}));
  // Two node numbers at one point (a mesh with duplicate nodes): said as
  // such, with the point, not as a repeated node.
  check("two nodes at one point",
        "coincident.msh",
        "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$Nodes\n5\n1 0 0 0\n2 1 0 "
        "0\n3 0 1 0\n4 0 0 1\n5 1 0 0\n$EndNodes\n" +
          elements({"1 4 2 1 1 1 2 3 4", "2 4 2 1 1 2 5 3 4"}));
  // The same four nodes twice (here through node 5 at node 2's point).
  check("a duplicated tetrahedron",
        "duplicated.msh",
        "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$Nodes\n5\n1 0 0 0\n2 1 0 "
        "0\n3 0 1 0\n4 0 0 1\n5 1 0 0\n$EndNodes\n" +
          elements({"1 4 2 1 1 1 2 3 4", "2 4 2 1 1 1 5 3 4"}));
  check("an undefined node",
        "undefined.msh",
        nodes + elements({"1 4 2 1 1 1 2 3 9"}));
  check("a hexahedron",
        "hex.msh",
        nodes + elements({"1 5 2 1 1 1 2 3 4 5 1 2 3"}));
  check("a 10-node tetrahedron",
        "tet10.msh",
        nodes + elements({"1 11 2 1 1 1 2 3 4 5 1 2 3 4 5"}));
  check("a Gmsh 4 file", "v4.msh", "$MeshFormat\n4.1 0 8\n$EndMeshFormat\n");
  check("a binary Gmsh file",
        "binary.msh",
        "$MeshFormat\n2.2 1 8\n$EndMeshFormat\n");
  check("a truncated file",
        "truncated.msh",
        "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$Nodes\n5\n1 0 0 0\n2 1 0 0\n");
  check(
    "a bad coordinate",
    "coordinate.msh",
    "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$Nodes\n1\n1 0 zero 0\n$EndNodes\n");
  check("two disconnected tetrahedra",
        "pieces.msh",
        "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$Nodes\n8\n1 0 0 0\n2 1 0 0\n"
        "3 0 1 0\n4 0 0 1\n5 5 0 0\n6 6 0 0\n7 5 1 0\n8 5 0 1\n$EndNodes\n" +
          elements({"1 4 2 1 1 1 2 3 4", "2 4 2 1 1 5 6 7 8"}));
  check("a boundary triangle that is not a face",
        "triangle.msh",
        nodes + elements({"1 2 2 3 3 1 2 5", "2 4 2 1 1 1 2 3 4"}));
  check("a surface mesh only",
        "surface.msh",
        nodes + elements({"1 2 2 3 3 1 2 3"}));
  check("a legacy VTK file in binary",
        "binary.vtk",
        "# vtk DataFile Version 3.0\nx\nBINARY\n");
  check("a VTK file that is not a grid",
        "polydata.vtk",
        "# vtk DataFile Version 3.0\nx\nASCII\nDATASET POLYDATA\n");
  check("an unknown extension", "mesh.stl", "solid x\n");
  try
    {
      palpate::read_mesh_file("does-not-exist.msh");
    }
  catch (const palpate::InputError &e)
    {
      deallog << "a missing file: refused" << std::endl
              << e.what() << std::endl;
    }
}
