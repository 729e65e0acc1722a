// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

// A trajectory is one file (issue 28, doc/extending.md): this test defines
// a new one, "figure eight", with entries of its own, in this file only,
// and registers it. Without touching palpate:
// - the scene's Haptics / Trajectory / Type accepts it, and its own
//   subsection (Haptics / Trajectory / figure eight) is declared and read;
// - Trajectory::create() builds it from the scene: its positions are the
//   analytic ones (to 1e-15 m), and it uses the shared Duration;
// - a whole interaction runs with it (the simulated device follows it: the
//   force log's HIP positions are the figure eight's at the log's times,
//   to 1e-9 m, the log's 9 digits);
// - a value its factory refuses is an input error naming the entry, the
//   file and the line.

#include <palpate/app/interaction_run.h>
#include <palpate/base/exceptions.h>
#include <palpate/haptics/trajectory.h>
#include <palpate/scene/scene.h>

#include <deal.II/base/parameter_handler.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "../tests.h"

namespace
{
  /**
   * A figure eight in the x-y plane through the rest position: width W
   * along x, W / 2 along y, one loop every Period:
   * (W/2 sin(2 pi t / T), W/4 sin(4 pi t / T), 0).
   */
  class FigureEight : public palpate::Trajectory
  {
  public:
    FigureEight(const double width, const double period, const double length)
      : width(width)
      , period(period)
      , length(length)
    {}

    static void
    declare_parameters(dealii::ParameterHandler &prm)
    {
      prm.declare_entry("Width",
                        "0.004",
                        dealii::Patterns::Double(),
                        "Width of the figure eight along x (m).");
      prm.declare_entry("Period",
                        "1",
                        dealii::Patterns::Double(),
                        "Time of one loop (s).");
    }

    static std::unique_ptr<palpate::Trajectory>
    create(const dealii::ParameterHandler &own, const palpate::Scene &scene)
    {
      const double width = own.get_double("Width");
      if (!(width > 0 && width < 0.1))
        throw palpate::Plugins::EntryError("Width",
                                           "must be between 0 and 0.1 m",
                                           "give the width in metres.");
      return std::make_unique<FigureEight>(
        width,
        own.get_double("Period"),
        scene.parameters.haptics.trajectory.duration);
    }

    static palpate::Utilities::Point3
    at(const double W, const double T, const double t)
    {
      const double pi = std::acos(-1.0);
      return {{W / 2 * std::sin(2 * pi * t / T),
               W / 4 * std::sin(4 * pi * t / T),
               0}};
    }

    palpate::Utilities::Point3
    position(const double t) const noexcept override
    {
      return at(width, period, std::clamp(t, 0.0, length));
    }

    double
    duration() const noexcept override
    {
      return length;
    }

    std::string
    description() const override
    {
      return "figure eight, " + palpate::Utilities::to_string(width, 3) +
             " m wide";
    }

  private:
    double width, period, length;
  };
} // namespace

PALPATE_REGISTER_TRAJECTORY(FigureEight,
                            "figure eight",
                            "a figure eight in the x-y plane, of Width");



int
main(int argc, char **argv)
{
  palpate::Environment env(argc, argv);
  initlog();

  // The shipped beam with the figure eight as its device's motion.
  const auto scene_text = [&](const std::string &width) {
    return beam_interaction(R"(
subsection Haptics
  subsection Trajectory
    set Type     = figure eight
    set Duration = 1
    subsection figure eight
      set Width  = )" + width +
                            R"(
      set Period = 0.8
    end
  end
end
subsection Output
  set Directory = figure-eight-output
end
)");
  };
  write_file("figure-eight.prm", scene_text("0.006"));
  const palpate::Scene scene = palpate::Scene::read("figure-eight.prm");

  const auto  trajectory = palpate::Trajectory::create(scene);
  const auto *eight      = dynamic_cast<const FigureEight *>(trajectory.get());
  double      worst      = 0;
  for (unsigned int i = 0; i <= 100; ++i)
    {
      const double t = 0.01 * i;
      worst =
        std::max(worst,
                 palpate::Utilities::distance(trajectory->position(t),
                                              FigureEight::at(0.006, 0.8, t)));
    }
  deallog << "created from the scene: " << ok(eight != nullptr)
          << ", positions to 1e-15 m: " << ok(worst <= 1e-15)
          << ", the shared Duration: " << ok(trajectory->duration() == 1)
          << ", " << trajectory->description() << std::endl;

  // A whole interaction with it: the force log's HIP is the figure eight.
  std::filesystem::remove_all("figure-eight-output");
  std::ostringstream report;
  palpate::run_interaction(report, scene);
  unsigned int rows = 0;
  double       off  = 0;
  for (const auto &values :
       read_csv_rows("figure-eight-output/figure-eight-forces.csv"))
    {
      if (values.size() < 4 || values[0] < 0)
        continue;
      ++rows;
      off = std::max(off,
                     palpate::Utilities::distance(
                       {{values[1], values[2], values[3]}},
                       FigureEight::at(0.006, 0.8, std::min(values[0], 1.0))));
    }
  deallog << "an interaction with it: the report names it "
          << ok(report.str().find("figure eight, 0.006 m wide") !=
                std::string::npos)
          << ", force log rows > 900 " << ok(rows > 900)
          << ", its HIP is the figure eight to 1e-9 m " << ok(off <= 1e-9)
          << std::endl;

  // A width its factory refuses.
  write_file("figure-eight-wide.prm", scene_text("1"));
  try
    {
      const palpate::Scene wide = palpate::Scene::read("figure-eight-wide.prm");
      palpate::Trajectory::create(wide);
      deallog << "Width = 1: accepted (WRONG)" << std::endl;
    }
  catch (const palpate::InputError &e)
    {
      deallog << "Width = 1: " << e.entry() << ": " << e.problem() << " (line "
              << e.line() << ")" << std::endl;
    }
}
