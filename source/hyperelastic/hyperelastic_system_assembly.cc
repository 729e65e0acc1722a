// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

// HyperelasticSystem's residual and tangent: the cell kernel (the weak
// form at each quadrature point), the loop over cells colour by colour on
// the task arena, the dead loads (gravity, surface tractions), and the rows
// of the multipliers that hold DoFs and of the sphere's contact.

#include <palpate/hyperelastic/hyperelastic_system_impl.h>
#include <palpate/mesh/mesh.h>

#include <deal.II/fe/fe_values.h>
#include <deal.II/grid/tria.h>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <atomic>
#include <cmath>

namespace palpate
{
  using namespace dealii;

  namespace
  {
    /** Largest number of scalar shape functions per cell (P2 tetrahedron). */
    constexpr unsigned int max_nodes = 10;
    /** Pressure shape functions per cell (P1). */
    constexpr unsigned int max_pressure = 4;
    /** Largest number of DoFs per cell. */
    constexpr unsigned int max_dofs = 3 * max_nodes + max_pressure;
  } // namespace



  template <typename Keep>
  void
  HyperelasticSystem::Impl::subtract_dead_loads(double     *f,
                                                const Keep &keep) const
  {
    for (unsigned int d = 0; d < f_body.size(); ++d)
      if (keep(d))
        f[d] -= f_body[d];
    if (!f_surface.empty())
      for (unsigned int d = 0; d < f_surface.size(); ++d)
        if (keep(d))
          f[d] -= load_factor * f_surface[d];
  }



  // One function on purpose (about 150 lines): the assembly's kernel, run
  // for every cell at every Newton iteration. It reads top-down as the weak
  // form (kinematics, stress, residual, tangent, scatter), and its loops
  // share the quadrature point's F, S and C and the cell's local arrays;
  // split, they would pass between the pieces on the hottest path of the
  // solver (doc/benchmarks/newton.md times it).
  template <bool with_matrix, bool to_dofs>
  bool
  HyperelasticSystem::Impl::assemble_cell(const unsigned int         c,
                                          const std::vector<double> &u,
                                          double                    *residual,
                                          double *matrix) const
  {
    const unsigned int  nk   = n_nodes_per_cell;
    const unsigned int  np   = n_pressure;
    const unsigned int  dpc  = dofs_per_cell;
    const unsigned int *dofs = &cell_dofs[c * dpc];

    double u_local[max_nodes][3];
    for (unsigned int k = 0; k < nk; ++k)
      for (unsigned int a = 0; a < 3; ++a)
        u_local[k][a] = u[dofs[local_dof[3 * k + a]]];
    double p_local[max_pressure];
    for (unsigned int m = 0; m < np; ++m)
      p_local[m] = u[dofs[local_pdof[m]]]; // scaled: p = pressure_scale p_local

    double r_local[max_dofs] = {};
    double k_local[with_matrix ? max_dofs * max_dofs : 1];
    if constexpr (with_matrix)
      std::fill_n(k_local, dpc * dpc, 0.0);
    const double s = pressure_scale;
    Tensor<2, 3> F, P, dJ;
    Tensor<4, 3> A, d2J;
    double       J;
    for (unsigned int q = 0; q < n_q; ++q)
      {
        const double *g = &gradients[(std::size_t(c) * n_q + q) * nk * 3];
        F               = unit_symmetric_tensor<3>();
        for (unsigned int k = 0; k < nk; ++k)
          for (unsigned int a = 0; a < 3; ++a)
            for (unsigned int b = 0; b < 3; ++b)
              F[a][b] += u_local[k][a] * g[3 * k + b];
        if (!(determinant(F) > 0) || !material->admissible(F))
          return false;
        material->evaluate(F, P, with_matrix ? &A : nullptr);
        const double w = JxW[c * n_q + q];

        // The pressure: P = P_iso - p dJ/dF, A = A_iso - p d2J/dF2, and the
        // pressure rows s int N_m (-(J - 1) - p/kappa) (+ stabilisation).
        const double *N = mixed ? &pressure_values[q * np] : nullptr;
        if (mixed)
          {
            volume_derivatives(F, J, dJ, with_matrix ? &d2J : nullptr);
            double p_tilde = 0;
            for (unsigned int m = 0; m < np; ++m)
              p_tilde += p_local[m] * N[m];
            const double pressure = s * p_tilde;
            P -= pressure * dJ;
            if constexpr (with_matrix)
              A -= pressure * d2J;
            const double volumetric = -(J - 1) - kappa_inverse * pressure;
            for (unsigned int m = 0; m < np; ++m)
              r_local[local_pdof[m]] += s * w * volumetric * N[m];
          }

        for (unsigned int k = 0; k < nk; ++k)
          for (unsigned int a = 0; a < 3; ++a)
            r_local[local_dof[3 * k + a]] +=
              w * (P[a][0] * g[3 * k] + P[a][1] * g[3 * k + 1] +
                   P[a][2] * g[3 * k + 2]);

        if constexpr (with_matrix)
          {
            // K_(ka)(lb) = w sum_JL A_aJbL g_kJ g_lL, in two steps:
            // Ag_k,abL = sum_J A_aJbL g_kJ, then contract with g_l.
            double Ag[max_nodes][3][3][3];
            for (unsigned int k = 0; k < nk; ++k)
              for (unsigned int a = 0; a < 3; ++a)
                for (unsigned int b = 0; b < 3; ++b)
                  for (unsigned int l = 0; l < 3; ++l)
                    Ag[k][a][b][l] = A[a][0][b][l] * g[3 * k] +
                                     A[a][1][b][l] * g[3 * k + 1] +
                                     A[a][2][b][l] * g[3 * k + 2];
            for (unsigned int k = 0; k < nk; ++k)
              for (unsigned int a = 0; a < 3; ++a)
                {
                  double *row = &k_local[local_dof[3 * k + a] * dpc];
                  for (unsigned int l = 0; l < nk; ++l)
                    for (unsigned int b = 0; b < 3; ++b)
                      row[local_dof[3 * l + b]] +=
                        w * (Ag[k][a][b][0] * g[3 * l] +
                             Ag[k][a][b][1] * g[3 * l + 1] +
                             Ag[k][a][b][2] * g[3 * l + 2]);
                }
            if (mixed)
              {
                // K_u,p = K_p,u = -s w N_m (dJ/dF)_aJ g_kJ;
                // K_p,p = -s^2 w N_m N_n / kappa.
                for (unsigned int k = 0; k < nk; ++k)
                  for (unsigned int a = 0; a < 3; ++a)
                    {
                      const double dJg = dJ[a][0] * g[3 * k] +
                                         dJ[a][1] * g[3 * k + 1] +
                                         dJ[a][2] * g[3 * k + 2];
                      const unsigned int i = local_dof[3 * k + a];
                      for (unsigned int m = 0; m < np; ++m)
                        {
                          const double v = -s * w * N[m] * dJg;
                          k_local[i * dpc + local_pdof[m]] += v;
                          k_local[local_pdof[m] * dpc + i] += v;
                        }
                    }
                if (kappa_inverse > 0)
                  for (unsigned int m = 0; m < np; ++m)
                    for (unsigned int n = 0; n < np; ++n)
                      k_local[local_pdof[m] * dpc + local_pdof[n]] -=
                        s * s * w * kappa_inverse * N[m] * N[n];
              }
          }
      }

    // Brezzi-Pitkaranta: - tau int grad p . grad q over the cell (the
    // gradients are constant, so the integral is the volume).
    if (stabilize)
      {
        const double *G      = &pressure_gradients[std::size_t(c) * np * 3];
        double        volume = 0;
        for (unsigned int q = 0; q < n_q; ++q)
          volume += JxW[c * n_q + q];
        double grad_p[3] = {0, 0, 0};
        for (unsigned int m = 0; m < np; ++m)
          for (unsigned int d = 0; d < 3; ++d)
            grad_p[d] += s * p_local[m] * G[3 * m + d];
        const double t = stabilization_tau[c] * volume;
        for (unsigned int m = 0; m < np; ++m)
          {
            r_local[local_pdof[m]] -=
              s * t *
              (grad_p[0] * G[3 * m] + grad_p[1] * G[3 * m + 1] +
               grad_p[2] * G[3 * m + 2]);
            if constexpr (with_matrix)
              for (unsigned int n = 0; n < np; ++n)
                k_local[local_pdof[m] * dpc + local_pdof[n]] -=
                  s * s * t *
                  (G[3 * m] * G[3 * n] + G[3 * m + 1] * G[3 * n + 1] +
                   G[3 * m + 2] * G[3 * n + 2]);
          }
      }

    // Scatter: into equations (or all DoFs), and into the CSR values.
    for (unsigned int i = 0; i < dpc; ++i)
      {
        if constexpr (to_dofs)
          residual[dofs[i]] += r_local[i];
        else if (const int e = cell_eqs[c * dpc + i]; e >= 0)
          residual[e] += r_local[i];
        if constexpr (with_matrix)
          {
            const long *position =
              &matrix_position[(std::size_t(c) * dpc + i) * dpc];
            for (unsigned int j = 0; j < dpc; ++j)
              if (position[j] >= 0)
                matrix[position[j]] += k_local[i * dpc + j];
          }
      }
    return true;
  }



  template <typename Function>
  bool
  HyperelasticSystem::Impl::for_all_cells(const Function &f) const
  {
    if (!arena)
      {
        // One thread needs no colours: cells in their own order, whose
        // DoFs were numbered cell by cell, keep the gather from u and the
        // scatter into the matrix's rows in cache (colour by colour, the
        // same loop took twice as long on the liver: doc/benchmarks/
        // organ-speed.md).
        const unsigned int n_cells = mesh.n_cells();
        for (unsigned int c = 0; c < n_cells; ++c)
          if (!f(c))
            return false;
        return true;
      }
    // Enter the arena once; colours run one after the other inside it.
    std::atomic<bool> ok(true);
    arena->execute([&]() {
      for (const auto &color : colors)
        {
          tbb::parallel_for(
            tbb::blocked_range<std::size_t>(0, color.size(), 16),
            [&](const tbb::blocked_range<std::size_t> &range) {
              for (std::size_t i = range.begin(); i < range.end(); ++i)
                if (!f(color[i]))
                  ok = false;
            });
          if (!ok)
            return;
        }
    });
    return ok;
  }



  // assemble(), a step: every cell's internal forces into f_work, and its
  // tangent into @p matrix if given; false if a cell's are not finite.
  bool
  HyperelasticSystem::Impl::assemble_cells(std::vector<double> *matrix) const
  {
    f_work.assign(dof_handler.n_dofs(), 0.0);
    bool ok;
    if (matrix != nullptr)
      {
        matrix->assign(pattern.n_nonzeros(), 0.0);
        ok = for_all_cells([&](const unsigned int c) {
          return assemble_cell<true, true>(c,
                                           u_work,
                                           f_work.data(),
                                           matrix->data());
        });
      }
    else
      ok = for_all_cells([&](const unsigned int c) {
        return assemble_cell<false, true>(c, u_work, f_work.data(), nullptr);
      });
    return ok;
  }



  // assemble(), a step: the internal forces from the DoFs to their
  // equations, less the dead loads; returns the internal forces' norm.
  double
  HyperelasticSystem::Impl::gather_forces(std::vector<double> &residual) const
  {
    double f_norm = 0; // internal forces only, not the pressure rows
    for (unsigned int d = 0; d < eq_of_dof.size(); ++d)
      {
        if (dof_component[d] < 3)
          f_norm += f_work[d] * f_work[d];
        if (eq_of_dof[d] >= 0)
          residual[eq_of_dof[d]] = f_work[d];
      }

    // Dead loads, only when there are any (gravity switched on, tractions
    // added): no work at all otherwise.
    if (!f_body.empty() || !f_surface.empty())
      {
        for (unsigned int d = 0; d < eq_of_dof.size(); ++d)
          f_work[d] = 0;
        subtract_dead_loads(f_work.data(), [&](const unsigned int d) {
          return eq_of_dof[d] >= 0;
        });
        for (unsigned int d = 0; d < eq_of_dof.size(); ++d)
          if (eq_of_dof[d] >= 0)
            residual[eq_of_dof[d]] += f_work[d];
      }
    return f_norm;
  }



  // assemble(), a step: the rows of the multipliers that hold fixed DoFs
  // and the probe's DoFs; returns the squared norm of their forces.
  double
  HyperelasticSystem::Impl::add_constraint_rows(
    const std::vector<double> &x,
    const Utilities::Point3   &target,
    std::vector<double>       &residual,
    std::vector<double>       *matrix) const
  {
    // The constraints: beta B^T x_lambda and beta (B u - g).
    double lambda_norm = 0;
    for (unsigned int m = 0; m < multiplier_dof.size(); ++m)
      {
        const unsigned int d = multiplier_dof[m];
        const double       value =
          m < n_probe_dof_multipliers ? target[m % 3] : fixed_value[d];
        const unsigned int e      = n_free + n_contact + m;
        const double       lambda = beta * x[e];
        residual[eq_of_dof[d]] += lambda;
        residual[e] = beta * (u_work[d] - value);
        lambda_norm += lambda * lambda;
        if (matrix != nullptr)
          {
            (*matrix)[position_lambda_u[m]] = beta;
            (*matrix)[position_u_lambda[m]] = beta;
          }
      }
    return lambda_norm;
  }



  // The sphere's contact, as an augmented Lagrangian (Alart and
  // Curnier's semi-smooth form): with the gap g = |x_k - c| - R of
  // candidate k, its multiplier x_lambda (scaled like the others, a
  // length) and lambda_hat = beta max(0, x_lambda - g), the node gets the
  // contact force lambda_hat n along the normal n from the centre c, and
  // the multiplier's row is
  //   -beta (x_lambda - max(0, x_lambda - g)),
  // i.e. -beta g while in contact (x_lambda > g: the node lies on the
  // sphere) and -beta x_lambda otherwise (no force). At a solution this
  // is exactly the complementarity g >= 0, lambda >= 0, g lambda = 0;
  // the residual is continuous, and its Jacobian (taken on either side
  // of the kink) is symmetric, so the symmetric LDL^T factorisation
  // serves: the augmentation beta n n^T stiffens the node's block, and
  // -lambda_hat (I - n n^T)/rho is the sphere's curvature.
  //
  // assemble(), a step: these rows for every contact candidate, their
  // squared forces added to @p lambda_norm; false for a node at the
  // sphere's centre.
  bool
  HyperelasticSystem::Impl::add_contact_rows(const std::vector<double> &x,
                                             const Utilities::Point3   &target,
                                             std::vector<double> &residual,
                                             std::vector<double> *matrix,
                                             const bool contact_in_matrix,
                                             double    &lambda_norm) const
  {
    for (unsigned int k = 0; k < n_contact; ++k)
      {
        const auto   &node = contact[k];
        const Contact c    = contact_at(k, u_work, x, target);
        if (!(c.rho > 1e-9 * sphere_radius))
          return false; // a node at the centre: far beyond any contact
        const unsigned int e = n_free + k;
        lambda_norm += c.lambda_hat * c.lambda_hat;
        if (c.lambda_hat > 0)
          {
            for (unsigned int a = 0; a < 3; ++a)
              if (node.eq[a] >= 0)
                residual[node.eq[a]] -= c.lambda_hat * c.n[a];
            residual[e] = -beta * c.gap;
            if (matrix != nullptr && !contact_in_matrix)
              (*matrix)[node.position_ll] = -beta;
            else if (matrix != nullptr)
              {
                (*matrix)[node.position_ll] = 0;
                const double curvature      = c.lambda_hat / c.rho;
                for (unsigned int a = 0; a < 3; ++a)
                  if (node.eq[a] >= 0)
                    {
                      (*matrix)[node.position_lu[a]] = -beta * c.n[a];
                      (*matrix)[node.position_ul[a]] = -beta * c.n[a];
                      for (unsigned int b = 0; b < 3; ++b)
                        if (node.eq[b] >= 0)
                          (*matrix)[node.position_uu[3 * a + b]] +=
                            (beta + curvature) * c.n[a] * c.n[b] -
                            (a == b ? curvature : 0.0);
                    }
              }
          }
        else
          {
            residual[e] = -beta * c.x_lambda;
            if (matrix != nullptr)
              {
                (*matrix)[node.position_ll] = -beta;
                for (unsigned int a = 0; a < 3; ++a)
                  if (node.eq[a] >= 0)
                    {
                      (*matrix)[node.position_lu[a]] = 0;
                      (*matrix)[node.position_ul[a]] = 0;
                    }
              }
          }
      }
    return true;
  }



  bool
  HyperelasticSystem::assemble(const std::vector<double> &x,
                               const Utilities::Point3   &target,
                               std::vector<double>       &residual,
                               std::vector<double>       *matrix,
                               double                    *force_scale,
                               const bool contact_in_matrix) const
  {
    const Impl &s = *impl;
    s.expand(x, s.u_work);
    // Internal forces go to all DoFs first (that is where the reactions at
    // eliminated DoFs live), then to the equations.
    if (!s.assemble_cells(matrix))
      return false;

    residual.assign(n_equations(), 0.0);
    const double f_norm = s.gather_forces(residual);
    double lambda_norm  = s.add_constraint_rows(x, target, residual, matrix);
    if (!s.add_contact_rows(
          x, target, residual, matrix, contact_in_matrix, lambda_norm))
      return false;

    for (const double r : residual)
      if (!std::isfinite(r))
        return false;
    if (force_scale != nullptr)
      *force_scale =
        std::max({std::sqrt(f_norm),
                  std::sqrt(lambda_norm),
                  1e-12 * s.material->youngs_modulus() * s.L * s.L});
    return true;
  }



  void
  HyperelasticSystem::add_surface_traction(const unsigned int       boundary_id,
                                           const Utilities::Point3 &traction)
  {
    Impl &s = *impl;
    if (s.f_surface.empty())
      s.f_surface.assign(n_dofs(), 0.0);
    const QGaussSimplex<2>               face_quadrature(s.degree + 1);
    FEFaceValues<3>                      fe_face(s.mapping,
                            s.fe->base_element(0),
                            face_quadrature,
                            update_values | update_JxW_values);
    std::vector<types::global_dof_index> dofs(s.dofs_per_cell);
    for (const auto &cell : s.dof_handler.active_cell_iterators())
      for (const unsigned int f : cell->face_indices())
        if (cell->face(f)->at_boundary() &&
            cell->face(f)->boundary_id() == boundary_id)
          {
            fe_face.reinit(typename Triangulation<3>::cell_iterator(cell), f);
            cell->get_dof_indices(dofs);
            for (unsigned int q = 0; q < face_quadrature.size(); ++q)
              for (unsigned int k = 0; k < s.n_nodes_per_cell; ++k)
                for (unsigned int c = 0; c < 3; ++c)
                  s.f_surface[dofs[s.local_dof[3 * k + c]]] +=
                    traction[c] * fe_face.shape_value(k, q) * fe_face.JxW(q);
          }
  }



  void
  HyperelasticSystem::add_body_force(const Utilities::Point3 &b)
  {
    // A dead load: integrated once, here, not at every residual.
    Impl &s = *impl;
    if (s.f_body.empty())
      s.f_body.assign(n_dofs(), 0.0);
    FEValues<3>                          fe_values(s.mapping,
                          s.fe->base_element(0),
                          s.quadrature,
                          update_values | update_JxW_values);
    std::vector<types::global_dof_index> dofs(s.dofs_per_cell);
    for (const auto &cell : s.dof_handler.active_cell_iterators())
      {
        fe_values.reinit(typename Triangulation<3>::cell_iterator(cell));
        cell->get_dof_indices(dofs);
        for (unsigned int q = 0; q < s.quadrature.size(); ++q)
          for (unsigned int k = 0; k < s.n_nodes_per_cell; ++k)
            for (unsigned int c = 0; c < 3; ++c)
              s.f_body[dofs[s.local_dof[3 * k + c]]] +=
                b[c] * fe_values.shape_value(k, q) * fe_values.JxW(q);
      }
  }



  void
  HyperelasticSystem::set_load_factor(const double factor)
  {
    impl->load_factor = factor;
  }



  std::vector<double>
  HyperelasticSystem::nodal_residual(const std::vector<double> &solution) const
  {
    const Impl &s = *impl;
    // The kernel works with scaled pressures.
    std::vector<double> u = solution;
    if (s.mixed)
      for (unsigned int d = 0; d < u.size(); ++d)
        if (s.dof_component[d] == 3)
          u[d] /= s.pressure_scale;
    std::vector<double> f(n_dofs(), 0.0);
    s.for_all_cells([&](const unsigned int c) {
      return s.assemble_cell<false, true>(c, u, f.data(), nullptr);
    });
    s.subtract_dead_loads(f.data(), [](const unsigned int) { return true; });
    return f;
  }
} // namespace palpate
