// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

// Haptics / Trajectory / Type = circle: through the rest position, of Radius,
// in the plane normal to Direction, at Speed for Duration.

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
    class CircleTrajectory : public SharedTrajectoryEntries
    {
    public:
      static std::unique_ptr<Trajectory>
      create(const dealii::ParameterHandler &, const Scene &scene)
      {
        const auto &t = scene.parameters.haptics.trajectory;
        return std::make_unique<Circle>(t.direction,
                                        t.radius,
                                        t.speed,
                                        t.duration);
      }

      static void
      check_scene(const Scene &scene)
      {
        // Through rest and around: the circle reaches two radii from it.
        TrajectoryChecks::check_radius(scene, 2);
        TrajectoryChecks::check_direction(scene);
        TrajectoryChecks::check_timing(scene);
        TrajectoryChecks::check_motion_length(scene);
      }
    };
  } // namespace

  PALPATE_REGISTER_TRAJECTORY(
    CircleTrajectory,
    "circle",
    "a circle of Radius through the rest position, in the plane normal "
    "to Direction")
} // namespace palpate
