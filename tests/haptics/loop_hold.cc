// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

// The common haptic loop runs the live view's device (issue 28): a
// continuous loop with a TargetFollower, as palpate serve runs it.
// - While held (HapticLoop::hold(), what the live view does while it
//   changes the scene), the loop reads no position and asks for no force;
//   after release() it goes on.
// - The follower reaches its target at rest, never faster than its
//   maximum speed.
// - The force log is a ring drained while the loop runs: rows whose times
//   increase by one period, none dropped.
// - The summary counts the ticks and names the device.

#include <palpate/haptics/haptic_loop.h>
#include <palpate/haptics/interaction.h>
#include <palpate/haptics/run_summary.h>
#include <palpate/haptics/target_follower.h>

#include <atomic>
#include <chrono>
#include <cmath>
#include <sstream>
#include <thread>

#include "../tests.h"

namespace
{
  /** The follower, counting the loop's calls. */
  class Counted : public palpate::TargetFollower
  {
  public:
    using TargetFollower::TargetFollower;

    palpate::Utilities::Point3
    position(const double t) noexcept override
    {
      calls.fetch_add(1);
      const auto x = TargetFollower::position(t);
      const auto d = palpate::Utilities::distance(x, last);
      fastest      = std::max(fastest.load(), d * 1000); // m/s at 1 kHz
      last         = x;
      return x;
    }

    std::atomic<unsigned long> calls{0};
    std::atomic<double>        fastest{0};
    palpate::Utilities::Point3 last{{0, 0, 0}};
  };
} // namespace

int
main(int argc, char **argv)
{
  palpate::Environment env(argc, argv);
  initlog();
  using namespace std::chrono_literals;

  palpate::Scene scene = small_beam_scene();
  scene.parameters.material_model.set("St.Venant-Kirchhoff",
                                      "Young's modulus",
                                      1e6);
  palpate::Interaction interaction(scene);
  interaction.attach();
  Counted             device(1000, 0.05);
  palpate::HapticLoop loop(
    interaction, device, 1000, palpate::HapticLoop::continuous, true);
  loop.start(palpate::HapticLoop::continuous);
  loop.start_motion();
  // Until the loop has run 100 ticks of motion (about 0.1 s; the thread
  // may start late, and a hold before the first logged tick leaves no gap
  // in the log to check).
  const auto waited = [&](const unsigned long n) {
    return wait_until([&] { return device.calls.load() >= n; },
                      generous_deadline,
                      std::to_string(n) + " calls of the loop",
                      1ms);
  };
  waited(100);

  // Held for 0.1 s: the scenario (the loop must read nothing meanwhile).
  loop.hold();
  const auto          held_since = std::chrono::steady_clock::now();
  const unsigned long held_at    = device.calls.load();
  std::this_thread::sleep_for(100ms);
  const unsigned long while_held = device.calls.load() - held_at;
  loop.release();
  // How long the log's gap can be, as this thread saw it: from the hold
  // until the loop's first tick after the release (a loaded machine
  // oversleeps, and wakes the loop late).
  waited(held_at + while_held + 1);
  const double held_for =
    std::chrono::duration<double>(std::chrono::steady_clock::now() - held_since)
      .count();
  waited(held_at + while_held + 51);
  const unsigned long after = device.calls.load() - held_at - while_held;
  deallog << "positions read while held: " << while_held
          << "; after the release, the loop goes on: " << ok(after > 50)
          << std::endl;

  // 2 mm away at 5 cm/s: about 0.1 s with the acceleration limit.
  device.set_target({{0.002, 0, -0.001}});
  // The log drained while the probe goes there, as the live view does.
  std::ostringstream csv;
  std::size_t        rows = 0;
  wait_until(
    [&] {
      rows += loop.drain_force_log(csv);
      return palpate::Utilities::distance(device.hip(), device.target()) <
             1e-12;
    },
    generous_deadline,
    "the follower at its target",
    10ms);
  const auto x = device.hip();
  deallog << "target reached: "
          << ok(palpate::Utilities::distance(x, device.target()) < 1e-12)
          << ", never faster than 5 cm/s: "
          << ok(device.fastest.load() <= 0.05 * (1 + 1e-9)) << std::endl;
  loop.join();
  rows += loop.drain_force_log(csv);

  // The rows: times one period apart (a held tick is not logged: one gap
  // of about 0.1 s), finite, as many as drained. The gap's upper bound is
  // what this thread saw from the hold to the loop's first tick after it,
  // plus 0.5 s for a last tick before the hold that the loop ran late; a
  // loop that did not come back fails "goes on" above.
  std::istringstream in(csv.str());
  std::string        line;
  double             previous = -1, largest_gap = 0;
  unsigned int       read = 0, finite = 0, one_period = 0;
  while (std::getline(in, line))
    {
      double             t = 0, v[6];
      char               comma;
      std::istringstream r(line);
      r >> t;
      bool good = std::isfinite(t);
      for (double &c : v)
        good = (r >> comma >> c) && good && std::isfinite(c);
      finite += good;
      if (previous >= 0)
        {
          const double gap = t - previous;
          largest_gap      = std::max(largest_gap, gap);
          one_period += std::abs(gap - 1e-3) < 0.5e-3;
        }
      previous = t;
      ++read;
    }
  deallog << "force log: rows drained = rows read: " << ok(rows == read)
          << ", all finite: " << ok(finite == read)
          << ", most one period apart: " << ok(one_period > 0.9 * read)
          << ", the hold's gap (0.1 s or what it was held): "
          << ok(largest_gap > 0.09 && largest_gap < held_for + 0.5)
          << ", none dropped: " << ok(loop.force_log_dropped() == 0)
          << std::endl;

  // For the log (not compared: timings).
  std::cout << "held for " << held_for << " s, largest gap in the log "
            << largest_gap << " s" << std::endl;

  palpate::RunSummary summary;
  loop.add_to(summary);
  summary.trajectory = device.description();
  deallog << "summary: ticks = logged rows + the rest before the motion: "
          << ok(summary.ticks >= read && summary.ticks <= read + 5)
          << ", names the device: "
          << ok(summary.trajectory.find("target follower") != std::string::npos)
          << std::endl;
}
