// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

// Fuzzing the mesh readers: a small beam written in every format palpate
// reads (Gmsh 2.2 and 1, legacy VTK classic and 5.1, VTU ascii, base64,
// base64+zlib and appended raw) and the shared liver501 (.msh, .vtk),
// mutated 600 times each (seeded: the counts below are the same on every
// run): bytes flipped, ranges deleted or repeated, lines dropped or
// duplicated, numbers replaced by nasty ones (nan, inf, 1e308, -1, huge
// counts), files truncated. Every mutant must either give a valid mesh
// (positive, finite volume) or an InputError: any other exception, a crash
// or a read slower than 2 s fails the test.

#include <palpate/mesh/generators.h>
#include <palpate/mesh/mesh.h>
#include <palpate/scene/scene.h>

#include <cmath>
#include <filesystem>
#include <random>

#include "../tests.h"

#include "../fuzz.h"
#include "../mesh_writers.h"


int
main(int argc, char **argv)
{
  palpate::Environment env(argc, argv);
  initlog();

  const palpate::MeshData  beam  = small_beam();
  std::vector<std::string> seeds = write_every_format(beam);
  seeds.push_back(palpate_meshes_dir + "/liver-tetgen/liver501.msh");
  seeds.push_back(palpate_meshes_dir + "/liver-tetgen/liver501.vtk");

  std::mt19937       rng(20261123);
  const unsigned int per_seed    = 600;
  unsigned int       total_valid = 0, total_rejected = 0, total_other = 0,
               total_slow = 0;
  for (const std::string &seed : seeds)
    {
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
              const palpate::Mesh mesh(palpate::read_mesh_file(file),
                                       1.0,
                                       file);
              if (std::isfinite(mesh.volume()) && mesh.volume() > 0 &&
                  mesh.n_cells() > 0)
                ++valid;
              else
                {
                  ++other;
                  deallog << "mutant " << i << " of " << seed
                          << ": a mesh of volume " << mesh.volume() << " and "
                          << mesh.n_cells() << " cells" << std::endl;
                }
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
      deallog << std::filesystem::path(seed).filename().string() << ": "
              << valid << " valid meshes, " << rejected << " input errors, "
              << other << " other outcomes (must be 0)" << std::endl;
      total_valid += valid, total_rejected += rejected, total_other += other,
        total_slow += slow;
    }
  deallog << "all " << seeds.size() * per_seed << " mutants: " << total_valid
          << " valid, " << total_rejected << " input errors, " << total_other
          << " other outcomes (must be 0), " << total_slow
          << " slower than 2 s (must be 0)" << std::endl;
}
