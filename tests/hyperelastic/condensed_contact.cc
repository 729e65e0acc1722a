// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

// Nonlinear solver / Contact solver = condensed gives the states of the
// contact in the matrix (the reference): on the beam touched by a 1 cm
// sphere and on the shipped indenter liver (Mooney-Rivlin P1-P1), states
// along a path that presses, slides the sphere sideways (the contact set
// moves) and lifts it, each from the previous one as an engine worker
// computes them. Force, displacement field and the set of nodes in
// contact agree to 1e-8 (both solved to a residual of 1e-10), and so does
// the probe's stiffness (to 1e-4), which also agrees with central
// differences of the force; so do the condensed states with the
// quasi-Newton steps Anderson-accelerated (Anderson depth = 4). A step of
// the sphere that changes the contact set converges on the kept factors
// without a refactorisation until the stiffness needs one.

#include <palpate/hyperelastic/hyperelastic_system.h>
#include <palpate/hyperelastic/state_solver.h>

#include <cmath>
#include <set>

#include "../tests.h"

namespace
{
  using palpate::Utilities::Point3;

  std::set<unsigned int>
  in_contact(const palpate::HyperelasticSystem &system,
             const palpate::State              &state)
  {
    std::set<unsigned int> nodes;
    for (const auto &c : system.contact(state))
      if (c.force > 0)
        nodes.insert(c.dofs[0]);
    return nodes;
  }

  void
  compare(const std::string         &name,
          palpate::Scene             scene,
          const std::vector<Point3> &path,
          const unsigned int         anderson_depth         = 0,
          const bool                 across_contact_changes = true)
  {
    scene.parameters.nonlinear_solver.residual_tolerance = 1e-10;
    scene.parameters.nonlinear_solver.compute_stiffness  = true;
    const Body           body(scene);
    palpate::StateSolver reference(body.mesh, body.nodes, scene.parameters);
    scene.parameters.nonlinear_solver.condensed_contact = true;
    scene.parameters.nonlinear_solver.anderson_depth    = anderson_depth;
    scene.parameters.nonlinear_solver.anderson_across_contact_changes =
      across_contact_changes;
    palpate::StateSolver condensed(body.mesh, body.nodes, scene.parameters);

    palpate::State from_reference = reference.rest_state(),
                   from_condensed = condensed.rest_state();
    double force = 0, field = 0, largest_field = 0, stiffness = 0,
           fd_stiffness = 0, largest_force = 0;
    unsigned int converged = 0, same_set = 0, touching = 0;
    for (const Point3 &target : path)
      {
        palpate::State a = reference.solve(from_reference, target);
        palpate::State b = condensed.solve(from_condensed, target);
        converged += a.converged && b.converged;
        const double f = palpate::Utilities::norm(a.force);
        largest_force  = std::max(largest_force, f);
        force          = std::max(force,
                         palpate::Utilities::distance(a.force, b.force) /
                           std::max(f, 1e-12));
        for (unsigned int i = 0; i < a.solution.size(); ++i)
          {
            field = std::max(field, std::abs(a.solution[i] - b.solution[i]));
            largest_field = std::max(largest_field, std::abs(a.solution[i]));
          }
        same_set += in_contact(reference.system(), a) ==
                    in_contact(condensed.system(), b);
        touching += !in_contact(reference.system(), a).empty();
        const auto relative = [](const std::array<double, 9> &k,
                                 const std::array<double, 9> &reference) {
          double d = 0, s = 0;
          for (unsigned int i = 0; i < 9; ++i)
            {
              d += std::pow(k[i] - reference[i], 2);
              s += std::pow(reference[i], 2);
            }
          return std::sqrt(d / s);
        };
        if (a.has_stiffness && b.has_stiffness && f > 0)
          stiffness = std::max(stiffness, relative(b.stiffness, a.stiffness));
        // At the first state, the condensed stiffness against central
        // differences of the reference's force (1 um each way).
        if (&target == &path.front() && b.has_stiffness)
          {
            std::array<double, 9> fd;
            for (unsigned int j = 0; j < 3; ++j)
              {
                Point3 plus = target, minus = target;
                plus[j] += 1e-6;
                minus[j] -= 1e-6;
                const auto fp = reference.solve(a, plus).force;
                const auto fm = reference.solve(a, minus).force;
                for (unsigned int i = 0; i < 3; ++i)
                  fd[3 * i + j] = -(fp[i] - fm[i]) / 2e-6;
              }
            fd_stiffness = relative(b.stiffness, fd);
          }
        from_reference = std::move(a);
        from_condensed = std::move(b);
      }
    // Displacements against the largest of the path: a state lifted off
    // is at rest, where both fields are round-off.
    field /= largest_field;
    deallog << name << ": " << path.size() << " states, " << converged
            << " converged in both, " << touching << " touching; largest force "
            << palpate::Utilities::to_string(largest_force, 3) << " N"
            << std::endl;
    deallog << name
            << ": forces agree to 1e-8: " << (force < 1e-8 ? "yes" : "NO")
            << ", displacement fields to 1e-8: "
            << (field < 1e-8 ? "yes" : "NO")
            << ", the same nodes in contact in every state: "
            << (same_set == path.size() ? "yes" : "NO") << std::endl;
    deallog << name << ": stiffness equal to 1e-4: "
            << (stiffness < 1e-4 ? "yes" : "NO")
            << ", to central differences at the first state within 1e-4: "
            << (fd_stiffness < 1e-4 ? "yes" : "NO") << std::endl;
  }
} // namespace



int
main(int argc, char **argv)
{
  palpate::Environment env(argc, argv);
  initlog();

  // The beam clamped on its bottom face, a 1 cm sphere on its top:
  // press 3 mm, slide 4 mm each way, press deeper, lift off.
  palpate::Scene beam = shipped_scene("beam.prm");
  touch_beam_with_sphere(beam, 0.01);
  const std::vector<Point3> beam_path = {{{0, 0, -0.0015}},
                                         {{0, 0, -0.003}},
                                         {{0.002, 0, -0.003}},
                                         {{0.004, 0, -0.003}},
                                         {{0.004, 0.002, -0.003}},
                                         {{0, 0.002, -0.004}},
                                         {{0, 0, -0.005}},
                                         {{0, 0, -0.003}},
                                         {{0, 0, -0.001}},
                                         {{0, 0, 0.001}}};
  compare("beam", beam, beam_path);
  // The same with the quasi-Newton steps Anderson-accelerated.
  compare("beam, Anderson depth 4", beam, beam_path, 4);

  // The shipped indenter liver: the engine's 5 mm steps from a pressed
  // state, sideways both ways.
  const palpate::Scene      liver      = shipped_scene("liver-indenter.prm");
  const std::vector<Point3> liver_path = {{{0, 0, -0.005}},
                                          {{0.005, 0, -0.005}},
                                          {{0.005, 0.005, -0.005}},
                                          {{0, 0.005, -0.005}}};
  compare("liver", liver, liver_path);
  compare("liver, Anderson depth 4", liver, liver_path, 4);
  // The benchmark's path before the history spanned contact changes.
  compare("liver, Anderson depth 4, a new history at each contact change",
          liver,
          liver_path,
          4,
          false);

  // A 2 mm slide of the pressed sphere on the liver moves the contact set;
  // the kept factors of the state before solve it (those the pressed
  // state's stiffness was computed with), until the residual is one step
  // from the state (1e-4), where the stiffness wants factors of its own.
  // (The scene's contact patches want theirs from max(1e-4, 10 x
  // tolerance) on: here the stiffness's Hermite and the tolerance of the
  // condensed path's own tests.)
  {
    palpate::Scene scene                                 = liver;
    scene.parameters.nonlinear_solver.condensed_contact  = true;
    scene.parameters.nonlinear_solver.residual_tolerance = 1e-8;
    scene.parameters.state_space.interpolation           = "tricubic Hermite";
    const Body           body(scene);
    palpate::StateSolver solver(body.mesh, body.nodes, scene.parameters);
    const palpate::State pressed =
      solver.solve(solver.rest_state(), {{0, 0, -0.005}});
    const palpate::State slid = solver.solve(pressed, {{0.002, 0, -0.005}});
    unsigned int         factorizations = 0;
    for (const auto &h : slid.history)
      factorizations += h.factorized && h.residual_before > 1e-4;
    deallog << "liver, a 2 mm slide: converged: "
            << (slid.converged ? "yes" : "NO") << ", contact set changed: "
            << (in_contact(solver.system(), pressed) !=
                    in_contact(solver.system(), slid) ?
                  "yes" :
                  "NO")
            << ", factorisations above a residual of 1e-4: " << factorizations
            << std::endl;
  }
}
