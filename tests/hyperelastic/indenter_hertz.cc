// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

// The indenter against Hertz's solution, at the coarsest level of the
// convergence study (benchmarks/run convergence): a neo-Hookean block,
// E = 10 kPa, nu = 0.3, indented 0.1 mm by a sphere of 1 cm radius
// (contact radius sqrt(R d) = 1 mm, a/R = 0.1: small strain), as a
// quarter block of 10 cm with planes of symmetry (HertzBlock), linear
// tetrahedra, spacing 0.5 mm under the sphere. Hertz: F = 4/3 E/(1 -
// nu^2) R^(1/2) d^(3/2) = 1.465 mN. At this level the force is 10 %
// above it (6 nodes in contact); the benchmark shows it converging to
// Hertz with the mesh. The saved output holds the ratio to 3 digits, so a
// change of the contact, the block or the element changes it.

#include <palpate/hyperelastic/hertz.h>
#include <palpate/hyperelastic/hyperelastic_system.h>
#include <palpate/hyperelastic/state_solver.h>

#include <cmath>

#include "../tests.h"

int
main(int argc, char **argv)
{
  palpate::Environment env(argc, argv);
  initlog();

  palpate::Scene scene        = shipped_scene("beam.prm");
  auto          &p            = scene.parameters;
  p.material_model.model_name = "Neo-Hookean";
  const double E = 1e4, nu = 0.3, R = 0.01, d = 1e-4;
  p.material_model.set("Neo-Hookean", "Young's modulus", E);
  p.material_model.set("Neo-Hookean", "Poisson's ratio", nu);
  const double         a = std::sqrt(R * d);
  palpate::HertzBlock  block(p, R, a, 0.1, a / 2, 1);
  palpate::StateSolver solver(*block.mesh, block.nodes, block.parameters);
  const palpate::State s = solver.solve(solver.rest_state(), {{0, 0, -d}});
  const double F = 4 * s.force[2], hertz = palpate::hertz_force(E, nu, R, d);
  unsigned int touching = 0;
  for (const auto &c : solver.system().contact(s))
    touching += c.force > 0;
  deallog << block.description << std::endl
          << "indented 0.1 mm: " << (s.converged ? "converged" : s.message)
          << ", " << touching << " nodes in contact" << std::endl
          << "force " << palpate::Utilities::to_string(1e3 * F, 4)
          << " mN, Hertz " << palpate::Utilities::to_string(1e3 * hertz, 4)
          << " mN, ratio " << palpate::Utilities::to_string(F / hertz, 3)
          << "; within 15 %: " << ok(std::abs(F / hertz - 1) < 0.15)
          << std::endl;
}
