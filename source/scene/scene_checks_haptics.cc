// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

// The checks of what a scene renders and writes (Scene::validate()): the
// haptic loop's rate, force limit and force change, the trajectory (by its
// plug-in's own check), and the shape frames' rate and disk limit.

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
  } // namespace



  void
  Scene::check_haptics() const
  {
    check_haptic_loop(*this);
    // The trajectory checks the entries it reads (its Radius, Direction,
    // Speed, Duration or File name: TrajectoryChecks).
    Plugins::check_scene("trajectory",
                         parameters.haptics.trajectory.type,
                         *this);
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
