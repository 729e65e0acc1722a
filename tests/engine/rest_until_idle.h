// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

#ifndef palpate_tests_engine_rest_until_idle_h
#define palpate_tests_engine_rest_until_idle_h

// The engine tests' drive: the HIP rests at each point of a path until the
// engine has computed the cell around it and has nothing left to do there.

#include <palpate/base/utilities.h>
#include <palpate/engine/engine.h>
#include <palpate/engine/hip_channel.h>
#include <palpate/state_space/state_cache.h>
#include <palpate/state_space/state_grid.h>

#include <chrono>
#include <vector>

#include "../wait.h"

/**
 * Start @p engine, rest the HIP at each point of @p path until the 8
 * corners of its cell are in @p cache (computed or failure points) and the
 * engine is idle, stop it. False if that did not come within 5 minutes at
 * one point.
 *
 * The corners say that the scheduler has seen the new position: idle()
 * alone may still describe the last one, and the cloud around this one
 * would then never be computed.
 */
inline bool
rest_until_idle(palpate::PrecomputationEngine                 &engine,
                palpate::HipChannel                           &hip,
                const palpate::StateGrid                      &grid,
                const palpate::StateCache                     &cache,
                const std::vector<palpate::Utilities::Point3> &path)
{
  const palpate::Utilities::Point3 zero{{0, 0, 0}};
  hip.write(path.front(), zero);
  engine.start();
  for (const auto &x : path)
    {
      hip.write(x, zero);
      palpate::GridIndex    lower;
      std::array<double, 3> local;
      if (!grid.locate(x, lower, local) ||
          !wait_until(
            [&] {
              for (const unsigned int q : grid.corners(lower))
                if (cache.status(q) == palpate::PointStatus::missing)
                  return false;
              return engine.idle();
            },
            300,
            "the engine to compute the cell around the HIP and be idle",
            std::chrono::milliseconds(10)))
        {
          engine.stop();
          return false;
        }
    }
  engine.stop();
  return true;
}

#endif
