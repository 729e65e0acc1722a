// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

// The assembled tangent is the derivative of the assembled residual: at a
// deformed, non-equilibrium point x and a random direction v,
// || K v - (R(x + e v) - R(x - e v)) / 2e || / || K v || < 1e-6, for each
// material, both treatments of the fixed nodes, and P1 and P2 elements;
// for Mooney-Rivlin the mixed u-p residual with P1-P1 (stabilised) and
// Taylor-Hood, exact and penalised. The compressible materials have no
// pressure field: 3 DoFs per node.

#include <palpate/hyperelastic/hyperelastic_system.h>
#include <palpate/hyperelastic/state_solver.h>

#include <cmath>
#include <random>

#include "../tests.h"

namespace
{
  std::vector<double>
  multiply(const palpate::SparsityCSR &p,
           const std::vector<double>  &values,
           const std::vector<double>  &v)
  {
    std::vector<double> y(p.n_rows, 0.0);
    for (unsigned int i = 0; i < p.n_rows; ++i)
      for (unsigned int k = p.row_start[i]; k < p.row_start[i + 1]; ++k)
        y[i] += values[k] * v[p.column[k]];
    return y;
  }

  double
  norm(const std::vector<double> &v)
  {
    double s = 0;
    for (const double x : v)
      s += x * x;
    return std::sqrt(s);
  }

  void
  check(const std::string                &name,
        palpate::Scene                    scene,
        const std::string                &material,
        const std::string                &treatment,
        const unsigned int                degree,
        const palpate::Utilities::Point3 &target)
  {
    auto &p                                     = scene.parameters;
    p.material_model.model_name                 = material;
    p.boundary_conditions.fixed_nodes.treatment = treatment;
    p.discretization.polynomial_degree          = degree;
    p.nonlinear_solver.max_increment_length     = 0.005;
    const Body           body(scene);
    palpate::StateSolver solver(body.mesh, body.nodes, p);
    const auto          &system = solver.system();

    // A deformed equilibrium, then a random perturbation off it.
    const palpate::State state = solver.solve(solver.rest_state(), target);
    std::vector<double>  x     = system.from_state(state);
    std::mt19937         random(7);
    std::uniform_real_distribution<double> u(-1, 1);
    const double                           L = system.length_scale();
    for (double &xi : x)
      xi += 1e-4 * L * u(random);

    std::vector<double> r, values, rp, rm;
    system.assemble(x, target, r, &values);
    std::vector<double> v(x.size());
    for (double &vi : v)
      vi = L * u(random);
    const std::vector<double> Kv = multiply(system.sparsity(), values, v);

    double best = 1;
    for (const double e : {1e-5, 1e-6, 1e-7})
      {
        std::vector<double> xp = x, xm = x;
        for (unsigned int i = 0; i < x.size(); ++i)
          xp[i] += e * v[i], xm[i] -= e * v[i];
        system.assemble(xp, target, rp, nullptr);
        system.assemble(xm, target, rm, nullptr);
        std::vector<double> difference(x.size());
        for (unsigned int i = 0; i < x.size(); ++i)
          difference[i] = Kv[i] - (rp[i] - rm[i]) / (2 * e);
        best = std::min(best, norm(difference) / norm(Kv));
      }
    deallog << name << ": " << system.discretization_description() << ", "
            << system.n_dofs() << " DoFs ("
            << (system.has_pressure() ? "with" : "no") << " pressure field), "
            << system.n_equations() << " equations, state "
            << (state.converged ? "converged" : "FAILED")
            << "; tangent vs central difference, relative error < 1e-6: "
            << (best < 1e-6 ? "yes" : "NO") << std::endl;
  }
} // namespace

int
main(int argc, char **argv)
{
  palpate::Environment env(argc, argv);
  initlog();

  const palpate::Scene liver = shipped_scene("paper-stvk.prm");
  const palpate::Scene beam  = shipped_scene("beam.prm");

  check("liver, St.Venant-Kirchhoff, elimination",
        liver,
        "St.Venant-Kirchhoff",
        "elimination",
        1,
        {{0, 0, -0.015}});
  check("liver, St.Venant-Kirchhoff, multipliers",
        liver,
        "St.Venant-Kirchhoff",
        "multipliers",
        1,
        {{0.01, 0, -0.01}});
  check("liver, neo-Hookean, elimination",
        liver,
        "Neo-Hookean",
        "elimination",
        1,
        {{0, 0, -0.02}});
  check("liver, neo-Hookean, multipliers",
        liver,
        "Neo-Hookean",
        "multipliers",
        1,
        {{0, -0.01, -0.01}});
  check("beam, St.Venant-Kirchhoff, P2",
        beam,
        "St.Venant-Kirchhoff",
        "elimination",
        2,
        {{0, 0, -0.01}});
  check("beam, neo-Hookean, P2, multipliers",
        beam,
        "Neo-Hookean",
        "multipliers",
        2,
        {{0, 0.005, -0.01}});

  // Mooney-Rivlin: the mixed u-p residual, P1-P1 (stabilised) and
  // Taylor-Hood, exact and penalised incompressibility.
  const palpate::Scene mr = shipped_scene("paper-mooney-rivlin.prm");
  check("liver, Mooney-Rivlin P1-P1, exact",
        mr,
        "Mooney-Rivlin",
        "elimination",
        1,
        {{0, 0, -0.015}});
  check("liver, Mooney-Rivlin P1-P1, exact, multipliers",
        mr,
        "Mooney-Rivlin",
        "multipliers",
        1,
        {{0.01, 0, -0.01}});
  palpate::Scene penalty = mr;
  penalty.parameters.material_model.set("Mooney-Rivlin",
                                        "Incompressibility",
                                        "penalty");
  penalty.parameters.material_model.set("Mooney-Rivlin", "Bulk modulus", 2.5e6);
  check("liver, Mooney-Rivlin P1-P1, penalty",
        penalty,
        "Mooney-Rivlin",
        "elimination",
        1,
        {{0, 0.01, -0.01}});
  palpate::Scene taylor_hood = beam;
  taylor_hood.parameters.material_model.set("Mooney-Rivlin", "C10", 2e4);
  taylor_hood.parameters.material_model.set("Mooney-Rivlin", "C01", 5e3);
  taylor_hood.parameters.material_model.set("Mooney-Rivlin",
                                            "Element",
                                            "Taylor-Hood");
  check("beam, Mooney-Rivlin Taylor-Hood, exact",
        taylor_hood,
        "Mooney-Rivlin",
        "elimination",
        2,
        {{0, 0.003, -0.008}});
}
