// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

// An interaction with State space / Interpolation = tricubic Hermite, as a
// haptics application runs it (issue 12). On the small beam scene (2 mm
// grid, a 4.5 mm cloud), after the cloud around rest is computed:
// - every state the engine published carries its stiffness, and the cell
//   of a point inside is interpolated by Hermite;
// - the settled force there equals the Hermite interpolation of the
//   cache, and Interaction::stiffness() equals the interpolant's -df/dx
//   by central differences (to 1e-5 of its size);
// - across the cell face x = 0 the reported stiffness is continuous (to
//   1e-3 of its size at 1 micrometre either side), and jumps less than
//   trilinear's (which jumps only as much as the field is non-linear: little
//   at 1 mm on a beam).

#include <palpate/haptics/force_interpolation.h>
#include <palpate/haptics/interaction.h>
#include <palpate/hyperelastic/state.h>
#include <palpate/state_space/state_cache.h>
#include <palpate/state_space/state_grid.h>

#include <chrono>
#include <cmath>
#include <thread>

#include "../tests.h"

int
main(int argc, char **argv)
{
  palpate::Environment env(argc, argv);
  initlog();
  using palpate::Utilities::Point3;

  palpate::Scene scene        = small_beam_scene();
  auto          &p            = scene.parameters;
  p.state_space.interpolation = "tricubic Hermite";
  p.material_model.set("St.Venant-Kirchhoff", "Young's modulus", 1e6);
  palpate::Interaction interaction(scene);
  const Point3         inside{{0.0007, -0.0003, -0.0011}};
  interaction.force(inside);
  interaction.attach();
  while (!interaction.initial_cloud_complete())
    std::this_thread::sleep_for(std::chrono::milliseconds(5));

  const auto &grid      = interaction.grid();
  const auto &cache     = interaction.cache();
  bool        all_stiff = true;
  unsigned    n         = 0;
  for (unsigned int q = 0; q < grid.size(); ++q)
    if (const auto s = cache.state(q); s)
      {
        all_stiff = all_stiff && s->has_stiffness;
        ++n;
      }
  deallog << "the engine's states carry their stiffness: " << ok(all_stiff)
          << " (" << (n > 20 ? "more than 20" : "FEW") << " states)"
          << std::endl;

  // Settle the rate-limited force at the point.
  const Point3 f      = settled_force(interaction, inside);
  const auto   sample = palpate::interpolate_hermite(grid, cache, inside);
  deallog << "cell interpolated by Hermite: " << ok(sample.hermite)
          << "; settled force = the Hermite interpolant: "
          << ok(palpate::Utilities::distance(f, sample.force) <=
                1e-12 * palpate::Utilities::norm(f))
          << std::endl;

  const auto  &K    = interaction.stiffness();
  const double e    = 1e-6;
  double       size = 0, diff = 0;
  for (const double k : K)
    size = std::max(size, std::abs(k));
  for (unsigned int j = 0; j < 3; ++j)
    {
      Point3 a = inside, b = inside;
      a[j] += e;
      b[j] -= e;
      const auto fa = palpate::interpolate_hermite(grid, cache, a);
      const auto fb = palpate::interpolate_hermite(grid, cache, b);
      for (unsigned int i = 0; i < 3; ++i)
        diff = std::max(diff,
                        std::abs(K[3 * i + j] +
                                 (fa.force[i] - fb.force[i]) / (2 * e)));
    }
  deallog << "stiffness() = -df/dx of the interpolant: "
          << ok(size > 0 && diff <= 1e-5 * size) << std::endl;

  // Across the face x = 0.
  const auto jump = [&](const palpate::InterpolateFunction interpolate) {
    const auto a = interpolate(grid, cache, {{-1e-6, -0.0003, -0.0011}});
    const auto b = interpolate(grid, cache, {{1e-6, -0.0003, -0.0011}});
    double     j = 0, s = 0;
    for (unsigned int i = 0; i < 9; ++i)
      {
        j = std::max(j, std::abs(a.stiffness[i] - b.stiffness[i]));
        s = std::max(s, std::abs(a.stiffness[i]));
      }
    return j / s;
  };
  deallog << "across a cell face the stiffness is continuous with Hermite: "
          << ok(jump(&palpate::interpolate_hermite) < 1e-3)
          << "; trilinear's jumps more: "
          << ok(jump(&palpate::interpolate_force) >=
                jump(&palpate::interpolate_hermite))
          << std::endl;
  interaction.detach();
}
