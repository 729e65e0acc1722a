// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

// The indenter through the engine, the cache, the haptic side and the
// state store, as a haptics application runs it. The small beam scene (a
// 2 mm grid of +-6 mm, a 4.5 mm cloud, 2 solver threads), meshed at 5 mm
// and lying clamped on its bottom face, touched by a sphere of 1 cm radius
// (Tip = sphere):
// - every state of the initial cloud converges, and each state the engine
//   computed equals a direct solve from rest to its grid point (to 1e-6 of
//   the force: the engine solves from a neighbour, the path does not
//   matter without friction);
// - at a HIP 1.1 mm into the beam the settled force is the trilinear
//   blend of its cell's corners, and pushes the probe out (+z);
// - at a HIP 3 mm above the surface, every corner is off the surface: the
//   force is exactly 0 and nothing is missing;
// - the states go into the store, and a second interaction loads them all
//   and renders the same force.

#include <palpate/haptics/force_interpolation.h>
#include <palpate/haptics/interaction.h>
#include <palpate/hyperelastic/state_solver.h>
#include <palpate/state_space/state_cache.h>
#include <palpate/state_space/state_grid.h>

#include <chrono>
#include <cmath>
#include <filesystem>
#include <thread>

#include "../tests.h"

using palpate::Utilities::Point3;

int
main(int argc, char **argv)
{
  palpate::Environment env(argc, argv);
  initlog();

  palpate::Scene scene = small_beam_scene();
  auto          &p     = scene.parameters;
  touch_beam_with_sphere(scene, 0.01);
  // Elements of 5 mm: a sphere finds the gaps between coarser nodes.
  p.mesh.beam_subdivisions_length = 20;
  p.mesh.beam_subdivisions_width  = 4;
  p.mesh.beam_subdivisions_height = 4;
  const std::string store         = "indenter.h5";
  std::filesystem::remove(store);
  p.state_space.store = store;

  const Point3 inside{{0.0007, -0.0003, -0.0011}}, above{{0.0007, 0, 0.003}};
  Point3       pressed_force;
  unsigned int computed = 0;
  {
    palpate::Interaction interaction(scene);
    interaction.force(inside);
    interaction.attach();
    wait_until([&] { return interaction.initial_cloud_complete(); },
               300,
               "the initial cloud");

    const auto          &grid  = interaction.grid();
    const auto          &cache = interaction.cache();
    palpate::StateSolver direct(interaction.mesh(), interaction.nodes(), p);
    const palpate::State rest  = direct.rest_state();
    bool                 all   = true;
    double               worst = 0, largest = 0;
    for (unsigned int q = 0; q < grid.size(); ++q)
      if (const auto s = cache.state(q); s)
        {
          ++computed;
          all                    = all && s->converged;
          const palpate::State d = direct.solve(rest, grid.position(q));
          worst =
            std::max(worst, palpate::Utilities::distance(d.force, s->force));
          largest = std::max(largest, palpate::Utilities::norm(d.force));
        }
    unsigned int failed = 0;
    for (unsigned int q = 0; q < grid.size(); ++q)
      failed += cache.status(q) == palpate::PointStatus::failed;
    deallog << "initial cloud around the HIP: "
            << (computed >= 40 ? "40 or more" : "FEW")
            << " states, no failure point: " << ok(failed == 0)
            << ", all converged: " << ok(all)
            << "; each equals a direct solve from rest: "
            << ok(largest > 0 && worst <= 1e-6 * largest) << std::endl;

    pressed_force     = settled_force(interaction, inside);
    const auto sample = palpate::interpolate_force(grid, cache, inside);
    deallog << "1.1 mm in: the force is the blend of its cell: "
            << ok(palpate::Utilities::distance(pressed_force, sample.force) <=
                  1e-12 * palpate::Utilities::norm(pressed_force))
            << ", pushes the probe out: " << ok(pressed_force[2] > 0)
            << std::endl;

    // Above the surface the cell's corners are computed on demand.
    // The probe held there (force() called, as the haptic loop does)
    // until they are.
    wait_until(
      [&] {
        interaction.force(above);
        return interaction.data_complete();
      },
      generous_deadline,
      "the cell above the surface");
    const Point3 off = settled_force(interaction, above);
    deallog << "3 mm above the surface: force exactly 0: "
            << ok(off[0] == 0 && off[1] == 0 && off[2] == 0)
            << ", nothing missing: " << ok(interaction.data_complete())
            << std::endl;
    interaction.detach();
  }

  palpate::Interaction again(scene);
  again.force(inside);
  again.attach();
  wait_until([&] { return again.initial_cloud_complete(); },
             300,
             "the second interaction's initial cloud");
  const Point3 f = settled_force(again, inside);
  deallog << "a second interaction loads the store (at least the initial "
             "cloud): "
          << ok(again.stored_points() >= computed) << "; same force: "
          << ok(palpate::Utilities::distance(f, pressed_force) <=
                1e-12 * palpate::Utilities::norm(f))
          << std::endl;
  again.detach();
  std::filesystem::remove(store);
}
