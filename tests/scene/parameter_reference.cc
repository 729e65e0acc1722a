// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

// doc/parameters.md is what `palpate --print-parameters markdown` prints
// today. If this fails, run `make parameters-doc` in the build directory
// and commit the result.

#include <palpate/scene/scene.h>

#include "../tests.h"

int
main(int argc, char **argv)
{
  palpate::Environment env(argc, argv);
  initlog();

  std::ostringstream generated;
  palpate::print_parameters(generated, palpate::ParameterFormat::markdown);

  std::ifstream      file(palpate_source_dir + "/doc/parameters.md");
  std::ostringstream committed;
  committed << file.rdbuf();

  if (generated.str() == committed.str())
    deallog << "doc/parameters.md is current" << std::endl;
  else
    {
      std::istringstream g(generated.str()), c(committed.str());
      std::string        gl, cl;
      unsigned int       line = 0;
      while (true)
        {
          ++line;
          const bool more_g = static_cast<bool>(std::getline(g, gl));
          const bool more_c = static_cast<bool>(std::getline(c, cl));
          if (!more_g && !more_c)
            break;
          if (gl != cl || more_g != more_c)
            break;
        }
      deallog << "doc/parameters.md is OUT OF DATE from line " << line
              << ": run 'make parameters-doc' in the build directory"
              << std::endl;
    }
}
