// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

// With Interpolation = contact patch and Contact solver = condensed, a
// state's Newton solve makes its last factors with the contact patch's
// Schur complement once the relative residual is below 1e-4, and the
// patch comes from them (no partial factorisation of its own); a sphere
// that clears the body's free equilibrium is that equilibrium, with no
// Newton step. On the beam touched by a 1 cm sphere, along a path that
// presses, slides, lifts the sphere off, moves it in the air and presses
// again, each state from the previous one: against the states of the path
// without either (patch from the converged tangent, every state walked
// to), the forces and fields agree to 1e-8, the patches hold the same
// nodes, positions (1e-8) and compliance (1e-3: the tangent of an
// iterate within 1e-4 of the state), and cost no more factorisations; the
// states in the air take no Newton iteration and are the free equilibrium
// to 1e-8. With gravity on, the rest configuration is no equilibrium: the
// first state in the air walks there, and the later ones start from it.
// The Schur complement's factors solve A x = b like a direct solver
// (1e-5: single precision) on a 3-D Laplacian, and return 0 for b = 0.

#include <palpate/hyperelastic/contact_patch.h>
#include <palpate/hyperelastic/inverse_block.h>
#include <palpate/hyperelastic/linear_solver.h>
#include <palpate/hyperelastic/state_solver.h>

#include <cmath>

#include "../tests.h"

namespace
{
  using palpate::Utilities::Point3;

  double
  relative(const std::vector<double> &a, const std::vector<double> &b)
  {
    double d = 0, s = 0;
    for (unsigned int i = 0; i < b.size(); ++i)
      {
        d = std::max(d, std::abs(a[i] - b[i]));
        s = std::max(s, std::abs(b[i]));
      }
    return a.size() != b.size() ? 1 : s > 0 ? d / s : d;
  }

  unsigned int
  factorizations(const palpate::State &s)
  {
    unsigned int n = s.stiffness_factorizations;
    for (const auto &r : s.history)
      n += r.factorized;
    return n;
  }

  void
  compare(const std::string &name, palpate::Scene scene)
  {
    auto &p                                  = scene.parameters;
    p.state_space.interpolation              = "contact patch";
    p.state_space.grid_spacing               = 0.002;
    p.nonlinear_solver.condensed_contact     = true;
    p.nonlinear_solver.residual_tolerance    = 1e-10;
    p.nonlinear_solver.patch_factor_residual = 0;
    p.nonlinear_solver.free_start            = false;
    const Body           body(scene);
    palpate::StateSolver reference(body.mesh, body.nodes, p);
    p.nonlinear_solver.patch_factor_residual = 1e-4;
    p.nonlinear_solver.free_start            = true;
    palpate::StateSolver solver(body.mesh, body.nodes, p);

    const auto at = [](const double x, const double y, const double z) {
      return Point3{{x, y, z}};
    };
    // Press 3 mm, slide 2 mm, lift 3 mm above the surface, move there,
    // press again.
    const std::vector<Point3> path = {at(0, 0, -0.001),
                                      at(0, 0, -0.003),
                                      at(0.002, 0, -0.003),
                                      at(0.002, 0, 0.001),
                                      at(0.002, 0, 0.003),
                                      at(0, 0.002, 0.003),
                                      at(-0.002, 0.002, 0.003),
                                      at(-0.002, 0.002, -0.002)};
    palpate::State a = reference.rest_state(), b = solver.rest_state();
    double         force = 0, field = 0, largest_field = 0, position = 0,
           compliance      = 0;
    unsigned int converged = 0, same_nodes = 0, in_air = 0, free_starts = 0,
                 factors_reference = 0, factors = 0;
    for (const Point3 &target : path)
      {
        a = reference.solve(a, target);
        b = solver.solve(b, target);
        converged += a.converged && b.converged;
        const double f = palpate::Utilities::norm(a.force);
        force          = std::max(force,
                         palpate::Utilities::distance(a.force, b.force) /
                           std::max(f, 1e-3));
        for (unsigned int i = 0; i < a.solution.size(); ++i)
          {
            field = std::max(field, std::abs(a.solution[i] - b.solution[i]));
            largest_field = std::max(largest_field, std::abs(a.solution[i]));
          }
        factors_reference += factorizations(a);
        factors += factorizations(b);
        if (f == 0)
          {
            ++in_air;
            free_starts += b.newton_iterations == 0 && b.force[0] == 0 &&
                           b.force[1] == 0 && b.force[2] == 0;
          }
        if (a.contact_patch && b.contact_patch)
          {
            same_nodes += a.contact_patch->nodes == b.contact_patch->nodes;
            position = std::max(position,
                                relative(b.contact_patch->position,
                                         a.contact_patch->position));
            compliance =
              std::max(compliance,
                       relative(b.contact_patch->W, a.contact_patch->W));
          }
      }
    // Against the largest of the path: in the air the fields are the
    // free equilibrium, round-off without gravity.
    field /= largest_field;
    deallog << name << ": " << path.size() << " states, " << converged
            << " converged in both, " << in_air << " in the air, "
            << free_starts << " of them without a Newton iteration"
            << std::endl;
    deallog << name
            << ": forces agree to 1e-8: " << (force < 1e-8 ? "yes" : "NO")
            << ", fields: " << (field < 1e-8 ? "yes" : "NO")
            << ", patches of the same nodes: "
            << (same_nodes == path.size() ? "yes" : "NO")
            << ", positions to 1e-8: " << (position < 1e-8 ? "yes" : "NO")
            << ", compliance to 1e-3: " << (compliance < 1e-3 ? "yes" : "NO")
            << std::endl;
    deallog << name << ": no more factorisations: "
            << (factors <= factors_reference ? "yes" : "NO") << std::endl;
  }

  void
  schur_solves()
  {
    const Laplacian    system(12);
    const auto        &pattern = system.pattern;
    const auto        &values  = system.values;
    const unsigned int n       = pattern.n_rows;
    // The block on the unknowns of two faces' middle rows.
    std::vector<unsigned int> unknowns;
    for (unsigned int x = 0; x < 12; ++x)
      unknowns.push_back(6 * 12 + x), unknowns.push_back(n - 1 - 6 * 12 - x);
    palpate::InverseBlock block(pattern);
    palpate::SchurFactors factors(block);
    std::vector<double>   inverse;
    const bool            made = block.compute(values, unknowns, inverse);
    const auto exact = palpate::LinearSolver::create("MUMPS", "METIS");
    exact->analyze(pattern);
    exact->factorize(values);
    // Right-hand sides: ones, a unit load on a block unknown (sparse), a
    // unit load inside.
    std::vector<double> b(3 * n, 0.0);
    for (unsigned int i = 0; i < n; ++i)
      b[i] = 1;
    b[n + unknowns[3]]    = 1;
    b[2 * n + n / 2]      = 1;
    std::vector<double> x = b, reference = b;
    const bool          solved = factors.solve_many(x, 3);
    exact->solve_many(reference, 3);
    double block_error = 0;
    for (unsigned int j = 0; j < unknowns.size(); ++j)
      {
        std::vector<double> e(n, 0.0);
        e[unknowns[j]] = 1;
        exact->solve(e);
        for (unsigned int i = 0; i < unknowns.size(); ++i)
          block_error = std::max(block_error,
                                 std::abs(inverse[i * unknowns.size() + j] -
                                          e[unknowns[i]]) /
                                   std::abs(e[unknowns[j]]));
      }
    std::vector<double> zero(n, 0.0);
    const bool          zero_solved = factors.solve(zero);
    deallog << "Laplacian n = " << n << ", a block of " << unknowns.size()
            << ": made: " << (made ? "yes" : "NO")
            << ", equal to the inverse's to 1e-5: "
            << (block_error < 1e-5 ? "yes" : "NO") << std::endl;
    deallog << "solves with its factors equal a direct solver's to 1e-5: "
            << (solved && relative(x, reference) < 1e-5 ? "yes" : "NO")
            << ", b = 0 gives 0: "
            << (zero_solved &&
                    relative(zero, std::vector<double>(n, 0.0)) == 0 ?
                  "yes" :
                  "NO")
            << ", factorize() refuses: "
            << (!factors.factorize(values) && !factors.message().empty() ?
                  "yes" :
                  "NO")
            << std::endl;
  }
} // namespace



int
main(int argc, char **argv)
{
  palpate::Environment env(argc, argv);
  initlog();

  palpate::Scene beam = shipped_scene("beam.prm");
  touch_beam_with_sphere(beam, 0.01);
  compare("beam", beam);
  beam.parameters.effects.turn_on("Gravity");
  compare("beam with gravity", beam);
  schur_solves();
}
