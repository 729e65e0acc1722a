// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

// What the bad_input tests share: the scenes their cases start from, and
// the check each case makes: run the real program, count an internal error
// or a crash, print the exit status and the message with this machine's
// paths and memory replaced (so the .output is the same everywhere).

#ifndef palpate_tests_app_bad_input_h
#define palpate_tests_app_bad_input_h

#include <filesystem>
#include <fstream>
#include <sstream>

#include "../tests.h"

namespace bad_input
{
  inline const std::string setup =
    "subsection Run\n  set Mode = set-up only\nend\n";
  inline const std::string interaction =
    "subsection Run\n  set Mode = interaction\nend\n";
  inline const std::string beam_body =
    "subsection Mesh\n  set Source = beam\nend\n"
    "subsection Boundary conditions\n"
    "  subsection Fixed nodes\n"
    "    set Selection = boundary id\n"
    "    set Boundary ids = 0\n"
    "  end\n"
    "  subsection Active node\n"
    "    set Point = 0.1, 0, 0.01\n"
    "  end\n"
    "end\n";
  inline const std::string beam = setup + beam_body;

  inline unsigned int n_cases = 0, n_internal = 0, n_crashes = 0;

  inline void
  run(const std::string &what, const std::string &arguments)
  {
    const ProgramRun r = run_palpate(arguments);
    ++n_cases;
    n_internal += r.output.find("internal error") != std::string::npos;
    // 0 success, 2 input error, 3 not available; anything else (a signal,
    // an internal error) is a crash here.
    n_crashes += r.exit_status != 0 && r.exit_status != 2 && r.exit_status != 3;
    deallog << "=== " << what << ": exit status " << r.exit_status << std::endl;
    // Only the message: the report lines before it are tested elsewhere.
    const auto  start = r.output.find("palpate:");
    std::string message =
      start == std::string::npos ? r.output : r.output.substr(start);
    while (!message.empty() && message.back() == '\n')
      message.pop_back();
    // Where the project and this test run differ between machines: the
    // messages name absolute paths (where a missing file was looked for).
    for (const auto &[path, shown] :
         {std::make_pair(std::filesystem::current_path().string(),
                         std::string("<test directory>")),
          std::make_pair(palpate_source_dir, std::string("<source>"))})
      for (auto at = message.find(path); at != std::string::npos;
           at      = message.find(path, at))
        message.replace(at, path.size(), shown);
    // And the machine's memory.
    const std::string memory = "more than this machine's ";
    if (const auto at = message.find(memory); at != std::string::npos)
      message.replace(at + memory.size(),
                      message.find(" GiB", at) - at - memory.size(),
                      "<memory>");
    deallog << message << std::endl;
  }

  inline void
  scene(const std::string &what,
        const std::string &file,
        const std::string &text)
  {
    write_file(file, text);
    run(what, file);
  }

  /** A symbolic link @p name to @p target (to itself, to nowhere, to a
   * device), made again if an earlier run left one. */
  inline void
  make_link(const std::string &target, const std::string &name)
  {
    std::filesystem::remove(name);
    std::filesystem::create_symlink(target, name);
  }


  /** The line every bad_input test ends with. */
  inline void
  summary()
  {
    deallog << n_cases << " cases: " << n_internal
            << " with an internal error, " << n_crashes
            << " crashed (both must be 0)" << std::endl;
  }
} // namespace bad_input

using namespace bad_input;

#endif
