// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

// A HIP that leaves the grid, jumps, or carries NaN or Inf never makes the
// device render a NaN or a jump (issue 10). On the beam scene (2 mm grid,
// stiff beam): after the cloud around a point inside is computed and the
// force there has settled, the HIP jumps 1 m away (outside the state
// space: the force is held), then is NaN, then +Inf (treated as outside),
// then jumps back. Every force is finite, no call changes the force by
// more than Haptics / Maximum force change, the cause is reported right at
// each stage, and back inside the force settles to the same value.

#include <palpate/haptics/interaction.h>

#include <chrono>
#include <cmath>
#include <limits>
#include <thread>

#include "../tests.h"

int
main(int argc, char **argv)
{
  palpate::Environment env(argc, argv);
  initlog();
  using palpate::Utilities::Point3;

  palpate::Scene scene = small_beam_scene();
  auto          &p     = scene.parameters;
  p.material_model.set("St.Venant-Kirchhoff", "Young's modulus", 1e6);
  palpate::Interaction interaction(scene);
  const Point3         inside{{0.0005, -0.0003, -0.0015}};
  interaction.force(inside);
  interaction.attach();
  while (!interaction.initial_cloud_complete())
    std::this_thread::sleep_for(std::chrono::milliseconds(5));

  const double step   = p.haptics.max_force_change;
  bool         finite = true, smooth = true;
  Point3       last{{0, 0, 0}};
  const auto   call = [&](const Point3 &x) {
    const Point3 f = interaction.force(x);
    finite         = finite && all_finite(f);
    smooth =
      smooth && palpate::Utilities::distance(f, last) <= step * (1 + 1e-12);
    last = f;
    return f;
  };
  const auto settle = [&](const Point3 &x) {
    Point3 f = call(x);
    for (unsigned int i = 0; i < 100000; ++i)
      {
        const Point3 g = call(x);
        if (palpate::Utilities::distance(f, g) == 0)
          break;
        f = g;
      }
    return f;
  };
  const auto cause_name = [](const palpate::MissingCause c) {
    return c == palpate::MissingCause::none           ? "none" :
           c == palpate::MissingCause::not_computed   ? "not computed" :
           c == palpate::MissingCause::failure_region ? "failure region" :
                                                        "outside";
  };

  const Point3 f_inside = settle(inside);
  deallog << "inside: |f| = "
          << palpate::Utilities::to_string(palpate::Utilities::norm(f_inside),
                                           3)
          << " N, cause " << cause_name(interaction.missing_cause())
          << std::endl;

  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  for (const auto &[what, x] :
       std::vector<std::pair<std::string, Point3>>{{"1 m away", {{1, 1, 1}}},
                                                   {"NaN", {{nan, 0, 0}}},
                                                   {"+Inf", {{0, inf, 0}}}})
    {
      const Point3 f = settle(x);
      deallog << what << ": cause " << cause_name(interaction.missing_cause())
              << ", force finite: "
              << (std::isfinite(palpate::Utilities::norm(f)) ? "yes" : "NO")
              << std::endl;
    }
  const Point3 f_back = settle(inside);
  interaction.detach();
  deallog << "back inside: cause " << cause_name(interaction.missing_cause())
          << ", the same force: "
          << (palpate::Utilities::distance(f_back, f_inside) <=
                  1e-12 * palpate::Utilities::norm(f_inside) ?
                "yes" :
                "NO")
          << std::endl;
  deallog << "every force finite: " << (finite ? "yes" : "NO")
          << "; no change per call above " << step
          << " N: " << (smooth ? "yes" : "NO") << std::endl;
}
