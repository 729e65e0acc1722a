// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

// An interpolation is one file (issue 46, doc/extending.md): this test
// defines a new one, "nearest corner" (the force of the cell's corner
// nearest to the HIP, linearised with Stiffness weight times that state's
// stiffness), with an entry of its own, in this file only, and registers
// it. Without touching palpate:
// - State space / Interpolation accepts its name (the Selection pattern
//   comes from the registry), the parameter reference describes it, and its
//   own subsection (State space / nearest corner) is declared and read;
// - what it declares each state must keep (the stiffness) is what the
//   solver computes: every state of an interaction carries it, though the
//   scene asks for no stiffness otherwise;
// - an interaction renders its force: the settled force and
//   Interaction::stiffness() are its formula on the cached states, and the
//   one corner it reads is the one point the interaction counts as used;
// - values its checks refuse are input errors naming the entry, the file
//   and the line: its own weight (check_parameters), a grid too coarse for
//   it (check_scene); and the built-in contact patch's check, which now
//   lives in its plug-in, still refuses a tip that is no sphere.

#include <palpate/base/exceptions.h>
#include <palpate/haptics/interaction.h>
#include <palpate/haptics/interpolation.h>
#include <palpate/hyperelastic/state.h>
#include <palpate/scene/scene.h>
#include <palpate/state_space/state_cache.h>
#include <palpate/state_space/state_grid.h>

#include <deal.II/base/parameter_handler.h>

#include <chrono>
#include <cmath>
#include <sstream>
#include <thread>

#include "../tests.h"

namespace
{
  using palpate::Utilities::Point3;

  /** The corner of the cell of @p local nearest to it (bit e: upper along
   * axis e, as StateGrid::corners()). */
  unsigned int
  nearest_corner(const std::array<double, 3> &local)
  {
    return (local[0] >= 0.5 ? 1u : 0u) | (local[1] >= 0.5 ? 2u : 0u) |
           (local[2] >= 0.5 ? 4u : 0u);
  }

  /** The force of the nearest corner's state, f_c - w K_c (x - x_c). */
  class NearestCorner : public palpate::Interpolation
  {
  public:
    NearestCorner(const palpate::StateGrid  &grid,
                  const palpate::StateCache &cache,
                  const double               weight)
      : Interpolation(grid, cache)
      , weight(weight)
    {}

    static void
    declare_parameters(dealii::ParameterHandler &prm)
    {
      prm.declare_entry("Stiffness weight",
                        "1",
                        dealii::Patterns::Double(0.),
                        "Fraction of the corner's stiffness the force is "
                        "linearised with (dimensionless).");
    }

    /** It linearises with the corner's stiffness: each state keeps it. */
    static constexpr palpate::Plugins::StateContents state_contents = {true,
                                                                       false};

    /** When the scene is read: a weight above 1 overshoots the state. */
    static void
    check_parameters(const dealii::ParameterHandler &own)
    {
      if (own.get_double("Stiffness weight") > 1)
        throw palpate::Plugins::EntryError(
          "Stiffness weight",
          "at most 1: beyond, the force overshoots the neighbouring states",
          "use a weight between 0 and 1.");
    }

    /** One state answers for half a cell: the grid must be fine. */
    static void
    check_scene(const palpate::Scene &scene)
    {
      if (scene.parameters.state_space.grid_spacing > 0.003)
        throw scene.error("State space/Grid spacing",
                          "nearest corner linearises one state over half a "
                          "cell: at most 3 mm",
                          "use a finer grid, or Interpolation = trilinear.");
    }

    static std::unique_ptr<palpate::Interpolation>
    create(const dealii::ParameterHandler &own,
           const palpate::Scene &,
           const palpate::Mesh &,
           const palpate::StateGrid  &grid,
           const palpate::StateCache &cache)
    {
      return std::make_unique<NearestCorner>(
        grid, cache, own.get_double("Stiffness weight"));
    }

    palpate::ForceSample
    force(const Point3 &x) noexcept override
    {
      palpate::ForceSample sample;
      palpate::GridIndex   lower;
      if (!grid.locate(x, lower, sample.local))
        return sample;
      sample.inside        = true;
      sample.corners       = grid.corners(lower);
      const unsigned int c = nearest_corner(sample.local);
      sample.read          = 1u << c;
      std::array<double, 9> K;
      bool                  has = false;
      if (!cache.read_force_and_stiffness(sample.corners[c],
                                          cache.generation(),
                                          sample.corner_forces[c],
                                          K,
                                          has))
        return sample;
      sample.hits         = 1;
      sample.complete     = true;
      const Point3 corner = grid.position(sample.corners[c]);
      sample.force        = sample.corner_forces[c];
      for (unsigned int i = 0; i < 3; ++i)
        for (unsigned int j = 0; j < 3; ++j)
          {
            sample.stiffness[3 * i + j] = has ? weight * K[3 * i + j] : 0;
            sample.force[i] -= sample.stiffness[3 * i + j] * (x[j] - corner[j]);
          }
      return sample;
    }

  private:
    const double weight;
  };
} // namespace

PALPATE_REGISTER_INTERPOLATION(NearestCorner,
                               "nearest corner",
                               "the force of the cell's corner nearest to "
                               "the HIP, linearised with its stiffness")



namespace
{
  /** The shipped beam with a small state space (a grid of @p spacing,
   * 2 mm unless given, of +-6 mm, a 4.5 mm cloud) and @p state_space's
   * lines in subsection State space. */
  std::string
  scene_text(const std::string &state_space,
             const std::string &spacing = "0.002")
  {
    return read_file(palpate_source_dir + "/parameters/beam.prm") + R"(
subsection Scheduler
  set Cloud radius = 0.0045
end
subsection State space
  set Extent       = 0.006
  set Grid spacing = )" +
           spacing + "\n" + state_space + "end\n";
  }

  const std::string nearest = R"(  set Interpolation = nearest corner
  subsection nearest corner
    set Stiffness weight = 0.5
  end
)";

  /** Read the scene @p text as the file @p name: the error it gives, as
   * the output shows it, or "" if there is none. */
  std::string
  refusal(const std::string &name, const std::string &text)
  {
    write_file(name, text);
    try
      {
        palpate::Scene::read(name);
        return "";
      }
    catch (const palpate::InputError &e)
      {
        return e.entry() + " (line " + std::to_string(e.line()) +
               "): " + e.problem();
      }
  }
} // namespace



int
main(int argc, char **argv)
{
  palpate::Environment env(argc, argv);
  initlog();

  deallog << "State space / Interpolation: one of "
          << palpate::Plugins::selection("interpolation") << std::endl;
  std::ostringstream reference;
  palpate::print_parameters(reference, palpate::ParameterFormat::markdown);
  deallog << "the parameter reference describes it: "
          << ok(reference.str().find("nearest corner: the force of the "
                                     "cell's corner nearest") !=
                std::string::npos)
          << std::endl;

  write_file("nearest.prm", scene_text(nearest));
  const palpate::Scene scene = palpate::Scene::read("nearest.prm");
  deallog << "its states keep their stiffness, as it declares: "
          << ok(scene.parameters.state_space.state_contents().stiffness &&
                !scene.parameters.nonlinear_solver.compute_stiffness)
          << std::endl;

  palpate::Interaction interaction(scene);
  const Point3         inside{{0.0007, -0.0003, -0.0011}};
  interaction.force(inside);
  interaction.attach();
  while (!interaction.initial_cloud_complete())
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  const auto &grid      = interaction.grid();
  const auto &cache     = interaction.cache();
  bool        all_stiff = true;
  for (unsigned int q = 0; q < grid.size(); ++q)
    if (const auto s = cache.state(q); s)
      all_stiff = all_stiff && s->has_stiffness;
  deallog << "every state the engine computed carries its stiffness: "
          << ok(all_stiff) << std::endl;

  // The nearest corner's state, and the force the plug-in's formula gives.
  palpate::GridIndex    lower;
  std::array<double, 3> local;
  grid.locate(inside, lower, local);
  const unsigned int corner = grid.corners(lower)[nearest_corner(local)];
  const auto         state  = cache.state(corner);
  const Point3       at     = grid.position(corner);
  Point3             expected;
  for (unsigned int i = 0; i < 3; ++i)
    {
      expected[i] = state->force[i];
      for (unsigned int j = 0; j < 3; ++j)
        expected[i] -= 0.5 * state->stiffness[3 * i + j] * (inside[j] - at[j]);
    }
  const Point3 f = settled_force(interaction, inside);
  deallog << "the settled force is the nearest corner's, linearised with "
             "half its stiffness: "
          << ok(palpate::Utilities::distance(f, expected) <=
                1e-12 * palpate::Utilities::norm(expected))
          << " (|f| = "
          << palpate::Utilities::to_string(palpate::Utilities::norm(f), 3)
          << " N); not trilinear's: "
          << ok(palpate::Utilities::distance(
                  f, palpate::interpolate_force(grid, cache, inside).force) >
                1e-6 * palpate::Utilities::norm(f))
          << std::endl;
  double K_error = 0, K_size = 0;
  for (unsigned int i = 0; i < 9; ++i)
    {
      K_error = std::max(K_error,
                         std::abs(interaction.stiffness()[i] -
                                  0.5 * state->stiffness[i]));
      K_size  = std::max(K_size, std::abs(state->stiffness[i]));
    }
  deallog << "Interaction::stiffness() is half the corner's: "
          << ok(K_size > 0 && K_error <= 1e-12 * K_size) << std::endl;
  const auto used = interaction.used_points();
  deallog << "points used: " << used.size() << ", the nearest corner: "
          << ok(used.size() == 1 && used[0] == corner) << std::endl;
  interaction.detach();

  deallog << "Stiffness weight = 2: "
          << refusal("heavy.prm",
                     scene_text("  set Interpolation = nearest corner\n"
                                "  subsection nearest corner\n"
                                "    set Stiffness weight = 2\n"
                                "  end\n"))
          << std::endl;
  deallog << "a 5 mm grid: "
          << refusal("coarse.prm", scene_text(nearest, "0.005")) << std::endl;
  deallog << "contact patch with Tip = point: "
          << refusal("patch.prm",
                     scene_text("  set Interpolation = contact patch\n"))
          << std::endl;
}
