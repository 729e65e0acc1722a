// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

// Patch test: a homogeneous deformation u = (F0 - I) X imposed on every
// surface node of a beam (the active node included, through its
// multipliers) is reproduced at the interior nodes to round-off, for both
// materials and P1 and P2 elements. For P1 the active node's multiplier
// also equals the nodal force of the homogeneous traction P0 N on the
// adjacent surface triangles; for P2 the active node is an interior node
// and its force vanishes.

#include <palpate/hyperelastic/hyperelastic_system.h>
#include <palpate/hyperelastic/material.h>
#include <palpate/hyperelastic/state_solver.h>

#include <cmath>

#include "../tests.h"

namespace
{
  using palpate::Utilities::Point3;

  const double F0[3][3] = {{1.08, 0.05, 0.0},
                           {-0.02, 0.95, 0.03},
                           {0.01, 0.0, 1.04}};

  Point3
  exact(const Point3 &X)
  {
    Point3 u;
    for (unsigned int i = 0; i < 3; ++i)
      {
        u[i] = -X[i];
        for (unsigned int j = 0; j < 3; ++j)
          u[i] += F0[i][j] * X[j];
      }
    return u;
  }

  void
  check(const std::string &material, const unsigned int degree)
  {
    palpate::Scene scene            = shipped_scene("beam.prm");
    auto          &p                = scene.parameters;
    p.mesh.beam_subdivisions_length = 4, p.mesh.beam_subdivisions_width = 3,
    p.mesh.beam_subdivisions_height       = 3;
    p.material_model.model_name           = material;
    p.discretization.polynomial_degree    = degree;
    p.nonlinear_solver.residual_tolerance = 1e-12; // to round-off

    Body body(scene);
    // Every surface node but the active one is fixed, and moved. For P2 the
    // surface edges next to a surface active node would carry free,
    // traction-free midpoint DoFs, which the homogeneous stress violates;
    // there the active node is an interior node, whose force must vanish.
    if (degree == 2)
      for (unsigned int v = 0; v < body.mesh.n_vertices(); ++v)
        if (!body.mesh.on_surface()[v])
          {
            body.nodes.active_vertex = v;
            break;
          }
    body.nodes.fixed_vertices.clear();
    for (unsigned int v = 0; v < body.mesh.n_vertices(); ++v)
      if (body.mesh.on_surface()[v] && v != body.nodes.active_vertex)
        body.nodes.fixed_vertices.push_back(v);

    palpate::StateSolver solver(body.mesh, body.nodes, p);
    auto                &system = solver.system();
    system.set_fixed_displacement(exact);
    // Newton starts from 95% of the homogeneous field (the boundary values
    // are imposed at once, so starting from rest would invert the thin
    // boundary elements); it must find the field itself.
    palpate::State start = solver.rest_state();
    for (unsigned int d = 0; d < system.n_dofs(); ++d)
      start.solution[d] =
        0.95 * exact(system.dof_positions()[d])[system.dof_components()[d]];
    const Point3 xa            = body.mesh.vertices()[body.nodes.active_vertex];
    start.active_displacement  = exact(xa);
    const palpate::State state = solver.solve(start, exact(xa));

    double error = 0, size = 0;
    for (unsigned int d = 0; d < system.n_dofs(); ++d)
      {
        const double u =
          exact(system.dof_positions()[d])[system.dof_components()[d]];
        error = std::max(error, std::abs(state.solution[d] - u));
        size  = std::max(size, std::abs(u));
      }
    deallog << material << ", P" << degree << ": converged " << state.converged
            << "; homogeneous field reproduced, max error / max u < 1e-10: "
            << (error / size < 1e-10 ? "yes" : "NO") << std::endl;

    if (degree == 2)
      deallog << "  force on the interior active node |f| < 1e-10 N: "
              << (palpate::Utilities::norm(state.force) < 1e-10 ? "yes" : "NO")
              << std::endl;
    else
      {
        // The traction of the homogeneous first Piola stress P0 on the
        // surface, lumped to the active node (1/3 of each adjacent
        // triangle's share), is the force the probe applies; the body
        // pushes back with the opposite force.
        dealii::Tensor<2, 3> F, P;
        for (unsigned int i = 0; i < 3; ++i)
          for (unsigned int j = 0; j < 3; ++j)
            F[i][j] = F0[i][j];
        system.material().evaluate(F, P, nullptr);
        Point3 force = {{0, 0, 0}};
        for (const auto &face : body.mesh.surface_faces())
          for (const unsigned int v : face.vertices)
            if (v == body.nodes.active_vertex)
              {
                const auto  &a     = body.mesh.vertices()[face.vertices[0]];
                const auto  &b     = body.mesh.vertices()[face.vertices[1]];
                const auto  &c     = body.mesh.vertices()[face.vertices[2]];
                const double e1[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]};
                const double e2[3] = {c[0] - a[0], c[1] - a[1], c[2] - a[2]};
                // Area-weighted outward normal N dA (the faces are oriented
                // outward), one third to each of its nodes.
                const double n[3] = {0.5 * (e1[1] * e2[2] - e1[2] * e2[1]),
                                     0.5 * (e1[2] * e2[0] - e1[0] * e2[2]),
                                     0.5 * (e1[0] * e2[1] - e1[1] * e2[0])};
                for (unsigned int i = 0; i < 3; ++i)
                  for (unsigned int J = 0; J < 3; ++J)
                    force[i] -= P[i][J] * n[J] / 3;
              }
        const double difference =
          palpate::Utilities::distance(force, state.force) /
          palpate::Utilities::norm(force);
        deallog
          << "  force on the probe ("
          << palpate::Utilities::to_string(state.force, 5)
          << ") N equals the lumped traction, relative difference < 1e-10: "
          << (difference < 1e-10 ? "yes" : "NO") << std::endl;
      }
  }
} // namespace

int
main(int argc, char **argv)
{
  palpate::Environment env(argc, argv);
  initlog();
  for (const std::string material : {"St.Venant-Kirchhoff", "Neo-Hookean"})
    for (const unsigned int degree : {1u, 2u})
      check(material, degree);
}
