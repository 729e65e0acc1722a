// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

// A haptic device is one file (issue 28, doc/extending.md): this test
// defines a new one, "pusher", in this file only, and registers it. It
// keeps its own clock (it presses down at Speed from the first tick of the
// motion, timed by itself) and says itself when the interaction is over
// (after Ticks forces rendered). Without touching palpate:
// - Haptics / Device accepts it and its subsection (Haptics / pusher) is
//   declared and read; the report and the summary name it;
// - the common haptic loop runs it: the run ends when the device says so
//   (the force log has exactly Ticks rows), the log's positions are the
//   ones it reported and its last row's force the last one it was sent;
// - a value its check refuses is an input error naming the entry, the
//   file and the line.

#include <palpate/app/interaction_run.h>
#include <palpate/base/exceptions.h>
#include <palpate/haptics/device.h>
#include <palpate/scene/scene.h>

#include <deal.II/base/parameter_handler.h>

#include <atomic>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "../tests.h"

namespace
{
  std::atomic<unsigned int> rendered{0};
  std::atomic<double>       last_fz{0}, deepest{0};

  /** Presses straight down at Speed, on its own clock, for Ticks forces. */
  class Pusher : public palpate::Device
  {
  public:
    Pusher(const double speed, const unsigned int ticks)
      : speed(speed)
      , ticks(ticks)
    {}

    static void
    declare_parameters(dealii::ParameterHandler &prm)
    {
      prm.declare_entry("Speed",
                        "0.002",
                        dealii::Patterns::Double(),
                        "How fast it presses down (m/s).");
      prm.declare_entry("Ticks",
                        "500",
                        dealii::Patterns::Integer(),
                        "How many forces it takes before it is done.");
    }

    static void
    check_parameters(const dealii::ParameterHandler &own)
    {
      if (!(own.get_double("Speed") > 0 && own.get_double("Speed") < 1))
        throw palpate::Plugins::EntryError("Speed",
                                           "must be between 0 and 1 m/s",
                                           "give a hand's speed.");
    }

    static std::unique_ptr<palpate::Device>
    create(const dealii::ParameterHandler &own, const palpate::Scene &)
    {
      return std::make_unique<Pusher>(own.get_double("Speed"),
                                      own.get_integer("Ticks"));
    }

    palpate::Utilities::Point3
    position(const double t) noexcept override
    {
      if (t <= 0)
        return {{0, 0, 0}};
      const auto now = std::chrono::steady_clock::now();
      if (!started)
        {
          start   = now;
          started = true;
        }
      const double own_t = std::chrono::duration<double>(now - start).count();
      const double z     = -speed * own_t;
      deepest.store(z);
      return {{0, 0, z}};
    }

    void
    render(const palpate::Utilities::Point3 &force) noexcept override
    {
      if (started)
        {
          ++count;
          ++rendered;
          last_fz.store(force[2]);
        }
    }

    bool
    finished(const double) const noexcept override
    {
      return count >= ticks;
    }

    double
    max_duration() const override
    {
      return 60;
    }

    std::string
    description() const override
    {
      return "pusher, " + std::to_string(ticks) + " ticks";
    }

  private:
    const double                          speed;
    const unsigned int                    ticks;
    bool                                  started = false;
    std::chrono::steady_clock::time_point start;
    unsigned int                          count = 0;
  };
} // namespace

PALPATE_REGISTER_DEVICE(Pusher, "pusher", "presses down (a test's device)")



int
main(int argc, char **argv)
{
  palpate::Environment env(argc, argv);
  initlog();

  const auto scene_text = [&](const std::string &speed) {
    return beam_interaction(R"(
subsection Haptics
  set Device = pusher
  subsection pusher
    set Speed = )" + speed + R"(
    set Ticks = 700
  end
end
subsection Output
  set Directory = pusher-output
end
)");
  };
  write_file("pusher.prm", scene_text("0.003"));
  std::filesystem::remove_all("pusher-output");
  std::ostringstream report;
  palpate::run_interaction(report, palpate::Scene::read("pusher.prm"));

  const auto          log  = read_csv_rows("pusher-output/pusher-forces.csv");
  const unsigned int  rows = log.size();
  bool                straight_down = true;
  std::vector<double> last;
  for (const auto &values : log)
    {
      straight_down = straight_down && values[1] == 0 && values[2] == 0 &&
                      values[3] <= 0 && values[3] >= deepest.load() - 1e-10;
      last = values;
    }
  deallog << "chosen by the scene: the report names it "
          << ok(report.str().find("device:        pusher, 700 ticks") !=
                std::string::npos)
          << ", the summary too "
          << ok(report.str().find("trajectory:        pusher, 700 ticks") !=
                std::string::npos)
          << std::endl;
  deallog << "the common loop ran it until it said so: force log rows = "
             "its 700 ticks "
          << ok(rows == 700 && rendered.load() == 700)
          << ", positions its own, straight down " << ok(straight_down)
          << ", the last row's force the last it was sent "
          << ok(!last.empty() && std::abs(last[6] - last_fz.load()) <=
                                   1e-8 * std::max(1.0, std::abs(last[6])))
          << ", pressed: force up " << ok(!last.empty() && last[6] > 0)
          << std::endl;

  write_file("pusher-fast.prm", scene_text("5"));
  try
    {
      palpate::Scene::read("pusher-fast.prm");
      deallog << "Speed = 5: accepted (WRONG)" << std::endl;
    }
  catch (const palpate::InputError &e)
    {
      deallog << "Speed = 5: " << e.entry() << ": " << e.problem() << " (line "
              << e.line() << ")" << std::endl;
    }
}
