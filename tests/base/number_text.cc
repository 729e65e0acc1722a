// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

// Numbers as the messages and summaries write them
// (Utilities::to_string): six significant digits by default, a point as
// three numbers, and a zero is "0" whatever its sign (a HIP at rest along
// an axis was written "-0").

#include <palpate/base/utilities.h>

#include <cmath>

#include "../tests.h"

int
main(int argc, char **argv)
{
  palpate::Environment env(argc, argv);
  initlog();
  using palpate::Utilities::to_string;

  const double negative_zero = std::copysign(0.0, -1.0);
  deallog << "-0 written as: " << to_string(negative_zero) << std::endl;
  deallog << "a point with -0: "
          << to_string(palpate::Utilities::Point3{{negative_zero, 1.5, -2e-5}})
          << std::endl;
  deallog << "pi: " << to_string(M_PI)
          << ", to 3 digits: " << to_string(M_PI, 3)
          << ", -pi: " << to_string(-M_PI) << std::endl;
}
