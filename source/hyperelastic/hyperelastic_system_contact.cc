// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

// The sphere probe of HyperelasticSystem (Tip = sphere): the surface nodes
// it may touch, each one's gap and contact force at a solution, the
// sphere's centre inside or outside the deformed surface, and the probe's
// force with its derivatives by the HIP's position (the load and force
// change that the state's stiffness is solved from).

#include <palpate/hyperelastic/hyperelastic_system_impl.h>
#include <palpate/mesh/mesh.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <set>

namespace palpate
{
  using namespace dealii;



  void
  HyperelasticSystem::Impl::find_contact_candidates(
    const Parameters::AllParameters &p,
    const std::vector<bool>         &dof_fixed)
  {
    // --- Tip = sphere: the contact candidates are the free surface nodes,
    // the vertices and (P2) the midpoints of the surface triangles' edges.
    // All of them, not only those near the probe's rest position: the
    // probe may go anywhere (palpate solve --to, the live view), a
    // candidate that is not touched costs one trivial row, and the
    // residual's loop over them is nothing next to the cells'.
    std::vector<types::global_dof_index> dofs(dofs_per_cell);
    const unsigned int first_line = fe->get_first_line_index();
    const unsigned int first_quad = fe->get_first_quad_index(0);
    sphere_radius      = p.boundary_conditions.active_node.tip_radius;
    sphere_rest_center = nodes.sphere_center;
    std::set<std::pair<unsigned int, unsigned int>> surface_edges;
    for (const auto &face : mesh.surface_faces())
      for (unsigned int i = 0; i < 3; ++i)
        surface_edges.insert(
          std::minmax(face.vertices[i], face.vertices[(i + 1) % 3]));
    // Node key: vertex v -> v, edge -> n_vertices + line index.
    std::map<unsigned int, std::array<unsigned int, 3>> node_dofs;
    std::map<unsigned int, Utilities::Point3>           node_position;
    for (const auto &cell : dof_handler.active_cell_iterators())
      {
        cell->get_dof_indices(dofs);
        for (unsigned int i = 0; i < first_quad && i < dofs_per_cell; ++i)
          {
            const unsigned int component =
              fe->system_to_component_index(i).first;
            if (component >= 3)
              continue;
            unsigned int key;
            if (i < first_line)
              {
                key = cell->vertex_index(i / fe->n_dofs_per_vertex());
                if (!mesh.on_surface()[key])
                  continue;
              }
            else
              {
                const auto line =
                  cell->line((i - first_line) / fe->n_dofs_per_line());
                if (!surface_edges.count(std::minmax(line->vertex_index(0),
                                                     line->vertex_index(1))))
                  continue;
                key = mesh.n_vertices() + line->index();
              }
            node_dofs[key][component] = dofs[i];
            node_position[key]        = dof_position[dofs[i]];
          }
      }
    for (const auto &face : mesh.surface_faces())
      {
        std::array<std::array<unsigned int, 3>, 3> d;
        std::array<Utilities::Point3, 3>           X;
        for (unsigned int i = 0; i < 3; ++i)
          {
            d[i] = node_dofs.at(face.vertices[i]);
            X[i] = node_position.at(face.vertices[i]);
          }
        surface_dofs.push_back(d);
        surface_rest.push_back(X);
      }
    // A node with some components fixed (a symmetry plane) slides on
    // its plane and may touch; one fixed entirely cannot move.
    for (const auto &[key, d] : node_dofs)
      if (!dof_fixed[d[0]] || !dof_fixed[d[1]] || !dof_fixed[d[2]])
        {
          ContactNode c;
          c.dof      = d;
          c.position = node_position[key];
          contact.push_back(c);
        }
    n_contact = contact.size();
  }



  HyperelasticSystem::Impl::Contact
  HyperelasticSystem::Impl::contact_at(const unsigned int         k,
                                       const std::vector<double> &u,
                                       const std::vector<double> &x,
                                       const Utilities::Point3   &target) const
  {
    const ContactNode &c = contact[k];
    Contact            r;
    for (unsigned int a = 0; a < 3; ++a)
      r.n[a] = c.position[a] + u[c.dof[a]] - sphere_rest_center[a] - target[a];
    r.rho = Utilities::norm(r.n);
    for (unsigned int a = 0; a < 3; ++a)
      r.n[a] /= r.rho;
    r.gap        = r.rho - sphere_radius;
    r.x_lambda   = x[n_free + k];
    r.lambda_hat = beta * std::max(0.0, r.x_lambda - r.gap);
    return r;
  }



  Utilities::Point3
  HyperelasticSystem::sphere_center(const Utilities::Point3 &target) const
  {
    const auto &c = impl->sphere_rest_center;
    return {{c[0] + target[0], c[1] + target[1], c[2] + target[2]}};
  }



  double
  HyperelasticSystem::sphere_center_distance(
    const std::vector<double> &x,
    const Utilities::Point3   &target) const
  {
    using namespace Utilities;
    const Impl &s = *impl;
    if (!has_contact())
      return std::numeric_limits<double>::infinity();
    s.expand(x, s.u_work);
    const Point3 c       = sphere_center(target);
    double       nearest = std::numeric_limits<double>::infinity();
    // Inside or outside by the parity of the crossings of a ray from the
    // centre (Moller and Trumbore's ray-triangle test), in a direction no
    // mesh is likely to line up with.
    const Point3 ray       = {{0.5377, 0.3107, 0.7836}};
    unsigned int crossings = 0;
    for (unsigned int f = 0; f < s.surface_dofs.size(); ++f)
      {
        std::array<Point3, 3> X;
        for (unsigned int i = 0; i < 3; ++i)
          for (unsigned int a = 0; a < 3; ++a)
            X[i][a] =
              s.surface_rest[f][i][a] + s.u_work[s.surface_dofs[f][i][a]];
        nearest =
          std::min(nearest,
                   distance(c, closest_on_triangle(c, X[0], X[1], X[2])));
        const Point3 e1 = minus(X[1], X[0]), e2 = minus(X[2], X[0]);
        const Point3 h   = cross(ray, e2);
        const double det = dot(e1, h);
        if (std::abs(det) < 1e-300)
          continue;
        const Point3 t0 = minus(c, X[0]);
        const double u  = dot(t0, h) / det;
        if (u < 0 || u > 1)
          continue;
        const Point3 q = cross(t0, e1);
        const double v = dot(ray, q) / det;
        if (v < 0 || u + v > 1)
          continue;
        if (dot(e2, q) / det > 0)
          ++crossings;
      }
    return crossings % 2 == 1 ? -nearest : nearest;
  }



  std::vector<HyperelasticSystem::ContactPoint>
  HyperelasticSystem::contact(const State &state) const
  {
    const Impl               &s = *impl;
    const std::vector<double> x = from_state(state);
    std::vector<ContactPoint> points(s.n_contact);
    for (unsigned int k = 0; k < s.n_contact; ++k)
      {
        const Impl::Contact c =
          s.contact_at(k, state.solution, x, state.active_displacement);
        points[k] = {s.contact[k].dof, c.gap, c.lambda_hat};
      }
    return points;
  }



  Utilities::Point3
  HyperelasticSystem::probe_force(const std::vector<double> &x,
                                  const Utilities::Point3   &target) const
  {
    const Impl       &s     = *impl;
    Utilities::Point3 force = {{0, 0, 0}};
    if (!has_contact())
      {
        // The sum over the tip's nodes (one for a point probe).
        for (unsigned int m = 0; m < s.n_probe_dof_multipliers; ++m)
          force[m % 3] += s.beta * x[s.n_free + m];
        return force;
      }
    s.expand(x, s.u_work);
    for (unsigned int k = 0; k < s.n_contact; ++k)
      {
        const Impl::Contact c = s.contact_at(k, s.u_work, x, target);
        for (unsigned int a = 0; a < 3; ++a)
          force[a] -= c.lambda_hat * c.n[a];
      }
    return force;
  }



  void
  HyperelasticSystem::probe_load(const std::vector<double> &x,
                                 const Utilities::Point3   &target,
                                 const unsigned int         j,
                                 std::vector<double>       &rhs) const
  {
    const Impl &s = *impl;
    rhs.assign(n_equations(), 0.0);
    if (!has_contact())
      {
        // R_lambda = beta (u - target) at the probe's rows of component j.
        for (unsigned int m = j; m < s.n_probe_dof_multipliers; m += 3)
          rhs[s.n_free + m] = s.beta;
        return;
      }
    // The contact terms depend on x_k - c only, so d/dc = -d/du_k of the
    // active nodes' terms (assemble()): -dR_u/dc_j = (beta + lambda/rho)
    // n n_j - lambda/rho e_j, and -dR_lambda/dc_j = -beta n_j.
    s.expand(x, s.u_work);
    for (unsigned int k = 0; k < s.n_contact; ++k)
      {
        const Impl::Contact c = s.contact_at(k, s.u_work, x, target);
        if (!(c.lambda_hat > 0))
          continue;
        const double curvature = c.lambda_hat / c.rho;
        for (unsigned int a = 0; a < 3; ++a)
          if (const int e = s.contact[k].eq[a]; e >= 0)
            rhs[e] = (s.beta + curvature) * c.n[a] * c.n[j] -
                     (a == j ? curvature : 0.0);
        rhs[s.n_free + k] = -s.beta * c.n[j];
      }
  }



  Utilities::Point3
  HyperelasticSystem::probe_force_change(const std::vector<double> &x,
                                         const Utilities::Point3   &target,
                                         const std::vector<double> &dx,
                                         const unsigned int         j) const
  {
    const Impl       &s  = *impl;
    Utilities::Point3 df = {{0, 0, 0}};
    if (!has_contact())
      {
        for (unsigned int m = 0; m < s.n_probe_dof_multipliers; ++m)
          df[m % 3] += s.beta * dx[s.n_free + m];
        return df;
      }
    // f = -sum lambda n with lambda = beta (x_lambda - g), g = rho - R:
    // with dr = du_k - e_j (the node relative to the centre),
    // dg = n . dr, dn = (dr - n (n . dr)) / rho.
    s.expand(x, s.u_work);
    for (unsigned int k = 0; k < s.n_contact; ++k)
      {
        const Impl::Contact c = s.contact_at(k, s.u_work, x, target);
        if (!(c.lambda_hat > 0))
          continue;
        Utilities::Point3 dr;
        for (unsigned int a = 0; a < 3; ++a)
          {
            const int e = s.contact[k].eq[a];
            dr[a]       = (e >= 0 ? dx[e] : 0.0) - (a == j ? 1.0 : 0.0);
          }
        const double dg      = Utilities::dot(c.n, dr);
        const double dlambda = s.beta * (dx[s.n_free + k] - dg);
        for (unsigned int a = 0; a < 3; ++a)
          df[a] -=
            dlambda * c.n[a] + c.lambda_hat * (dr[a] - c.n[a] * dg) / c.rho;
      }
    return df;
  }



  void
  HyperelasticSystem::contact_rows(const std::vector<double> &x,
                                   const Utilities::Point3   &target,
                                   std::vector<ContactRow>   &rows) const
  {
    const Impl &s = *impl;
    s.expand(x, s.u_work);
    rows.resize(s.n_contact);
    for (unsigned int k = 0; k < s.n_contact; ++k)
      {
        const Impl::Contact c = s.contact_at(k, s.u_work, x, target);
        rows[k]               = {
                        s.contact[k].eq, s.n_free + k, c.n, c.rho, c.gap, c.lambda_hat};
      }
  }
} // namespace palpate
