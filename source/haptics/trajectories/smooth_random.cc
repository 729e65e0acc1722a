// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

// Haptics / Trajectory / Type = smooth random: a seeded random walk within
// Radius of the rest position, of root-mean-square Speed, for Duration.

#include <palpate/base/plugins.h>
#include <palpate/haptics/trajectory.h>
#include <palpate/haptics/trajectory_checks.h>
#include <palpate/scene/scene.h>

#include <deal.II/base/parameter_handler.h>

namespace palpate
{
  namespace
  {
    /** The plug-in: it reads only the shared entries. */
    class SmoothRandomTrajectory : public SharedTrajectoryEntries
    {
    public:
      static std::unique_ptr<Trajectory>
      create(const dealii::ParameterHandler &, const Scene &scene)
      {
        const auto &t = scene.parameters.haptics.trajectory;
        return std::make_unique<SmoothRandom>(t.radius,
                                              t.speed,
                                              t.duration,
                                              t.seed);
      }

      static void
      check_scene(const Scene &scene)
      {
        TrajectoryChecks::check_radius(scene, 1);
        TrajectoryChecks::check_timing(scene);
        TrajectoryChecks::check_motion_length(scene);
      }
    };
  } // namespace

  PALPATE_REGISTER_TRAJECTORY(
    SmoothRandomTrajectory,
    "smooth random",
    "a smooth random walk within Radius, of root-mean-square Speed, from Seed")
} // namespace palpate
