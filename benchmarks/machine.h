// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

// What a benchmark prints about the machine it ran on.

#ifndef palpate_benchmarks_machine_h
#define palpate_benchmarks_machine_h

#include <fstream>
#include <string>
#include <thread>

/** The processor model and the number of cores, e.g. "AMD EPYC, 2 cores". */
inline std::string
machine()
{
  std::ifstream cpuinfo("/proc/cpuinfo");
  std::string   line, model = "?";
  while (std::getline(cpuinfo, line))
    if (line.rfind("model name", 0) == 0)
      {
        model = line.substr(line.find(':') + 2);
        break;
      }
  return model + ", " + std::to_string(std::thread::hardware_concurrency()) +
         " cores";
}

#endif
