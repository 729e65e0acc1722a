// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

#include <palpate/hyperelastic/condensed_contact.h>
#include <palpate/hyperelastic/linear_solver.h>

#include <algorithm>
#include <cmath>

namespace palpate
{
  CondensedContact::CondensedContact(const HyperelasticSystem &system)
    : system(system)
    , n(system.n_equations())
    , beta(system.constraint_scale())
  {
    reset();
  }



  void
  CondensedContact::reset()
  {
    slot_of.assign(system.n_active_multipliers(), -1);
    columns.clear();
    block_slot   = nullptr;
    block_values = nullptr;
  }



  void
  CondensedContact::use_block(const std::vector<int>    &slot,
                              const std::vector<double> &block)
  {
    block_slot   = &slot;
    block_values = &block;
  }



  unsigned int
  CondensedContact::n_candidates() const
  {
    return candidates.size();
  }



  unsigned int
  CondensedContact::n_columns() const
  {
    return columns.size() / std::max(n, 1u);
  }



  const ContactLCP &
  CondensedContact::contact_problem() const
  {
    return lcp;
  }



  bool
  CondensedContact::condense(
    LinearSolver                                      &solver,
    const std::vector<HyperelasticSystem::ContactRow> &rows)
  {
    const unsigned int m = candidates.size(), M = 3 * m;
    H.resize(std::size_t(M) * M);
    candidate_eq.resize(M);
    for (unsigned int r = 0; r < M; ++r)
      candidate_eq[r] = rows[candidates[r / 3]].eq[r % 3];
    // From the Schur complement's block, if it holds every candidate.
    from_block = block_slot != nullptr;
    for (unsigned int r = 0; from_block && r < M; ++r)
      from_block = candidate_eq[r] < 0 || (*block_slot)[candidate_eq[r]] >= 0;
    if (from_block)
      {
        const std::size_t k = std::llround(std::sqrt(block_values->size()));
        for (unsigned int r = 0; r < M; ++r)
          for (unsigned int c = 0; c < M; ++c)
            {
              const int e = candidate_eq[r], f = candidate_eq[c];
              H[std::size_t(r) * M + c] =
                e < 0 || f < 0 ?
                  0.0 :
                  (*block_values)[(*block_slot)[e] * k + (*block_slot)[f]];
            }
        return true;
      }

    // The columns of nodes that just became candidates: one block solve
    // with the kept factors, unit forces along x, y and z at each.
    missing.clear();
    for (const unsigned int k : candidates)
      if (slot_of[k] < 0)
        missing.push_back(k);
    if (!missing.empty())
      {
        fresh.assign(std::size_t(n) * 3 * missing.size(), 0.0);
        for (unsigned int c = 0; c < missing.size(); ++c)
          for (unsigned int a = 0; a < 3; ++a)
            if (const int e = rows[missing[c]].eq[a]; e >= 0)
              fresh[(std::size_t(3) * c + a) * n + e] = 1;
        if (!solver.solve_many(fresh, 3 * missing.size()))
          return false;
        for (unsigned int c = 0; c < missing.size(); ++c)
          {
            slot_of[missing[c]] = columns.size() / n;
            columns.insert(columns.end(),
                           fresh.begin() + std::size_t(3) * c * n,
                           fresh.begin() + std::size_t(3) * (c + 1) * n);
          }
      }

    // H = P Z on the candidates (symmetric up to the factors' round-off:
    // made exactly so) and the contact forces' stiffness G.
    for (unsigned int i = 0; i < m; ++i)
      for (unsigned int a = 0; a < 3; ++a)
        for (unsigned int j = 0; j < m; ++j)
          for (unsigned int b = 0; b < 3; ++b)
            {
              const int e = rows[candidates[i]].eq[a];
              H[(3 * i + a) * M + 3 * j + b] =
                e < 0 ?
                  0.0 :
                  columns[(std::size_t(slot_of[candidates[j]]) + b) * n + e];
            }
    for (unsigned int r = 0; r < M; ++r)
      for (unsigned int c = 0; c < r; ++c)
        H[r * M + c] = H[c * M + r] = 0.5 * (H[r * M + c] + H[c * M + r]);
    return true;
  }



  bool
  CondensedContact::assemble_W(
    const std::vector<double>                         &x,
    const std::vector<HyperelasticSystem::ContactRow> &rows,
    const bool                                         with_curvature)
  {
    const unsigned int m = candidates.size(), M = 3 * m;
    G.assign(9 * m, 0.0);
    curved = false;
    for (unsigned int i = 0; with_curvature && i < m; ++i)
      {
        const auto  &r = rows[candidates[i]];
        const double l = std::max(0.0, beta * x[r.multiplier_eq]);
        if (l == 0)
          continue;
        curved = true;
        for (unsigned int a = 0; a < 3; ++a)
          for (unsigned int b = 0; b < 3; ++b)
            G[9 * i + 3 * a + b] =
              -l / r.rho * ((a == b ? 1.0 : 0.0) - r.n[a] * r.n[b]);
      }

    // A = I + G H (G is block diagonal), and S = A^-1 C^T.
    A.assign(std::size_t(M) * M, 0.0);
    for (unsigned int r = 0; r < M; ++r)
      A[r * M + r] = 1;
    if (curved)
      {
        for (unsigned int i = 0; i < m; ++i)
          for (unsigned int a = 0; a < 3; ++a)
            for (unsigned int c = 0; c < 3; ++c)
              if (const double g = G[9 * i + 3 * a + c]; g != 0)
                for (unsigned int col = 0; col < M; ++col)
                  A[(3 * i + a) * M + col] += g * H[(3 * i + c) * M + col];
        if (!lu_factorize(A, M, pivot))
          return false;
      }
    S.assign(std::size_t(M) * m, 0.0); // column j at S[j * M]
    for (unsigned int j = 0; j < m; ++j)
      {
        for (unsigned int b = 0; b < 3; ++b)
          S[std::size_t(j) * M + 3 * j + b] = rows[candidates[j]].n[b];
        if (curved)
          lu_solve(A, M, pivot, &S[std::size_t(j) * M]);
      }
    // W = C H S, symmetric in exact arithmetic: made exactly so.
    W.resize(std::size_t(m) * m);
    for (unsigned int i = 0; i < m; ++i)
      for (unsigned int j = 0; j < m; ++j)
        {
          double w = 0;
          for (unsigned int a = 0; a < 3; ++a)
            {
              const double ni = rows[candidates[i]].n[a];
              for (unsigned int c = 0; c < M; ++c)
                w += ni * H[(3 * i + a) * M + c] * S[std::size_t(j) * M + c];
            }
          W[i * m + j] = w;
        }
    for (unsigned int i = 0; i < m; ++i)
      for (unsigned int j = 0; j < i; ++j)
        W[i * m + j] = W[j * m + i] = 0.5 * (W[i * m + j] + W[j * m + i]);
    // A compliance is positive definite; check it as the contact problem
    // will use it.
    return true;
  }



  bool
  CondensedContact::add_columns(const std::vector<double> &v,
                                std::vector<double>       &step)
  {
    if (from_block)
      {
        response.assign(n, 0.0);
        for (unsigned int r = 0; r < candidate_eq.size(); ++r)
          if (candidate_eq[r] >= 0)
            response[candidate_eq[r]] = v[r];
        if (!solver_now->solve(response))
          return false;
        for (unsigned int e = 0; e < n; ++e)
          step[e] += response[e];
        return true;
      }
    for (unsigned int i = 0; i < candidates.size(); ++i)
      for (unsigned int b = 0; b < 3; ++b)
        if (const double c = v[3 * i + b]; c != 0)
          {
            const double *z =
              &columns[(std::size_t(slot_of[candidates[i]]) + b) * n];
            for (unsigned int e = 0; e < n; ++e)
              step[e] += c * z[e];
          }
    return true;
  }



  bool
  CondensedContact::step(
    LinearSolver                                      &solver,
    const std::vector<double>                         &x,
    const std::vector<HyperelasticSystem::ContactRow> &rows,
    std::vector<double>                               &step,
    const double                                       tolerance)
  {
    // Which nodes take part: those in contact, and those that are or that
    // the step brings within a tenth of the radius of the sphere. One
    // further out cannot touch it in this step; one that does after all
    // is a candidate at the next (its gap is negative then, and the
    // residual, which is the reference's, says the state is not yet an
    // equilibrium). Each candidate costs three compliance columns: on the
    // shipped liver a quarter radius made 30-40 candidates, a tenth 15-25,
    // for the same Newton iterations (doc/benchmarks/organ-speed.md).
    const double R         = system.sphere_radius();
    const auto   moved_gap = [&](const HyperelasticSystem::ContactRow &r) {
      double g = r.gap;
      for (unsigned int a = 0; a < 3; ++a)
        if (r.eq[a] >= 0)
          g += r.n[a] * step[r.eq[a]];
      return g;
    };
    candidates.clear();
    for (unsigned int k = 0; k < rows.size(); ++k)
      if (x[rows[k].multiplier_eq] > 0 ||
          std::min(rows[k].gap, moved_gap(rows[k])) < 0.1 * R)
        candidates.push_back(k);
    const unsigned int m = candidates.size(), M = 3 * m;
    if (m == 0)
      return true;
    solver_now = &solver;
    if (!condense(solver, rows))
      return false;

    // The candidates' part of K^-1 (-R).
    v0.resize(M);
    for (unsigned int i = 0; i < m; ++i)
      for (unsigned int a = 0; a < 3; ++a)
        {
          const int e   = rows[candidates[i]].eq[a];
          v0[3 * i + a] = e < 0 ? 0.0 : step[e];
        }
    // The exact Newton step, with the forces' own stiffness G, where the
    // contact problem on it settles; else the step without it, whose W is
    // a compliance and always has a solution (a quasi-Newton step).
    bool with_curvature = false;
    for (const unsigned int k : candidates)
      with_curvature = with_curvature || x[rows[k].multiplier_eq] > 0;
    if (with_curvature && assemble_W(x, rows, true) &&
        solve_contact(x, rows, step, tolerance, true))
      return true;
    assemble_W(x, rows, false);
    return solve_contact(x, rows, step, tolerance, false);
  }



  bool
  CondensedContact::solve_contact(
    const std::vector<double>                         &x,
    const std::vector<HyperelasticSystem::ContactRow> &rows,
    std::vector<double>                               &step,
    const double                                       tolerance,
    const bool                                         settled_only)
  {
    // With G: du_0 = K^-1 (-R) - Z A^-1 G P K^-1 (-R) (Woodbury), so the
    // candidates move by v0 - H y, y = A^-1 G v0.
    const unsigned int m = candidates.size(), M = 3 * m;
    y.assign(M, 0.0);
    if (curved)
      {
        for (unsigned int i = 0; i < m; ++i)
          for (unsigned int a = 0; a < 3; ++a)
            for (unsigned int b = 0; b < 3; ++b)
              y[3 * i + a] += G[9 * i + 3 * a + b] * v0[3 * i + b];
        lu_solve(A, M, pivot, y.data());
      }
    // The contact problem for the new forces: the gaps after du_0 and the
    // forces' change, w = g + C du_0 + W (lambda' - lambda).
    q.resize(m);
    lambda.resize(m);
    for (unsigned int i = 0; i < m; ++i)
      {
        const auto &r = rows[candidates[i]];
        lambda[i]     = std::max(0.0, beta * x[r.multiplier_eq]);
        double g      = r.gap;
        for (unsigned int a = 0; a < 3; ++a)
          {
            double moved = v0[3 * i + a];
            for (unsigned int c = 0; c < M; ++c)
              moved -= H[(3 * i + a) * M + c] * y[c];
            g += r.n[a] * moved;
          }
        q[i] = g;
      }
    for (unsigned int i = 0; i < m; ++i)
      for (unsigned int j = 0; j < m; ++j)
        q[i] -= W[i * m + j] * lambda[j];
    lambda_old = lambda;
    if (!lcp.solve(W, q, lambda, tolerance, !curved) && settled_only)
      return false;

    // step += Z (S (lambda' - lambda) - y): the forces' change, and G.
    v.resize(M);
    for (unsigned int c = 0; c < M; ++c)
      v[c] = -y[c];
    for (unsigned int j = 0; j < m; ++j)
      {
        const double d                          = lambda[j] - lambda_old[j];
        step[rows[candidates[j]].multiplier_eq] = d / beta;
        if (d != 0)
          for (unsigned int c = 0; c < M; ++c)
            v[c] += d * S[std::size_t(j) * M + c];
      }
    return add_columns(v, step);
  }



  bool
  CondensedContact::stiffness(
    LinearSolver                                      &solver,
    const std::vector<double>                         &x,
    const std::vector<HyperelasticSystem::ContactRow> &rows,
    std::array<double, 9>                             &stiffness)
  {
    // Moving the centre by dc = e_j: the forces of the nodes in contact
    // change by dlambda and their normals turn, so that they stay on the
    // sphere. With the tangent K + P^T G P, the nodes move by
    // Z A^-1 (C^T dlambda + G dc) (G dc: the normals turning with the
    // centre), and n_i . du_i = n_i . dc gives
    //   W dlambda = C dc - C H A^-1 G dc.
    // The force on the probe, -sum lambda_i n_i, changes by
    // -sum (dlambda_i n_i + lambda_i (I - n_i n_i^T)(du_i - dc) / rho_i).
    stiffness.fill(0.0);
    candidates.clear();
    for (unsigned int k = 0; k < rows.size(); ++k)
      if (rows[k].lambda_hat > 0)
        candidates.push_back(k);
    const unsigned int m = candidates.size(), M = 3 * m;
    if (m == 0)
      return true;
    solver_now = &solver;
    if (!condense(solver, rows) ||
        !(assemble_W(x, rows, true) || assemble_W(x, rows, false)))
      return false;
    factors = W;
    if (!lu_factorize(factors, m, pivot_W))
      return false;
    std::vector<double> b(m), load(M), du(M);
    for (unsigned int j = 0; j < 3; ++j)
      {
        // load = A^-1 G dc on the candidates.
        std::fill(load.begin(), load.end(), 0.0);
        for (unsigned int i = 0; i < m; ++i)
          for (unsigned int a = 0; a < 3; ++a)
            load[3 * i + a] = G[9 * i + 3 * a + j];
        if (curved)
          lu_solve(A, M, pivot, load.data());
        for (unsigned int i = 0; i < m; ++i)
          {
            double hl = 0;
            for (unsigned int a = 0; a < 3; ++a)
              for (unsigned int c = 0; c < M; ++c)
                hl +=
                  rows[candidates[i]].n[a] * H[(3 * i + a) * M + c] * load[c];
            b[i] = rows[candidates[i]].n[j] - hl;
          }
        lu_solve(factors, m, pivot_W, b.data());
        // du on the candidates: H (S dlambda + load).
        std::vector<double> t(load);
        for (unsigned int i = 0; i < m; ++i)
          for (unsigned int c = 0; c < M; ++c)
            t[c] += b[i] * S[std::size_t(i) * M + c];
        for (unsigned int r = 0; r < M; ++r)
          {
            double s = 0;
            for (unsigned int c = 0; c < M; ++c)
              s += H[r * M + c] * t[c];
            du[r] = s;
          }
        Utilities::Point3 df = {{0, 0, 0}};
        for (unsigned int i = 0; i < m; ++i)
          {
            const auto       &r = rows[candidates[i]];
            const double      l = std::max(0.0, beta * x[r.multiplier_eq]);
            Utilities::Point3 d;
            for (unsigned int a = 0; a < 3; ++a)
              d[a] = du[3 * i + a] - (a == j ? 1.0 : 0.0);
            const double nd = r.n[0] * d[0] + r.n[1] * d[1] + r.n[2] * d[2];
            for (unsigned int a = 0; a < 3; ++a)
              df[a] -= b[i] * r.n[a] + l * (d[a] - r.n[a] * nd) / r.rho;
          }
        for (unsigned int i = 0; i < 3; ++i)
          stiffness[3 * i + j] = -df[i];
      }
    for (const double k : stiffness)
      if (!std::isfinite(k))
        return false;
    return true;
  }
} // namespace palpate
