// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

// The embedding example of doc/embedding.md, compiled as it is shipped
// (doc/examples/embed.cc, its main renamed) and run on the beam scene with
// a 2 mm grid: its forces while the "device" presses 10 mm down in one
// second are compared with the saved output (4 digits), and it reports no
// missing-data event.

#include <iomanip>
#include <regex>
#include <sstream>

#include "../tests.h"

#define main embed_example_main
#include "../../doc/examples/embed.cc"
#undef main

int
main()
{
  write_file("embed.prm",
             read_file(palpate_source_dir + "/parameters/beam.prm") + R"(
subsection State space
  set Grid spacing = 0.002
  set Extent       = 0.014
end
subsection Scheduler
  set Cloud radius = 0.005
end
subsection Engine
  set Workers = 2
end
)");

  // Run the example with its standard output captured.
  std::ostringstream captured;
  std::streambuf    *saved  = std::cout.rdbuf(captured.rdbuf());
  int                argc   = 2;
  char               name[] = "embed", file[] = "embed.prm";
  char              *argv[] = {name, file, nullptr};
  char             **args   = argv;
  const int          status = embed_example_main(argc, args);
  std::cout.rdbuf(saved);

  initlog();
  deallog << "exit status " << status << std::endl;
  const std::regex force(
    R"(t = ([0-9.]+) s, force \(([^,]+), ([^,]+), ([^)]+)\) N)");
  std::istringstream lines(captured.str());
  std::string        line;
  while (std::getline(lines, line))
    {
      std::smatch m;
      if (std::regex_match(line, m, force))
        {
          deallog << "t = " << m[1] << " s, force";
          for (unsigned int k = 2; k <= 4; ++k)
            deallog << " " << std::setprecision(4) << std::stod(m[k]);
          deallog << " N" << std::endl;
        }
      else
        deallog << line << std::endl;
    }
}
