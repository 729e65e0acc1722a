// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

// The embedding API on the beam scene (2 mm grid, 4.5 mm cloud, 2 solver
// threads), and on-the-fly parameter changes:
// - after attach() the initial cloud around the HIP (where force() last
//   saw it, before attaching) is computed, and the force at a point
//   of a cell is the trilinear interpolation of independently computed
//   states at its corners (relative difference < 1e-6: different staging
//   paths, Newton tolerance 1e-8);
// - force() ramps to it at the scene's maximum change per call, and fades
//   to zero at the same rate after detach();
// - parameters cannot change while attached, and what the grid and engine
//   were built for cannot change at all; bad parameters leave the
//   interaction as it was;
// - doubling Young's modulus invalidates the cache: nothing is available,
//   and while the new cloud is computed no interpolation ever sees a state
//   of the old material (StVK with displacement control: the new forces are
//   exactly twice the old ones, to solver tolerance);
// - moving the active node invalidates the cache too, and the new states
//   are those of the new active node.

#include <palpate/engine/hip_channel.h>
#include <palpate/haptics/force_interpolation.h>
#include <palpate/haptics/interaction.h>
#include <palpate/hyperelastic/state_solver.h>
#include <palpate/state_space/state_cache.h>
#include <palpate/state_space/state_grid.h>

#include <chrono>
#include <cmath>
#include <thread>

#include "../tests.h"

namespace
{
  using palpate::Utilities::Point3;

  /** Wait (at most 5 minutes) for the cloud around the attach position. */
  bool
  wait_for_cloud(palpate::Interaction &interaction)
  {
    return wait_until([&] { return interaction.initial_cloud_complete(); },
                      300,
                      "the initial cloud");
  }

  /** The trilinear interpolation at @p x of states computed directly from
   * rest, with the interaction's current mesh, nodes and parameters. */
  Point3
  direct_force(const palpate::Interaction &interaction, const Point3 &x)
  {
    palpate::StateSolver  solver(interaction.mesh(),
                                interaction.nodes(),
                                interaction.scene().parameters);
    palpate::GridIndex    cell;
    std::array<double, 3> local;
    interaction.grid().locate(x, cell, local);
    const auto corners = interaction.grid().corners(cell);
    const auto weights = palpate::trilinear_weights(local);
    Point3     f{{0, 0, 0}};
    for (unsigned int c = 0; c < 8; ++c)
      {
        const palpate::State s =
          solver.solve(solver.rest_state(),
                       interaction.grid().position(corners[c]));
        for (unsigned int d = 0; d < 3; ++d)
          f[d] += weights[c] * s.force[d];
      }
    return f;
  }

  double
  relative_difference(const Point3 &a, const Point3 &b)
  {
    return palpate::Utilities::distance(a, b) / palpate::Utilities::norm(b);
  }

  /** Call force(x) until the output stops changing; the number of calls. */
  unsigned int
  settle(palpate::Interaction &interaction, const Point3 &x, Point3 &f)
  {
    f = interaction.force(x);
    for (unsigned int calls = 1; calls < 100000; ++calls)
      {
        const Point3 g = interaction.force(x);
        if (palpate::Utilities::distance(f, g) == 0)
          return calls;
        f = g;
      }
    return 100000;
  }
} // namespace

int
main(int argc, char **argv)
{
  palpate::Environment env(argc, argv);
  initlog();

  palpate::Scene scene       = small_beam_scene();
  auto          &p           = scene.parameters;
  p.haptics.force_limit      = 10;
  p.haptics.max_force_change = 1e-3;
  p.material_model.set("St.Venant-Kirchhoff", "Young's modulus", 1e6);
  palpate::Interaction interaction(scene);
  const Point3         x{{0.0012, -0.0007, -0.0015}};
  deallog << "grid of " << interaction.grid().size() << " points; HIP at ("
          << palpate::Utilities::to_string(x, 3) << ") m" << std::endl;

  // Before attaching: nothing computed, no force.
  deallog << "before attach: force ("
          << palpate::Utilities::to_string(interaction.force(x), 3)
          << ") N, complete " << interaction.data_complete() << std::endl;

  interaction.attach();
  deallog << "initial cloud computed: "
          << (wait_for_cloud(interaction) ? "yes" : "NO")
          << ", cache: " << interaction.cache().counts().first << " available, "
          << interaction.cache().counts().second << " failed" << std::endl;
  const auto sample =
    palpate::interpolate_force(interaction.grid(), interaction.cache(), x);
  const Point3 f_old    = sample.force;
  const Point3 expected = direct_force(interaction, x);
  deallog << "interpolated force (" << palpate::Utilities::to_string(f_old, 5)
          << ") N, complete " << sample.complete
          << "; from direct solves at the corners: "
          << (relative_difference(f_old, expected) < 1e-6 ? "same" :
                                                            "DIFFERENT")
          << std::endl;

  Point3             f;
  const unsigned int ramp = settle(interaction, x, f);
  deallog << "force(): reaches it after " << ramp << " calls (|f| / 1e-3 N = "
          << static_cast<unsigned int>(
               std::ceil(palpate::Utilities::norm(f_old) / 1e-3))
          << "), equal: "
          << (palpate::Utilities::distance(f, f_old) < 1e-12 ? "yes" : "NO")
          << ", complete " << interaction.data_complete() << std::endl;

  // No change while in contact.
  palpate::Parameters::AllParameters changed = p;
  changed.material_model.set(
    "St.Venant-Kirchhoff",
    "Young's modulus",
    2 * p.material_model.get_double("St.Venant-Kirchhoff", "Young's modulus"));
  try
    {
      interaction.change_parameters(changed);
      deallog << "change while attached: accepted (WRONG)" << std::endl;
    }
  catch (const std::logic_error &e)
    {
      deallog << "change while attached: refused" << std::endl;
    }

  interaction.detach();
  const unsigned int fade = settle(interaction, x, f);
  deallog << "after detach: force fades to ("
          << palpate::Utilities::to_string(f, 3) << ") N in " << fade
          << " calls, complete " << interaction.data_complete() << std::endl;

  // What cannot change, and bad parameters.
  palpate::Parameters::AllParameters other_grid = changed;
  other_grid.state_space.grid_spacing           = 0.001;
  try
    {
      interaction.change_parameters(other_grid);
    }
  catch (const std::invalid_argument &e)
    {
      deallog << "grid change refused: " << e.what() << std::endl;
    }
  // Every Mesh entry counts, the surface mesher's too (it was compared
  // field by field, without them: the change was accepted and ignored).
  palpate::Parameters::AllParameters other_surface = changed;
  other_surface.mesh.surface_target_nodes += 1000;
  try
    {
      interaction.change_parameters(other_surface);
      deallog << "surface setting change ACCEPTED" << std::endl;
    }
  catch (const std::invalid_argument &e)
    {
      deallog << "surface setting change refused: "
              << (std::string(e.what()).find("'Mesh'") != std::string::npos ?
                    "names Mesh" :
                    "DOES NOT NAME Mesh")
              << std::endl;
    }
  // The interpolation decides what each state keeps: another one would
  // leave the haptic loop reading what the solvers no longer compute.
  palpate::Parameters::AllParameters other_interpolation = changed;
  other_interpolation.state_space.interpolation          = "tricubic Hermite";
  try
    {
      interaction.change_parameters(other_interpolation);
      deallog << "interpolation change ACCEPTED" << std::endl;
    }
  catch (const std::invalid_argument &e)
    {
      deallog << "interpolation change refused: "
              << (std::string(e.what()).find("'State space'") !=
                      std::string::npos ?
                    "names State space" :
                    "DOES NOT NAME State space")
              << std::endl;
    }
  palpate::Parameters::AllParameters no_fixed_nodes           = changed;
  no_fixed_nodes.boundary_conditions.fixed_nodes.boundary_ids = {7};
  try
    {
      interaction.change_parameters(no_fixed_nodes);
    }
  catch (const palpate::InputError &e)
    {
      deallog
        << "a fixed-node selection that selects nothing refused (InputError); cache still "
        << interaction.cache().counts().first << " available" << std::endl;
    }

  // Young's modulus doubled.
  interaction.change_parameters(changed);
  deallog << "E doubled: cache " << interaction.cache().counts().first
          << " available, " << interaction.cache().counts().second
          << " failed; interpolation complete "
          << palpate::interpolate_force(interaction.grid(),
                                        interaction.cache(),
                                        x)
               .complete
          << std::endl;
  interaction.attach();
  // Read as the haptic side would (every 0.1 ms) until the cloud is there.
  unsigned int complete_reads = 0, stale_reads = 0;
  wait_until(
    [&] {
      const auto s =
        palpate::interpolate_force(interaction.grid(), interaction.cache(), x);
      if (s.complete)
        {
          ++complete_reads;
          Point3 twice = f_old;
          for (double &c : twice)
            c *= 2;
          stale_reads += relative_difference(s.force, twice) > 1e-6;
        }
      return interaction.initial_cloud_complete();
    },
    300,
    "the cloud at the doubled modulus",
    std::chrono::microseconds(100));
  const Point3 f_new =
    palpate::interpolate_force(interaction.grid(), interaction.cache(), x)
      .force;
  deallog << "while recomputing: " << (complete_reads > 0 ? "some" : "no")
          << " complete reads, of which " << stale_reads << " stale"
          << std::endl;
  deallog << "new force / old force: " << f_new[0] / f_old[0] << ", "
          << f_new[1] / f_old[1] << ", " << f_new[2] / f_old[2] << std::endl;

  // The active node moves to the bottom corner of the free end.
  interaction.detach();
  palpate::Parameters::AllParameters moved    = changed;
  moved.boundary_conditions.active_node.point = {{0.1, 0, -0.01}};
  const unsigned int old_active_node = interaction.nodes().active_vertex;
  interaction.change_parameters(moved);
  deallog << "active node " << old_active_node << " -> "
          << interaction.nodes().active_vertex << ": cache "
          << interaction.cache().counts().first << " available" << std::endl;
  interaction.attach();
  deallog << "cloud recomputed: "
          << (wait_for_cloud(interaction) ? "yes" : "NO") << std::endl;
  const Point3 f_moved =
    palpate::interpolate_force(interaction.grid(), interaction.cache(), x)
      .force;
  deallog << "force (" << palpate::Utilities::to_string(f_moved, 5)
          << ") N; from direct solves with the new active node: "
          << (relative_difference(f_moved, direct_force(interaction, x)) <
                  1e-6 ?
                "same" :
                "DIFFERENT")
          << std::endl;
  interaction.detach();

  const palpate::RunSummary summary = interaction.summary();
  deallog << "summary: non-finite forces " << summary.non_finite_forces
          << ", largest change per call " << summary.largest_force_change
          << " N" << std::endl;
}
