// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

// read_mesh_file(): which reader a file goes to (source/mesh/readers/, one
// per format), after the checks every mesh file passes first.

#include <palpate/base/exceptions.h>
#include <palpate/mesh/mesh_file.h>
#include <palpate/mesh/readers/gmsh_reader.h>
#include <palpate/mesh/readers/line_reader.h>
#include <palpate/mesh/readers/vtk_reader.h>
#include <palpate/mesh/readers/vtu_reader.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>
#include <system_error>
#include <vector>

namespace palpate
{
  MeshData
  read_vtp(const std::string &filename)
  {
    return mesh_readers::read_vtk_xml(filename, true);
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
      throw mesh_readers::unreadable(filename, why);
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
        throw mesh_readers::unreadable(filename, mesh_readers::system_reason());
    }
    const std::string extension =
      std::filesystem::path(filename).extension().string();
    if (extension == ".msh")
      return mesh_readers::read_gmsh(filename);
    if (extension == ".vtk")
      return mesh_readers::read_vtk(filename);
    if (extension == ".vtu")
      return mesh_readers::read_vtk_xml(filename, false);
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
