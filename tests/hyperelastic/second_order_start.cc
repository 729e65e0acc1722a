// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

// StateSolver::solve(from, target, behind): with the state behind the
// source on the same grid line, Newton starts from the extrapolation
// behind -> from -> target. On the liver (StVK), 6 steps of 5 mm along -x
// from rest (the shipped stroke): the same states (forces to 1e-6 relative) in
// fewer Newton iterations. A "behind" state that is not on the line through
// source and target is ignored: the solve is the plain one, iteration for
// iteration. With the state two steps behind as well, the start is the
// quadratic through three states (third order): fewer iterations still.

#include <palpate/hyperelastic/state_solver.h>

#include <cmath>

#include "../tests.h"

int
main(int argc, char **argv)
{
  using palpate::Utilities::Point3;
  palpate::Environment env(argc, argv);
  initlog();

  // Exact Newton steps (no kept factorisation), so that two solves of the
  // same transition can be compared iteration for iteration.
  palpate::Scene scene = shipped_scene("paper-stvk.prm");
  scene.parameters.nonlinear_solver.set_reuse(false);
  const Body           body(scene);
  palpate::StateSolver solver(body.mesh, body.nodes, body.scene.parameters);

  std::vector<palpate::State> plain{solver.rest_state()},
    extrapolated{solver.rest_state()};
  unsigned int iterations[2] = {0, 0};
  double       difference    = 0;
  for (int k = 1; k <= 6; ++k)
    {
      const Point3 x{{-0.005 * k, 0, 0}};
      plain.push_back(solver.solve(plain.back(), x));
      extrapolated.push_back(
        solver.solve(extrapolated.back(),
                     x,
                     k > 1 ? &extrapolated[extrapolated.size() - 2] : nullptr));
      iterations[0] += plain.back().newton_iterations;
      iterations[1] += extrapolated.back().newton_iterations;
      difference =
        std::max(difference,
                 palpate::Utilities::distance(plain.back().force,
                                              extrapolated.back().force) /
                   palpate::Utilities::norm(plain.back().force));
    }
  deallog << "6 states along a line: forces agree to 1e-6: "
          << (difference < 1e-6 ? "yes" : "NO")
          << "; fewer Newton iterations with the state behind: "
          << (iterations[1] < iterations[0] ? "yes" : "NO") << std::endl;
  deallog << "all converged: "
          << (plain.back().converged && extrapolated.back().converged ? "yes" :
                                                                        "NO")
          << ", force at 3 cm ("
          << palpate::Utilities::to_string(extrapolated.back().force, 4)
          << ") N" << std::endl;

  // Third order: with the state two steps behind as well.
  {
    std::vector<palpate::State> third{solver.rest_state()};
    unsigned int                n3 = 0;
    double                      d3 = 0;
    for (int k = 1; k <= 6; ++k)
      {
        const Point3          x{{-0.005 * k, 0, 0}};
        const palpate::State *b  = k > 1 ? &third[third.size() - 2] : nullptr;
        const palpate::State *bb = k > 2 ? &third[third.size() - 3] : nullptr;
        third.push_back(solver.solve(third.back(), x, b, bb));
        n3 += third.back().newton_iterations;
        d3 = std::max(d3,
                      palpate::Utilities::distance(plain[k].force,
                                                   third.back().force) /
                        palpate::Utilities::norm(plain[k].force));
      }
    deallog << "with two states behind: forces agree to 1e-6: "
            << (d3 < 1e-6 ? "yes" : "NO")
            << "; fewer Newton iterations than with one: "
            << (n3 < iterations[1] ? "yes" : "NO") << std::endl;
  }

  // Off the line: behind = the state at 5 mm, source at 1 cm, target 5 mm
  // sideways from the source.
  const Point3         side{{-0.01, 0, -0.005}};
  const palpate::State a = solver.solve(plain[2], side);
  const palpate::State b = solver.solve(plain[2], side, &plain[1]);
  deallog << "a state off the line is ignored: "
          << (a.newton_iterations == b.newton_iterations &&
                  palpate::Utilities::distance(a.force, b.force) == 0 ?
                "yes" :
                "NO")
          << std::endl;
}
