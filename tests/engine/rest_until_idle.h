// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

#ifndef palpate_tests_engine_rest_until_idle_h
#define palpate_tests_engine_rest_until_idle_h

// The engine tests' drive: the HIP rests at each point of a path until the
// engine has nothing left to do there.

#include <palpate/base/utilities.h>
#include <palpate/engine/engine.h>
#include <palpate/engine/hip_channel.h>

#include <chrono>
#include <thread>
#include <vector>

/** Start @p engine, rest the HIP at each point of @p path until the engine
 * is idle, stop it. False if it was still busy after 5 minutes at one
 * point. */
inline bool
rest_until_idle(palpate::PrecomputationEngine                 &engine,
                palpate::HipChannel                           &hip,
                const std::vector<palpate::Utilities::Point3> &path)
{
  using Clock = std::chrono::steady_clock;
  const palpate::Utilities::Point3 zero{{0, 0, 0}};
  hip.write(path.front(), zero);
  engine.start();
  for (const auto &x : path)
    {
      hip.write(x, zero);
      // Let the scheduler see the new position (100 Hz) before asking
      // whether anything is left to do.
      std::this_thread::sleep_for(std::chrono::milliseconds(100));
      const auto start = Clock::now();
      while (!engine.idle())
        {
          if (Clock::now() - start > std::chrono::minutes(5))
            return false;
          std::this_thread::sleep_for(std::chrono::milliseconds(10));
        }
    }
  engine.stop();
  return true;
}

#endif
