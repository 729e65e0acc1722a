// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

// The active-node stiffness K = -df/dx of a converged state (three solves
// with the tangent's factorisation), against central finite differences of
// the force: K e_j = -(f(x + e e_j) - f(x - e e_j)) / 2e, each force a full
// Newton solve from the state, e = 10 micrometres (truncation e^2 K'' is
// far below the tolerance). On liver501, 1 cm into the liver from rest,
// for StVK, neo-Hookean and Mooney-Rivlin (P1-P1, pressure multipliers),
// with exact Newton steps and with factorisation reuse (GMRES), and at
// rest; for a rigid tip of three nodes on the beam; and for a sphere of
// 1 cm radius in contact with liver501 (pressed 1 cm, moved 3.6 mm aside). K
// must agree with the differences to 1e-3 of its largest entry (it comes from
// the tangent of the last Newton step, one iterate behind the state: measured
// 1e-4) and be symmetric to 1e-5 (the force is the gradient of the strain
// energy; GMRES solves to 1e-6 with factorisation reuse), and positive
// definite.

#include <palpate/hyperelastic/hyperelastic_system.h>
#include <palpate/hyperelastic/state_solver.h>
#include <palpate/mesh/mesh.h>
#include <palpate/mesh/node_selection.h>

#include <cmath>

#include "../tests.h"

namespace
{
  void
  check(const std::string                &name,
        palpate::Scene                    scene,
        const palpate::Utilities::Point3 &target,
        const bool                        reuse)
  {
    auto &p = scene.parameters;
    p.nonlinear_solver.set_reuse(reuse);
    p.state_space.interpolation       = "tricubic Hermite";
    const palpate::Mesh          mesh = palpate::Mesh::create(scene);
    const palpate::NodeSelection nodes =
      palpate::NodeSelection::create(scene, mesh);
    palpate::StateSolver solver(mesh, nodes, p);
    const palpate::State rest = solver.rest_state();
    const palpate::State s    = solver.solve(rest, target);
    deallog << name << (reuse ? ", reuse" : ", exact steps") << ": "
            << (s.converged && s.has_stiffness ? "converged" : "FAILED");
    if (!s.converged || !s.has_stiffness)
      {
        deallog << std::endl;
        return;
      }
    const double e       = 1e-5;
    double       largest = 0, diff = 0, asym = 0;
    for (const double k : s.stiffness)
      largest = std::max(largest, std::abs(k));
    for (unsigned int j = 0; j < 3; ++j)
      {
        auto plus = target, minus = target;
        plus[j] += e;
        minus[j] -= e;
        const palpate::State a = solver.solve(s, plus);
        const palpate::State b = solver.solve(s, minus);
        for (unsigned int i = 0; i < 3; ++i)
          {
            const double fd = -(a.force[i] - b.force[i]) / (2 * e);
            diff = std::max(diff, std::abs(fd - s.stiffness[3 * i + j]));
            asym = std::max(asym,
                            std::abs(s.stiffness[3 * i + j] -
                                     s.stiffness[3 * j + i]));
          }
      }
    // Positive definite: the leading minors of the symmetric part.
    const auto  &K  = s.stiffness;
    const double m1 = K[0], m2 = K[0] * K[4] - K[1] * K[3];
    const double m3 = K[0] * (K[4] * K[8] - K[5] * K[7]) -
                      K[1] * (K[3] * K[8] - K[5] * K[6]) +
                      K[2] * (K[3] * K[7] - K[4] * K[6]);
    deallog << ", |K| = " << palpate::Utilities::to_string(largest, 2)
            << " N/m; against differences "
            << (diff <= 1e-3 * largest ? "ok" : "WRONG") << ", symmetric "
            << (asym <= 1e-5 * largest ? "ok" : "NO");
    if (!solver.system().has_contact())
      deallog << ", positive definite "
              << (m1 > 0 && m2 > 0 && m3 > 0 ? "yes" : "NO") << std::endl;
    else
      {
        // A frictionless sphere may slide off a convex surface: sideways
        // its stiffness may be negative (on a flat one it is 0). Along the
        // force, pressing harder, it is positive.
        const auto  &f   = s.force;
        const double ff  = palpate::Utilities::dot(f, f);
        double       kff = 0;
        for (unsigned int i = 0; i < 3; ++i)
          for (unsigned int j = 0; j < 3; ++j)
            kff += f[i] * K[3 * i + j] * f[j];
        deallog << ", along the force "
                << (kff / ff > 0 ? "positive" : "NOT positive") << std::endl;
      }
  }
} // namespace

int
main(int argc, char **argv)
{
  palpate::Environment env(argc, argv);
  initlog();

  const palpate::Utilities::Point3 push    = {{0, 0, -0.01}};
  const palpate::Utilities::Point3 at_rest = {{0, 0, 0}};
  for (const bool reuse : {false, true})
    {
      check("liver501 StVK", shipped_scene("paper-stvk.prm"), push, reuse);
      palpate::Scene nh                       = shipped_scene("paper-stvk.prm");
      nh.parameters.material_model.model_name = "Neo-Hookean";
      check("liver501 neo-Hookean", nh, push, reuse);
      check("liver501 Mooney-Rivlin",
            shipped_scene("paper-mooney-rivlin.prm"),
            push,
            reuse);
    }
  check("liver501 StVK at rest",
        shipped_scene("paper-stvk.prm"),
        at_rest,
        false);
  palpate::Scene tip = shipped_scene("beam.prm");
  tip.parameters.boundary_conditions.active_node.tip_radius = 0.011;
  tip.parameters.boundary_conditions.active_node.tip        = "glued nodes";
  check("beam, tip", tip, {{0.004, 0.002, -0.003}}, false);

  // A sphere in contact: the stiffness is d(contact resultant)/d(centre),
  // through the nodes in contact (HyperelasticSystem::probe_load and
  // probe_force_change). A 2 cm sphere (a smaller one is refused on
  // liver501's triangles) pressed 1 cm in and moved sideways,
  // so that the sphere slides and K has off-diagonal terms.
  for (const bool reuse : {false, true})
    {
      palpate::Scene sphere = shipped_scene("paper-stvk.prm");
      auto          &a      = sphere.parameters.boundary_conditions.active_node;
      a.tip                 = "sphere";
      a.tip_radius          = 0.02;
      // The scene's own push (3 cm) is deeper than the sphere's radius, and
      // the sphere would then have to clear liver501's triangles by a
      // margin: this one is pressed 1 cm.
      a.prescribed_displacement = {{0.003, -0.002, -0.01}};
      check("liver501 StVK, sphere", sphere, a.prescribed_displacement, reuse);
    }
}
