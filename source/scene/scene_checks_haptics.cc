// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

// The checks of what a scene renders and writes (Scene::validate()): the
// haptic loop's rate, force limit and force change, the trajectory's radius,
// direction, duration and speed, and the shape frames' rate and disk limit.

#include <palpate/scene/scene_impl.h>

namespace palpate
{
  namespace
  {
    // Scene::check_haptics(), first step: the haptic loop's rate, force limit
    // and force change, the device's side of the run.
    void
    check_haptic_loop(const Scene &scene)
    {
      using namespace Limits;
      const auto &p = scene.parameters;

      // Haptics.
      const auto &h = p.haptics;
      if (h.loop_rate <= 0)
        throw scene.error("Haptics/Loop rate",
                          "the rate must be positive",
                          "use 1000 Hz.");
      if (h.loop_rate < min_loop_rate)
        throw scene.error(
          "Haptics/Loop rate",
          "at least " + Utilities::to_string(min_loop_rate, 3) +
            " Hz: a haptic loop renders forces at hundreds to "
            "thousands of ticks per second, and a run waits for "
            "its ticks",
          "use 1000 Hz.");
      if (!(h.force_limit >= min_force_limit))
        throw scene.error(
          "Haptics/Force limit",
          "at least " + Utilities::to_string(min_force_limit, 3) +
            " N: below, the device renders (nearly) no force at all "
            "(haptic devices reach 1-40 N)",
          "set the device's peak force in N, e.g. 8.");
      // The limit is the device's safety: 1e308 N would remove it. No
      // haptic device renders a kilonewton.
      if (h.force_limit > 1000)
        throw scene.error("Haptics/Force limit",
                          "at most 1000 N: the limit protects the hand and the "
                          "device, and haptic devices reach 1-40 N",
                          "set the device's peak force in N, e.g. 8.");
      if (h.max_force_change > h.force_limit)
        throw scene.error(
          "Haptics/Maximum force change",
          "at most the force limit (" + Utilities::to_string(h.force_limit, 4) +
            " N) per tick: a larger change is a jump the filter "
            "would never limit",
          "use e.g. 0.05 N.");
      if (!(h.max_force_change >= min_force_change))
        throw scene.error(
          "Haptics/Maximum force change",
          "at least " + Utilities::to_string(min_force_change, 3) +
            " N per tick: below, a force of 1 N takes more than 10 s "
            "to arrive at 1 kHz, and the hand feels nothing",
          "use e.g. 0.05 N.");
      if (h.loop_rate > max_loop_rate)
        throw scene.error(
          "Haptics/Loop rate",
          "at most " + Utilities::to_string(max_loop_rate, 5) +
            " Hz: haptic devices run at 1 kHz, the fastest at 10 kHz, "
            "and the loop preallocates its statistics for every tick",
          "use 1000 Hz.");
    }



    // Scene::check_haptics(), second step: the trajectory's radius, direction,
    // duration and speed, the hand's side of the run.
    void
    check_trajectory(const Scene &scene)
    {
      using namespace Limits;
      const auto &p = scene.parameters;
      const auto &t = p.haptics.trajectory;
      // At least 0.1 mm: below, a smooth random motion's speed scaling
      // divides by (nearly) zero and its positions are NaN.
      // A circle starts at rest and goes around through the point two radii
      // away, so Radius = Extent leaves the state space (to twice it); a
      // random walk stays within Radius.
      const double across = t.type == "circle" ? 2 : 1;
      if ((t.type == "circle" || t.type == "smooth random") &&
          across * t.radius > p.state_space.extent)
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
      if ((t.type == "circle" || t.type == "smooth random") &&
          !(t.radius >= 1e-4))
        throw scene.error(
          "Haptics/Trajectory/Radius",
          "a " + t.type +
            " needs a radius of at least 0.0001 m (0.1 mm; with 0 "
            "or less every position of the probe is undefined)",
          "give the radius in metres, e.g. 0.01.");
      if ((t.type == "straight line" || t.type == "circle") &&
          t.direction[0] == 0 && t.direction[1] == 0 && t.direction[2] == 0)
        throw scene.error("Haptics/Trajectory/Direction",
                          "the direction is the zero vector",
                          "give a direction, e.g. 0, 0, -1.");
      // A motion of less than a hundredth of a second is no motion: with 0
      // (or 1e-300) the run ended at once with 0 N and exit 0.
      if (t.type != "replay" && !(t.duration >= 0.01))
        throw scene.error(
          "Haptics/Trajectory/Duration",
          "the motion would last " + Utilities::to_string(t.duration, 3) +
            " s: at least 0.01 s (ten ticks of a 1 kHz loop) are "
            "needed for any motion",
          "give the motion's length in seconds, e.g. 2.");
      if (t.type != "replay" && t.duration > max_motion_duration)
        throw scene.error(
          "Haptics/Trajectory/Duration",
          "at most " + Utilities::to_string(max_motion_duration, 4) +
            " s (one hour): the haptic loop preallocates its "
            "statistics and force log for every tick of the run, so "
            "the real-time thread never allocates",
          "split a longer session into several runs.");
      if (t.type != "replay" && t.speed > max_hip_speed)
        throw scene.error(
          "Haptics/Trajectory/Speed",
          "at most " + Utilities::to_string(max_hip_speed, 3) +
            " m/s: a hand on a haptic device moves at most about "
            "2 m/s, and states for a faster probe can never be "
            "computed in time",
          "give the speed in m/s: 0.01 is 1 cm/s, a careful "
          "palpation; 0.03 m/s is fast.");
      // A motion that moves the probe less than 0.1 mm is no motion: with
      // Speed = 0 (or 1e-300) the run would hold the probe at rest, render
      // 0 N and end with exit 0, as if a motion had been rendered.
      if ((t.type == "straight line" || t.type == "circle" ||
           t.type == "smooth random") &&
          !(t.speed * t.duration >= min_motion_length))
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
      if (t.type == "replay" && t.file_name.empty())
        throw scene.error("Haptics/Trajectory/File name",
                          "Type = replay, but no CSV file is named",
                          "name a CSV file with columns t, x, y, z.");
    }
  } // namespace



  void
  Scene::check_haptics() const
  {
    check_haptic_loop(*this);
    check_trajectory(*this);
  }



  void
  Scene::check_shape_output() const
  {
    using namespace Limits;
    const auto &p = parameters;
    if (p.effects.shape_output && p.effects.shape_output_rate <= 0)
      throw error("Effects/Shape output rate",
                  "the rate must be positive",
                  "use 30 Hz.");
    if (p.effects.shape_output &&
        p.effects.shape_output_limit > max_memory_budget)
      throw error("Effects/Shape output limit",
                  "at most " + Utilities::to_string(max_memory_budget, 7) +
                    " MiB (1 TiB): more than any disk palpate writes to, "
                    "and beyond it the byte count overflows (frames were "
                    "left out as if over the limit)",
                  "give the most disk space the frames may take in MiB, "
                  "e.g. 1000.");
    // Below one megabyte not even a dozen frames of a small liver fit:
    // with 0 the run would write no frame and say nothing was wrong.
    if (p.effects.shape_output &&
        !(p.effects.shape_output_limit >= min_shape_output_limit))
      throw error("Effects/Shape output limit",
                  "at least " +
                    Utilities::to_string(min_shape_output_limit, 3) +
                    " MiB: a frame of a 500-node liver is about 85 KiB, so "
                    "a smaller limit writes no frame",
                  "give the most disk space the frames may take in MiB, "
                  "e.g. 1000; to write no frames, set Shape output = false.");
    if (p.effects.shape_output && p.effects.shape_output_rate < 1.0 / 3600)
      throw error("Effects/Shape output rate",
                  "at least one frame an hour (" +
                    Utilities::to_string(1.0 / 3600, 3) +
                    " Hz): a motion lasts at most an hour, so a slower "
                    "rate writes no frame",
                  "use 30 Hz.");
    if (p.effects.shape_output &&
        p.effects.shape_output_rate > max_shape_output_rate)
      throw error("Effects/Shape output rate",
                  "at most " + Utilities::to_string(max_shape_output_rate, 3) +
                    " Hz: each frame is a VTU file of the whole mesh, and a "
                    "screen shows at most 240 frames a second",
                  "use 30 Hz.");
  }
} // namespace palpate
