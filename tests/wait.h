// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

// Waiting for an event in a test: poll a condition, with a deadline long
// enough that only a hang reaches it. A test checks what happened (the
// condition), never how long it took; a machine slowed down by other jobs
// only makes the wait longer. Needs nothing from deal.II or palpate, so
// that every test can include it.

#ifndef palpate_tests_wait_h
#define palpate_tests_wait_h

#include <chrono>
#include <iostream>
#include <string>
#include <thread>

/** The deadline (s) a test gives an event that should come within a second
 * or two: long enough for a machine under load, short enough that a hang
 * ends the test well before ctest's own timeout. */
constexpr double generous_deadline = 60;

/**
 * Poll @p condition (a callable returning bool) every @p poll until it
 * holds, at most @p seconds: true as soon as it holds; false once the
 * deadline has passed without it, with a line on stderr saying what was
 * waited for (@p what), so that a failed check in the output has its
 * cause in the log. The condition is checked once more at the deadline:
 * a slow poll never turns an event that came into a timeout.
 */
template <typename Condition>
bool
wait_until(Condition                    &&condition,
           const double                   seconds,
           const std::string             &what,
           const std::chrono::nanoseconds poll = std::chrono::milliseconds(5))
{
  using Clock    = std::chrono::steady_clock;
  const auto end = Clock::now() + std::chrono::duration_cast<Clock::duration>(
                                    std::chrono::duration<double>(seconds));
  while (!condition())
    {
      if (Clock::now() >= end)
        {
          if (condition())
            return true;
          std::cerr << "gave up after " << seconds << " s waiting for " << what
                    << std::endl;
          return false;
        }
      std::this_thread::sleep_for(poll);
    }
  return true;
}

#endif
