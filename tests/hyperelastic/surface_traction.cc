// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

// Effects / Surface traction: a dead-load traction on the faces with one
// boundary id (issue 13). On the shipped beam (10 x 2 x 2 cm, clamped at
// x = 0), t = (0, 0, -1000) Pa on the end face x = L (boundary id 1,
// 4 cm^2), the probe holding its node at rest:
// - the reactions (fixed nodes and probe) balance the load: they sum to
//   t A = 0.4 N, to 1e-9;
// - the load acts: the probe carries it, and twice the traction gives twice
//   the probe force (small strains: linear to 1e-3);
// - off, it leaves no trace: the reactions sum to zero;
// - a boundary id no face has is an input error naming the entry.

#include <palpate/base/exceptions.h>
#include <palpate/hyperelastic/hyperelastic_system.h>
#include <palpate/hyperelastic/state_solver.h>
#include <palpate/mesh/mesh.h>
#include <palpate/mesh/node_selection.h>

#include <cmath>

#include "../tests.h"


int
main(int argc, char **argv)
{
  palpate::Environment env(argc, argv);
  initlog();

  palpate::Scene scene = shipped_scene("beam.prm");
  auto          &e     = scene.parameters.effects;
  e.turn_on("Surface traction", true);
  e.set("Surface traction", "Traction boundary id", "1");
  e.set("Surface traction", "Traction", "0, 0, -1000");
  const auto [f1, sum1] = force_and_reactions_at_rest(scene);
  e.set("Surface traction", "Traction", "0, 0, -2000");
  const auto [f2, sum2] = force_and_reactions_at_rest(scene);
  e.turn_on("Surface traction", false);
  const auto [f0, sum0] = force_and_reactions_at_rest(scene);
  const double load     = 1000 * 4e-4;

  deallog << "reactions balance t A = 0.4 N: "
          << ok(std::abs(sum1[2] - load) < 1e-9 &&
                std::abs(sum1[0]) + std::abs(sum1[1]) < 1e-9)
          << std::endl;
  deallog << "the probe carries the load: "
          << ok(f1[2] < -0.5 * load && f1[2] > -1.01 * load)
          << "; twice the traction, twice the force (1e-3): "
          << ok(std::abs(f2[2] / f1[2] - 2) < 1e-3) << std::endl;
  deallog << "off: no load, reactions sum to zero: "
          << ok(palpate::Utilities::norm(sum0) < 1e-12 &&
                palpate::Utilities::norm(f0) < 1e-12)
          << std::endl;

  e.turn_on("Surface traction", true);
  e.set("Surface traction", "Traction boundary id", "7");
  try
    {
      const palpate::Mesh mesh = palpate::Mesh::create(scene);
      palpate::NodeSelection::create(scene, mesh);
      deallog << "boundary id 7: NO ERROR" << std::endl;
    }
  catch (const palpate::InputError &error)
    {
      deallog << "boundary id 7: input error on " << error.entry() << ": "
              << error.problem() << std::endl;
    }
}
