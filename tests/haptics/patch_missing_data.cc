// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

// Missing data with Interpolation = contact patch (issue 45): the last
// complete cell's patches keep answering. The beam touched by a 1 cm
// sphere, a 2 mm grid of +-6 mm; the HIP pressed 1.1 mm in slides along
// +x out of the state space (its edge at 6 mm) to 7.5 mm, then rises to
// 3 mm above the surface there:
// - beyond the edge the force is the tissue's: within 3.5 % of a direct
//   solve at 7.5 mm, as between states (2.7 %; the spring ForceHold
//   holds, from the last cell's force and stiffness, is 6 % off there);
// - the force changes continuously across the edge (no jump beyond the
//   filter's own limit);
// - lifted off the surface outside the grid, the force is exactly 0;
// - the time outside is still reported, as an outside event, and the
//   summary says how far beyond the last complete cell the patches
//   answered (the 1.5 mm from the edge; not the lift off the surface,
//   where they answer zero).

#include <palpate/haptics/interaction.h>
#include <palpate/hyperelastic/state_solver.h>

#include <chrono>
#include <cmath>
#include <thread>

#include "../tests.h"

using palpate::Utilities::Point3;

namespace
{
  /** The force at @p x once the HIP's cell is complete (or it is outside
   * the grid) and the force has settled. */
  Point3
  force_at(palpate::Interaction &interaction, const Point3 &x)
  {
    wait_until(
      [&] {
        interaction.force(x);
        return interaction.data_complete() ||
               interaction.missing_cause() == palpate::MissingCause::outside;
      },
      generous_deadline,
      "the HIP's cell (or the HIP outside the grid)",
      std::chrono::milliseconds(2));
    return settled_force(interaction, x);
  }
} // namespace

int
main(int argc, char **argv)
{
  palpate::Environment env(argc, argv);
  initlog();

  palpate::Scene scene = small_beam_scene();
  touch_beam_with_sphere(scene, 0.01);
  beam_with_contact_patches(scene);
  auto &p = scene.parameters;

  const double         depth = -0.0011, edge = 0.006, beyond = 0.0075;
  palpate::Interaction interaction(scene);
  interaction.force({{0.0007, 0, depth}});
  interaction.attach();
  wait_until([&] { return interaction.initial_cloud_complete(); },
             300,
             "the initial cloud");

  // Along +x in steps of 0.1 mm, each step's cell computed first.
  double largest_step = 0;
  Point3 last         = force_at(interaction, {{0.0007, 0, depth}});
  Point3 at_edge      = last;
  for (double x = 0.0008; x <= beyond + 1e-9; x += 0.0001)
    {
      const Point3 f = force_at(interaction, {{x, 0, depth}});
      largest_step =
        std::max(largest_step, palpate::Utilities::distance(f, last));
      last = f;
      if (std::abs(x - edge) < 5e-5)
        at_edge = f;
    }
  const bool outside =
    interaction.missing_cause() == palpate::MissingCause::outside;

  palpate::StateSolver direct(interaction.mesh(), interaction.nodes(), p);
  const palpate::State there =
    direct.solve(direct.rest_state(), {{beyond, 0, depth}});
  const double error = palpate::Utilities::distance(last, there.force) /
                       palpate::Utilities::norm(there.force);
  deallog << "7.5 mm along, 1.5 mm outside the grid: outside " << ok(outside)
          << ", the force is the tissue's (a direct solve "
          << "there) within 3.5 %: " << ok(there.converged && error < 0.035)
          << ", it differs from the force at the edge: "
          << ok(palpate::Utilities::distance(last, at_edge) >
                0.02 * palpate::Utilities::norm(at_edge))
          << std::endl;
  if (!(error < 0.035))
    deallog << "  (rendered " << palpate::Utilities::to_string(last, 4)
            << " N, direct " << palpate::Utilities::to_string(there.force, 4)
            << " N)" << std::endl;
  // 0.1 mm steps of a stiffness of a few hundred N/m: mN apart.
  deallog << "continuous across the edge: the largest change between "
             "0.1 mm steps is below 5 mN: "
          << ok(largest_step < 0.005) << std::endl;

  const Point3 above = force_at(interaction, {{beyond, 0, 0.003}});
  deallog << "3 mm above the surface outside the grid: exactly 0: "
          << ok(above[0] == 0 && above[1] == 0 && above[2] == 0) << std::endl;
  interaction.detach();
  const auto summary = interaction.summary();
  deallog << "the time outside is reported as an outside event: "
          << ok(summary.outside_events >= 1 && summary.outside_seconds > 0)
          << "; the patches answered up to 1-2 mm from where the data were "
             "last complete: "
          << ok(summary.patched_farthest > 0.001 &&
                summary.patched_farthest < 0.002)
          << std::endl;
}
