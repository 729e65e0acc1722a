// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

// The multiplier is the reaction: at a computed state of the liver, the
// force on the probe equals f_ext - f_int at the active node, computed
// from the residual; the reactions of all constrained nodes (active and
// fixed) sum to zero, or, with gravity on, to the body's weight. Fixed
// nodes treated by elimination and by multipliers give the same state,
// and the fixed nodes' multipliers equal the eliminated reactions.

#include <palpate/hyperelastic/hyperelastic_system.h>
#include <palpate/hyperelastic/state_solver.h>

#include <cmath>

#include "../tests.h"

namespace
{
  using palpate::Utilities::Point3;

  /** Reactions at the constrained DoFs of a state, summed by component. */
  Point3
  total_reaction(const palpate::HyperelasticSystem &system,
                 const palpate::State              &state)
  {
    const auto f = system.nodal_residual(state.solution);
    Point3     sum{{0, 0, 0}};
    for (const unsigned int d : system.fixed_dofs())
      sum[system.dof_components()[d]] -= f[d];
    for (unsigned int c = 0; c < 3; ++c)
      sum[c] += state.force[c];
    return sum;
  }

  bool
  small(const double x)
  {
    return x < 1e-8;
  }
} // namespace

int
main(int argc, char **argv)
{
  palpate::Environment env(argc, argv);
  initlog();

  const Point3   target = {{0.01, -0.01, -0.02}};
  palpate::State eliminated;
  for (const std::string treatment : {"elimination", "multipliers"})
    {
      palpate::Scene scene = shipped_scene("paper-stvk.prm");
      scene.parameters.boundary_conditions.fixed_nodes.treatment = treatment;
      scene.parameters.nonlinear_solver.residual_tolerance       = 1e-11;
      const Body           body(scene);
      palpate::StateSolver solver(body.mesh, body.nodes, scene.parameters);
      const auto          &system = solver.system();
      const palpate::State state  = solver.solve(solver.rest_state(), target);

      const auto f = system.nodal_residual(state.solution);
      Point3     from_residual;
      for (unsigned int c = 0; c < 3; ++c)
        from_residual[c] = -f[system.active_dofs()[c]];
      const double scale = palpate::Utilities::norm(state.force);
      deallog << "liver, fixed nodes by " << treatment << ": "
              << system.n_equations() << " equations, converged "
              << state.converged << ", force on the probe ("
              << palpate::Utilities::to_string(state.force, 5) << ") N"
              << std::endl;
      deallog
        << "  multiplier = reaction from the residual, relative difference < 1e-8: "
        << (small(palpate::Utilities::distance(from_residual, state.force) /
                  scale) ?
              "yes" :
              "NO")
        << std::endl;
      deallog << "  sum of all reactions (active + fixed) / |force| < 1e-8: "
              << (small(
                    palpate::Utilities::norm(total_reaction(system, state)) /
                    scale) ?
                    "yes" :
                    "NO")
              << std::endl;

      if (treatment == "elimination")
        eliminated = state;
      else
        {
          double u_difference = 0, u_size = 0;
          for (unsigned int d = 0; d < state.solution.size(); ++d)
            {
              u_difference =
                std::max(u_difference,
                         std::abs(state.solution[d] - eliminated.solution[d]));
              u_size = std::max(u_size, std::abs(eliminated.solution[d]));
            }
          deallog
            << "  same state as with elimination: displacement difference / max u < 1e-8: "
            << (small(u_difference / u_size) ? "yes" : "NO")
            << ", force difference / |force| < 1e-8: "
            << (small(
                  palpate::Utilities::distance(state.force, eliminated.force) /
                  scale) ?
                  "yes" :
                  "NO")
            << std::endl;
          // The multipliers of the fixed DoFs are their reactions.
          const auto fe    = system.nodal_residual(eliminated.solution);
          double     worst = 0, size = 0;
          for (unsigned int m = 3; m < state.multipliers.size(); ++m)
            {
              const unsigned int d = system.fixed_dofs()[m - 3];
              worst = std::max(worst, std::abs(state.multipliers[m] + fe[d]));
              size  = std::max(size, std::abs(fe[d]));
            }
          deallog
            << "  fixed-node multipliers = eliminated reactions, relative difference < 1e-7: "
            << (worst / size < 1e-7 ? "yes" : "NO") << std::endl;
        }
    }

  // The incompressible Mooney-Rivlin liver (P1-P1 and Taylor-Hood): the
  // multiplier is still the reaction, and reactions still balance.
  for (const std::string element : {"P1-P1", "Taylor-Hood"})
    {
      palpate::Scene scene = shipped_scene("paper-mooney-rivlin.prm");
      scene.parameters.material_model.set("Mooney-Rivlin", "Element", element);
      scene.parameters.nonlinear_solver.residual_tolerance = 1e-11;
      const Body           body(scene);
      palpate::StateSolver solver(body.mesh, body.nodes, scene.parameters);
      const auto          &system = solver.system();
      const palpate::State state =
        solver.solve(solver.rest_state(), {{0.005, -0.005, -0.01}});
      const auto f = system.nodal_residual(state.solution);
      Point3     from_residual;
      for (unsigned int c = 0; c < 3; ++c)
        from_residual[c] = -f[system.active_dofs()[c]];
      const double scale = palpate::Utilities::norm(state.force);
      deallog << "liver, Mooney-Rivlin " << element << ": converged "
              << state.converged << ", force on the probe ("
              << palpate::Utilities::to_string(state.force, 4) << ") N"
              << std::endl;
      deallog
        << "  multiplier = reaction from the residual, relative difference < 1e-8: "
        << (small(palpate::Utilities::distance(from_residual, state.force) /
                  scale) ?
              "yes" :
              "NO")
        << std::endl;
      deallog << "  sum of all reactions (active + fixed) / |force| < 1e-8: "
              << (small(
                    palpate::Utilities::norm(total_reaction(system, state)) /
                    scale) ?
                    "yes" :
                    "NO")
              << std::endl;
    }

  // With gravity, the constrained nodes carry the weight rho g V.
  {
    palpate::Scene scene = shipped_scene("beam.prm");
    scene.parameters.effects.turn_on("Gravity");
    scene.parameters.nonlinear_solver.residual_tolerance = 1e-11;
    const Body           body(scene);
    palpate::StateSolver solver(body.mesh, body.nodes, scene.parameters);
    const palpate::State state =
      solver.solve(solver.rest_state(), {{0, 0, -0.002}});
    const Point3 sum = total_reaction(solver.system(), state);
    const double weight =
      scene.parameters.material_model.density * 9.81 * body.mesh.volume();
    deallog << "beam under gravity, active node held 2 mm down: weight "
            << weight << " N; reactions sum to ("
            << palpate::Utilities::to_string(sum, 5) << ") N" << std::endl;
    deallog
      << "  reactions = weight (0, 0, -rho g V), relative difference < 1e-8: "
      << (small(palpate::Utilities::distance(sum, {{0, 0, -weight}}) / weight) ?
            "yes" :
            "NO")
      << std::endl;
  }
}
