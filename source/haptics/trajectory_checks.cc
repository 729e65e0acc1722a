// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

// The shared entries of Haptics / Trajectory, checked for the trajectories
// that read them (TrajectoryChecks, called from each plug-in's
// check_scene()).

#include <palpate/base/utilities.h>
#include <palpate/haptics/trajectory_checks.h>
#include <palpate/scene/scene.h>

namespace palpate
{
  namespace TrajectoryChecks
  {
    void
    check_radius(const Scene &scene, const double across)
    {
      const auto &p = scene.parameters;
      const auto &t = p.haptics.trajectory;
      // A circle starts at rest and goes around through the point two radii
      // away, so Radius = Extent leaves the state space (to twice it); a
      // random walk stays within Radius.
      if (across * t.radius > p.state_space.extent)
        throw scene.error(
          "Haptics/Trajectory/Radius",
          // (6 digits: with 3, 0.0501 would say "goes 0.1 m", as
          // if it fitted.)
          "a " + t.type + " of radius " + Utilities::to_string_exact(t.radius) +
            " m goes " +
            Utilities::to_string_apart(across * t.radius,
                                       p.state_space.extent,
                                       6) +
            " m from rest and leaves the state space (State space "
            "/ Extent = " +
            Utilities::to_string(p.state_space.extent, 3) +
            " m), where no force is computed",
          "give the radius in metres, e.g. 0.01, at most " +
            Utilities::to_string(p.state_space.extent / across, 3) + " m" +
            (across == 2 ? std::string(" (half the extent: a circle "
                                       "through rest reaches twice "
                                       "its radius).") :
                           std::string(" (the extent).")),
          {"State space/Extent"});
      // At least 0.1 mm: below, a smooth random motion's speed scaling
      // divides by (nearly) zero and its positions are NaN.
      if (!(t.radius >= 1e-4))
        throw scene.error(
          "Haptics/Trajectory/Radius",
          "a " + t.type +
            " needs a radius of at least 0.0001 m (0.1 mm; with 0 "
            "or less every position of the probe is undefined)",
          "give the radius in metres, e.g. 0.01.");
    }



    void
    check_direction(const Scene &scene)
    {
      const auto &d = scene.parameters.haptics.trajectory.direction;
      if (d[0] == 0 && d[1] == 0 && d[2] == 0)
        throw scene.error("Haptics/Trajectory/Direction",
                          "the direction is the zero vector",
                          "give a direction, e.g. 0, 0, -1.");
    }



    void
    check_timing(const Scene &scene)
    {
      using namespace Limits;
      const auto &t = scene.parameters.haptics.trajectory;
      // A motion of less than a hundredth of a second is no motion: with 0
      // (or 1e-300) the run would end at once with 0 N and exit 0.
      if (!(t.duration >= 0.01))
        throw scene.error(
          "Haptics/Trajectory/Duration",
          "the motion would last " + Utilities::to_string(t.duration, 3) +
            " s: at least 0.01 s (ten ticks of a 1 kHz loop) are "
            "needed for any motion",
          "give the motion's length in seconds, e.g. 2.");
      if (t.duration > max_motion_duration)
        throw scene.error(
          "Haptics/Trajectory/Duration",
          "at most " + Utilities::to_string(max_motion_duration, 4) +
            " s (one hour): the haptic loop preallocates its "
            "statistics and force log for every tick of the run, so "
            "the real-time thread never allocates",
          "split a longer session into several runs.");
      if (t.speed > max_hip_speed)
        throw scene.error(
          "Haptics/Trajectory/Speed",
          "at most " + Utilities::to_string(max_hip_speed, 3) +
            " m/s: a hand on a haptic device moves at most about "
            "2 m/s, and states for a faster probe can never be "
            "computed in time",
          "give the speed in m/s: 0.01 is 1 cm/s, a careful "
          "palpation; 0.03 m/s is fast.");
    }



    void
    check_motion_length(const Scene &scene)
    {
      using namespace Limits;
      const auto &t = scene.parameters.haptics.trajectory;
      // A motion that moves the probe less than 0.1 mm is no motion: with
      // Speed = 0 (or 1e-300) the run would hold the probe at rest, render
      // 0 N and end with exit 0, as if a motion had been rendered.
      if (!(t.speed * t.duration >= min_motion_length))
        throw scene.error("Haptics/Trajectory/Speed",
                          "at " + Utilities::to_string(t.speed, 3) +
                            " m/s for " + Utilities::to_string(t.duration, 3) +
                            " s the probe moves " +
                            Utilities::to_string(t.speed * t.duration, 3) +
                            " m: at least " +
                            Utilities::to_string(min_motion_length, 3) +
                            " m (0.1 mm) of motion are needed for the force to "
                            "change",
                          "give the speed in m/s: 0.01 is 1 cm/s, a careful "
                          "palpation.",
                          {"Haptics/Trajectory/Duration"});
    }
  } // namespace TrajectoryChecks
} // namespace palpate
