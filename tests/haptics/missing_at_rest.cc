// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

// Missing data counts from when the hand moves, not while it waits at rest
// for the motion to start. On the small beam scene with every state but
// rest a failure point (one Newton iteration allowed, an unreachable
// tolerance), the cell around rest is a failure region from the start:
// - held at rest after the initial cloud, the HIP sees that cause, yet no
//   missing-data event and no missing time is counted (the hand has felt
//   nothing and the zero force at rest is the body's);
// - moved 1 mm into that cell, the missing data is an event at once;
// - the cloud's points beyond the failed ring around rest are neither
//   computed nor failure points (no converged neighbour to start from),
//   and Interaction::initial_cloud_missing() counts them.

#include <palpate/haptics/interaction.h>
#include <palpate/state_space/state_cache.h>

#include <chrono>
#include <thread>

#include "../tests.h"

int
main(int argc, char **argv)
{
  palpate::Environment env(argc, argv);
  initlog();
  using palpate::Utilities::Point3;

  palpate::Scene scene                     = small_beam_scene();
  auto          &p                         = scene.parameters;
  p.nonlinear_solver.max_newton_iterations = 1;
  p.nonlinear_solver.residual_tolerance    = 1e-14;
  palpate::Interaction interaction(scene);
  const Point3         rest{{0, 0, 0}}, moved{{0.001, 0, 0}};
  interaction.force(rest);
  interaction.attach();
  const auto start = std::chrono::steady_clock::now();
  while (!interaction.initial_cloud_complete() &&
         std::chrono::steady_clock::now() - start < std::chrono::seconds(120))
    std::this_thread::sleep_for(std::chrono::milliseconds(5));

  const auto hold = [&](const Point3 &x) {
    for (unsigned int i = 0; i < 100; ++i)
      {
        interaction.force(x);
        std::this_thread::sleep_for(std::chrono::milliseconds(1));
      }
  };
  const auto events = [&] {
    const palpate::RunSummary s = interaction.summary();
    return s.missing_events + s.failure_region_events + s.outside_events;
  };

  hold(rest);
  const palpate::RunSummary at_rest = interaction.summary();
  deallog << "initial cloud done: "
          << (interaction.initial_cloud_complete() ? "yes" : "NO")
          << "; at rest the cause is a failure region: "
          << (interaction.missing_cause() ==
                  palpate::MissingCause::failure_region ?
                "yes" :
                "NO")
          << "; events and missing time counted at rest: "
          << (events() == 0 && at_rest.missing_seconds == 0 &&
                  at_rest.failure_region_seconds == 0 ?
                "none" :
                "SOME")
          << std::endl;

  hold(moved);
  const palpate::RunSummary after = interaction.summary();
  deallog << "moved 1 mm into the cell: an event counted: "
          << (events() >= 1 ? "yes" : "NO") << ", with missing time: "
          << (after.missing_seconds + after.failure_region_seconds > 0 ? "yes" :
                                                                         "NO")
          << std::endl;
  const auto         counts  = interaction.cache().counts();
  const unsigned int missing = interaction.initial_cloud_missing();
  deallog << "the cloud's points neither computed nor failed: "
          << (missing > 0 && missing + counts.first + counts.second ==
                               interaction.initial_cloud_size() ?
                "counted" :
                "NOT counted")
          << std::endl;
  interaction.detach();
}
