// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

// The palpate program. All logic lives in the library; see
// palpate::run_application() and `palpate --help`.

#include <palpate/app/application.h>
#include <palpate/base/environment.h>

#include <cstdio>
#include <iostream>

int
main(int argc, char **argv)
{
  // Standard output line by line, also into a file or a pipe: a stop signal
  // during the set-up (before a run's stop handler is installed, when the
  // signal still ends the process at once) left even the scene report that
  // was already printed unwritten in the buffer.
  std::setvbuf(stdout, nullptr, _IOLBF, 0);
  palpate::Environment environment(argc, argv);
  return palpate::run_application(argc, argv, std::cout, std::cerr);
}
