// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

// Fuzzing the surface readers (issue 26: the fuzzers cover every input
// file): the shipped liver501 surface as OBJ, and the same surface written
// here as ascii STL, binary STL and ascii PLY, mutated 400 times each
// (tests/fuzz.h, seeded). Every mutant must either give a surface with
// finite vertices and at least one triangle, or an InputError: any other
// exception, a crash or a read slower than 2 s fails the test.

#include <palpate/base/exceptions.h>
#include <palpate/mesh/surface.h>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>

#include "../tests.h"

#include "../fuzz.h"

namespace
{
  void
  write_stl_ascii(const palpate::Surface &s, const std::string &file)
  {
    std::ofstream out(file);
    out << "solid liver\n";
    for (const auto &t : s.triangles)
      {
        out << "facet normal 0 0 0\n outer loop\n";
        for (const unsigned int v : t)
          out << "  vertex " << s.vertices[v][0] << " " << s.vertices[v][1]
              << " " << s.vertices[v][2] << "\n";
        out << " endloop\nendfacet\n";
      }
    out << "endsolid liver\n";
  }

  void
  write_stl_binary(const palpate::Surface &s, const std::string &file)
  {
    std::ofstream out(file, std::ios::binary);
    char          header[80] = "palpate fuzz seed";
    out.write(header, 80);
    const std::uint32_t n = s.triangles.size();
    out.write(reinterpret_cast<const char *>(&n), 4);
    for (const auto &t : s.triangles)
      {
        float f[12] = {};
        for (unsigned int k = 0; k < 3; ++k)
          for (unsigned int d = 0; d < 3; ++d)
            f[3 + 3 * k + d] = static_cast<float>(s.vertices[t[k]][d]);
        out.write(reinterpret_cast<const char *>(f), sizeof(f));
        const std::uint16_t attribute = 0;
        out.write(reinterpret_cast<const char *>(&attribute), 2);
      }
  }

  void
  write_ply(const palpate::Surface &s, const std::string &file)
  {
    std::ofstream out(file);
    out << "ply\nformat ascii 1.0\nelement vertex " << s.vertices.size()
        << "\nproperty float x\nproperty float y\nproperty float z\n"
        << "element face " << s.triangles.size()
        << "\nproperty list uchar int vertex_indices\nend_header\n";
    for (const auto &v : s.vertices)
      out << v[0] << " " << v[1] << " " << v[2] << "\n";
    for (const auto &t : s.triangles)
      out << "3 " << t[0] << " " << t[1] << " " << t[2] << "\n";
  }
} // namespace

int
main()
{
  initlog();
  const std::string obj =
    palpate_meshes_dir + "/liver-tetgen/liver501-surface.obj";
  const palpate::Surface liver = palpate::read_surface(obj);
  write_stl_ascii(liver, "seed-ascii.stl");
  write_stl_binary(liver, "seed-binary.stl");
  write_ply(liver, "seed.ply");
  const std::vector<std::string> seeds = {obj,
                                          "seed-ascii.stl",
                                          "seed-binary.stl",
                                          "seed.ply"};

  std::mt19937       rng(20261125);
  const unsigned int per_seed    = 400;
  unsigned int       total_other = 0, total_slow = 0;
  for (const std::string &seed : seeds)
    {
      // The seed itself reads.
      const palpate::Surface s = palpate::read_surface(seed);
      deallog << std::filesystem::path(seed).filename().string() << " ("
              << s.format << "): " << s.vertices.size() << " vertices, "
              << s.triangles.size() << " triangles" << std::endl;
      const std::string text      = read_file(seed);
      const std::string extension = seed.substr(seed.rfind('.'));
      const std::string file      = "mutant" + extension;
      unsigned int      valid = 0, rejected = 0, other = 0, slow = 0;
      for (unsigned int i = 0; i < per_seed; ++i)
        {
          write_file(file, fuzz::mutate(text, rng));
          const fuzz::CpuTimer timer;
          try
            {
              const palpate::Surface m      = palpate::read_surface(file);
              bool                   finite = !m.triangles.empty();
              for (const auto &v : m.vertices)
                for (const double x : v)
                  finite = finite && std::isfinite(x);
              for (const auto &t : m.triangles)
                for (const unsigned int v : t)
                  finite = finite && v < m.vertices.size();
              if (finite)
                ++valid;
              else if (++other <= 3)
                deallog << "mutant " << i << " of " << seed
                        << ": a surface with non-finite vertices, a vertex "
                           "index out of range or no triangles"
                        << std::endl;
            }
          catch (const palpate::InputError &)
            {
              ++rejected;
            }
          catch (const std::exception &e)
            {
              if (++other <= 3)
                deallog << "mutant " << i << " of " << seed
                        << ": NOT an input error: " << e.what() << std::endl;
            }
          if (timer.seconds() > 2)
            ++slow;
        }
      deallog << "  " << valid << " valid surfaces, " << rejected
              << " input errors, " << other << " other outcomes (must be 0)"
              << std::endl;
      total_other += other, total_slow += slow;
    }
  deallog << "all " << seeds.size() * per_seed << " mutants: " << total_other
          << " other outcomes (must be 0), " << total_slow
          << " slower than 2 s (must be 0)" << std::endl;
}
