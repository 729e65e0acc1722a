// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

// For benchmarks that measure the MPI engine: a benchmark re-runs itself
// under mpirun as a "child" for one configuration (rank 0 runs the
// interaction, the other ranks are solver servers) and reads back one line
//   CHILD key=value key=value ...
// from its output. A configuration with the threaded engine runs as a
// child too, without mpirun, so that every configuration starts from a
// fresh process.

#ifndef palpate_benchmarks_mpi_child_h
#define palpate_benchmarks_mpi_child_h

#include <unistd.h>

#include <array>
#include <cstdio>
#include <cstdlib>
#include <map>
#include <sstream>
#include <stdexcept>
#include <string>

extern char **environ;

namespace mpi_child
{
  /** This program's path. */
  inline std::string
  self()
  {
    std::array<char, 4096> path{};
    const ssize_t          n = readlink("/proc/self/exe", path.data(), 4095);
    if (n <= 0)
      throw std::runtime_error("cannot find this program's path");
    return std::string(path.data(), n);
  }

  /**
   * The command that runs this program with @p arguments: under mpirun
   * with @p ranks processes (more than the cores allowed, as root if we
   * are root), or alone if @p ranks is 0.
   */
  inline std::string
  command(const unsigned int ranks, const std::string &arguments)
  {
    std::string c;
    if (ranks > 0)
      c = "mpirun --oversubscribe" +
          std::string(geteuid() == 0 ? " --allow-run-as-root" : "") + " -np " +
          std::to_string(ranks) + " ";
    return c + self() + " " + arguments + " 2>&1";
  }

  /**
   * Remove the variables that an MPI library set in this process's
   * environment, so that a child process (or its mpirun) starts a job of
   * its own.
   */
  inline void
  clean_environment()
  {
    for (bool removed = true; removed;)
      {
        removed = false;
        for (char **e = environ; *e != nullptr; ++e)
          {
            const std::string v(*e);
            const std::string name = v.substr(0, v.find('='));
            if ((name.rfind("OMPI_", 0) == 0 || name.rfind("PMIX_", 0) == 0) &&
                name.rfind("OMPI_ALLOW_RUN_AS_ROOT", 0) != 0)
              {
                unsetenv(name.c_str());
                removed = true;
                break;
              }
          }
      }
  }

  /**
   * Run @p command and return the key=value pairs of its CHILD line;
   * throws with the whole output if there is none. The environment is
   * cleaned first (clean_environment()).
   */
  inline std::map<std::string, std::string>
  run(const std::string &command)
  {
    clean_environment();
    FILE *pipe = popen(command.c_str(), "r");
    if (pipe == nullptr)
      throw std::runtime_error("cannot run " + command);
    std::string            output;
    std::array<char, 4096> buffer;
    std::size_t            n;
    while ((n = fread(buffer.data(), 1, buffer.size(), pipe)) > 0)
      output.append(buffer.data(), n);
    pclose(pipe);

    std::istringstream lines(output);
    std::string        line;
    while (std::getline(lines, line))
      if (line.rfind("CHILD ", 0) == 0)
        {
          std::map<std::string, std::string> values;
          std::istringstream                 words(line.substr(6));
          std::string                        word;
          while (words >> word)
            if (const auto eq = word.find('='); eq != std::string::npos)
              values[word.substr(0, eq)] = word.substr(eq + 1);
          return values;
        }
    throw std::runtime_error("the run\n  " + command +
                             "\nprinted no result:\n" + output);
  }
} // namespace mpi_child

#endif
