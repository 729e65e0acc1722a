// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

// The palpate program. All logic lives in the library; see
// palpate::run_application() and `palpate --help`.

#include <palpate/app/application.h>
#include <palpate/base/environment.h>

#include <iostream>

int
main(int argc, char **argv)
{
  palpate::Environment environment(argc, argv);
  return palpate::run_application(argc, argv, std::cout, std::cerr);
}
