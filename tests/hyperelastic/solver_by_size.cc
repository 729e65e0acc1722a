// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

// Solver settings that follow the mesh (issue 25): with the defaults
// Nonlinear solver / Reuse factorization = by size and Linear solver /
// Solver and Ordering = by size, a solver chooses by its number of
// equations: exact Newton steps, MUMPS in double and AMF on the paper's
// StVK liver (1,473 equations), reuse from 1,500 equations (Mooney-Rivlin
// on the same liver, 1,974), single-precision factors in GMRES and METIS
// from 5,000 (a beam of 5,835 equations). A setting the scene fixes is
// kept whatever the size. Each case also solves a state, so a wrong choice
// that breaks the solver would show. A tangent beyond single precision
// (Young's modulus 1e43 Pa: entries above float's 3.4e38) makes the mixed
// solver fall back to MUMPS in double, and the state is still computed,
// with the force 1e38 times that at 1e5 Pa (StVK is linear in E) to 1e-9.

#include <palpate/hyperelastic/hyperelastic_system.h>
#include <palpate/hyperelastic/state_solver.h>

#include "../tests.h"

namespace
{
  palpate::State
  report(const std::string &name, const palpate::Scene &scene)
  {
    const Body           body(scene);
    palpate::StateSolver solver(body.mesh, body.nodes, scene.parameters);
    const unsigned int   n = solver.system().n_equations();
    const palpate::State s =
      solver.solve(solver.rest_state(), {{0, 0, -0.002}});
    deallog << name << ": " << n << " equations, reuse "
            << (solver.settings().reuse_factorization ? "on" : "off") << ", "
            << solver.linear_solver_name() << ", converged "
            << (s.converged ? "yes" : "no") << std::endl;
    return s;
  }
} // namespace

int
main(int argc, char **argv)
{
  palpate::Environment env(argc, argv);
  initlog();

  palpate::Scene stvk = shipped_scene("paper-stvk.prm");
  AssertThrow(stvk.parameters.nonlinear_solver.reuse_by_size &&
                stvk.parameters.linear_solver.ordering == "by size",
              dealii::ExcMessage("the shipped scene should use the defaults"));
  report("liver501 StVK", stvk);
  report("liver501 Mooney-Rivlin", shipped_scene("paper-mooney-rivlin.prm"));

  palpate::Scene beam        = shipped_scene("beam.prm");
  auto          &m           = beam.parameters.mesh;
  m.beam_subdivisions_length = 24;
  m.beam_subdivisions_width = m.beam_subdivisions_height = 8;
  const palpate::State soft = report("beam 24 x 8 x 8", beam);

  // Beyond single precision: the fall-back to double.
  palpate::Scene stiff = beam;
  stiff.parameters.material_model.set("St.Venant-Kirchhoff",
                                      "Young's modulus",
                                      1e43);
  const palpate::State hard =
    report("beam 24 x 8 x 8, E = 1e43 Pa (after the solve)", stiff);
  palpate::Utilities::Point3 scaled = soft.force;
  for (double &f : scaled)
    f *= 1e38;
  deallog << "  force = 1e38 x the force at 1e5 Pa: "
          << (hard.converged &&
                  palpate::Utilities::distance(hard.force, scaled) <=
                    1e-9 * palpate::Utilities::norm(scaled) ?
                "yes" :
                "NO")
          << std::endl;

  // Fixed by the scene: kept.
  beam.parameters.linear_solver.solver = "MUMPS";
  report("beam 24 x 8 x 8, MUMPS fixed", beam);

  // Fixed by the scene: kept.
  beam.parameters.linear_solver.ordering = "AMF";
  beam.parameters.nonlinear_solver.set_reuse(false);
  report("beam 24 x 8 x 8, AMF and no reuse fixed", beam);
  stvk.parameters.linear_solver.ordering = "METIS";
  stvk.parameters.nonlinear_solver.set_reuse(true);
  report("liver501 StVK, METIS and reuse fixed", stvk);
}
