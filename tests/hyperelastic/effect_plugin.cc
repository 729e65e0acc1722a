// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

// A load effect is one file (issue 13, doc/extending.md): this test defines
// a new effect, "Uniform body force", in this file only, and registers it.
// Without touching palpate:
// - its switch and its entry exist in the parameter reference, and a scene
//   file can set them;
// - on, it loads the body: on the shipped beam (10 x 2 x 2 cm) with the
//   probe holding its node at rest, the reactions sum to b V to 1e-9;
// - off (the default), it is never constructed and the reactions sum to 0;
// - a value its factory refuses is an input error naming the entry, file
//   and line.

#include <palpate/base/exceptions.h>
#include <palpate/hyperelastic/effect.h>
#include <palpate/hyperelastic/hyperelastic_system.h>
#include <palpate/hyperelastic/state_solver.h>
#include <palpate/mesh/mesh.h>
#include <palpate/mesh/node_selection.h>

#include <deal.II/base/parameter_handler.h>

#include <atomic>
#include <cmath>
#include <sstream>

#include "../tests.h"

namespace
{
  std::atomic<int> constructed{0};

  /** A body force b (N/m^3), constant in space: the test's plug-in. */
  class UniformBodyForce : public palpate::Effect
  {
  public:
    explicit UniformBodyForce(const palpate::Utilities::Point3 &b)
      : b(b)
    {
      ++constructed;
    }

    static void
    declare_parameters(dealii::ParameterHandler &prm)
    {
      prm.declare_entry(
        "Body force density",
        "0, 0, -1000",
        dealii::Patterns::List(dealii::Patterns::Double(), 3, 3, ","),
        "The body force b (N/m^3).");
    }

    static std::unique_ptr<palpate::Effect>
    create(const dealii::ParameterHandler &prm)
    {
      const auto b =
        palpate::Utilities::parse_point(prm.get("Body force density"));
      if (palpate::Utilities::norm(b) > 1e9)
        throw palpate::Plugins::EntryError("Body force density",
                                           "beyond 1e9 N/m^3",
                                           "give b in N/m^3.");
      return std::make_unique<UniformBodyForce>(b);
    }

    std::string
    description(const palpate::Mesh &,
                const palpate::Parameters::AllParameters &) const override
    {
      return "uniform body force (" + palpate::Utilities::to_string(b) +
             " N/m^3)";
    }

    void
    apply(palpate::HyperelasticSystem &system,
          const palpate::Parameters::AllParameters &) const override
    {
      system.add_body_force(b);
    }

  private:
    const palpate::Utilities::Point3 b;
  };

  PALPATE_REGISTER_EFFECT(UniformBodyForce,
                          "Uniform body force",
                          "a uniform body force (the test's plug-in)")

  /** The sum of the reactions (N) at rest. */
  palpate::Utilities::Point3
  reactions(const palpate::Scene &scene)
  {
    return force_and_reactions_at_rest(scene).second;
  }
} // namespace

int
main(int argc, char **argv)
{
  palpate::Environment env(argc, argv);
  initlog();

  // The parameter reference lists the switch and the entry.
  {
    dealii::ParameterHandler prm;
    palpate::Parameters::AllParameters::declare_parameters(prm);
    std::ostringstream out;
    prm.print_parameters(out, dealii::ParameterHandler::ShortPRM);
    deallog << "declared: switch "
            << ok(out.str().find("set Uniform body force") != std::string::npos)
            << ", entry "
            << ok(out.str().find("set Body force density") != std::string::npos)
            << std::endl;
  }

  // A scene file switches it on.
  const std::string beam =
    read_file(palpate_source_dir + "/parameters/beam.prm");
  write_file("on.prm",
             beam + "\nsubsection Effects\n  set Uniform body force = "
                    "true\n  set Body force density = 0, 0, -2000\nend\n");
  const palpate::Scene on     = palpate::Scene::read("on.prm");
  const auto           sum_on = reactions(on);
  const double         load   = 2000 * 0.1 * 0.02 * 0.02;
  deallog << "on: reactions sum to b V = " << load << " N (1e-9): "
          << ok(std::abs(sum_on[2] - load) < 1e-9 &&
                std::abs(sum_on[0]) + std::abs(sum_on[1]) < 1e-9)
          << std::endl;

  // Off by default: never built.
  constructed            = 0;
  palpate::Scene off     = shipped_scene("beam.prm");
  const auto     sum_off = reactions(off);
  deallog << "off: never constructed " << ok(constructed == 0)
          << ", reactions sum to zero "
          << ok(palpate::Utilities::norm(sum_off) < 1e-12) << std::endl;

  // Its factory's refusal is an input error with the entry's line.
  write_file("bad.prm",
             beam + "\nsubsection Effects\n  set Uniform body force = "
                    "true\n  set Body force density = 0, 0, -1e12\nend\n");
  try
    {
      palpate::Scene::read("bad.prm");
      deallog << "bad value: NOT refused" << std::endl;
    }
  catch (const palpate::InputError &e)
    {
      deallog << "bad value: " << e.entry() << ": " << e.problem() << " (line "
              << e.line() << ")" << std::endl;
    }
}
