// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

#include <palpate/hyperelastic/contact_lcp.h>

#include <algorithm>
#include <cmath>
#include <limits>

namespace palpate
{
  bool
  lu_factorize(double *A, const unsigned int m, unsigned int *pivot) noexcept
  {
    for (unsigned int k = 0; k < m; ++k)
      {
        unsigned int p = k;
        for (unsigned int i = k + 1; i < m; ++i)
          if (std::abs(A[i * m + k]) > std::abs(A[p * m + k]))
            p = i;
        pivot[k] = p;
        if (!(A[p * m + k] != 0))
          return false;
        if (p != k)
          for (unsigned int j = 0; j < m; ++j)
            std::swap(A[k * m + j], A[p * m + j]);
        const double d = A[k * m + k];
        for (unsigned int i = k + 1; i < m; ++i)
          {
            const double l = A[i * m + k] /= d;
            if (l != 0)
              for (unsigned int j = k + 1; j < m; ++j)
                A[i * m + j] -= l * A[k * m + j];
          }
      }
    return true;
  }



  void
  lu_solve(const double       *LU,
           const unsigned int  m,
           const unsigned int *pivot,
           double             *b) noexcept
  {
    for (unsigned int k = 0; k < m; ++k)
      std::swap(b[k], b[pivot[k]]);
    for (unsigned int i = 0; i < m; ++i)
      for (unsigned int k = 0; k < i; ++k)
        b[i] -= LU[i * m + k] * b[k];
    for (int i = int(m) - 1; i >= 0; --i)
      {
        for (unsigned int k = i + 1; k < m; ++k)
          b[i] -= LU[i * m + k] * b[k];
        b[i] /= LU[i * m + i];
      }
  }



  bool
  lu_factorize(std::vector<double>       &A,
               const unsigned int         m,
               std::vector<unsigned int> &pivot)
  {
    pivot.resize(m);
    return lu_factorize(A.data(), m, pivot.data());
  }



  void
  lu_solve(const std::vector<double>       &LU,
           const unsigned int               m,
           const std::vector<unsigned int> &pivot,
           double                          *b)
  {
    lu_solve(LU.data(), m, pivot.data(), b);
  }



  bool
  ContactLCP::solve_active(const std::vector<double> &W, const unsigned int m)
  {
    // LU rather than Cholesky: with the contact forces' own stiffness the
    // active block is that of a saddle point, nonsingular but possibly
    // indefinite.
    const unsigned int a = index.size();
    block.resize(a * a);
    for (unsigned int i = 0; i < a; ++i)
      for (unsigned int j = 0; j < a; ++j)
        block[i * a + j] = W[index[i] * m + index[j]];
    if (!lu_factorize(block, a, pivot))
      return false;
    lu_solve(block, a, pivot, rhs.data());
    return true;
  }



  double
  ContactLCP::error(const std::vector<double> &W,
                    const std::vector<double> &q,
                    const std::vector<double> &lambda)
  {
    const unsigned int m = q.size();
    w.resize(m);
    double worst = 0, diagonal = 0;
    for (unsigned int i = 0; i < m; ++i)
      diagonal = std::max(diagonal, W[i * m + i]);
    for (unsigned int i = 0; i < m; ++i)
      {
        double s = q[i];
        for (unsigned int j = 0; j < m; ++j)
          s += W[i * m + j] * lambda[j];
        w[i] = s;
        // A force is turned into the gap it would open (W_ii lambda) so
        // that both sides of the complementarity compare as lengths.
        const double f = diagonal * lambda[i];
        worst          = std::max({worst, -f, -s, std::min(f, s)});
      }
    return worst;
  }



  bool
  ContactLCP::solve(const std::vector<double> &W,
                    const std::vector<double> &q,
                    std::vector<double>       &lambda,
                    const double               tolerance,
                    const bool                 positive_definite)
  {
    const unsigned int m = q.size();
    iterations = sweeps = 0;
    lambda.resize(m, 0.0);
    active.assign(m, 0);
    error(W, q, lambda);
    for (unsigned int i = 0; i < m; ++i)
      active[i] = lambda[i] > 0 || w[i] < 0;
    double best_error = std::numeric_limits<double>::max();
    // Each iteration: the forces of the active nodes close their gaps,
    // the others carry none; then nodes with a negative force leave and
    // nodes left inside the sphere join.
    for (; iterations < 4 * m + 10; ++iterations)
      {
        index.clear();
        for (unsigned int i = 0; i < m; ++i)
          if (active[i])
            index.push_back(i);
        rhs.resize(index.size());
        for (unsigned int i = 0; i < index.size(); ++i)
          rhs[i] = -q[index[i]];
        if (!solve_active(W, m))
          break;
        std::fill(lambda.begin(), lambda.end(), 0.0);
        for (unsigned int i = 0; i < index.size(); ++i)
          lambda[index[i]] = rhs[i];
        const double e = error(W, q, lambda);
        if (e < best_error)
          best_error = e, best = lambda;
        bool changed = false;
        for (unsigned int i = 0; i < m; ++i)
          {
            const bool now = active[i] ? lambda[i] > 0 : w[i] < -tolerance;
            changed        = changed || now != bool(active[i]);
            active[i]      = now;
          }
        if (!changed)
          break;
      }
    if (best.size() == m)
      lambda = best;
    else
      std::fill(lambda.begin(), lambda.end(), 0.0);
    if (best_error <= tolerance || !positive_definite)
      return best_error <= tolerance;
    // Projected Gauss-Seidel from the best iterate: converges for any
    // positive definite W, slowly where the nodes are strongly coupled.
    for (; sweeps < 2000; ++sweeps)
      {
        for (unsigned int i = 0; i < m; ++i)
          {
            double s = q[i];
            for (unsigned int j = 0; j < m; ++j)
              s += W[i * m + j] * lambda[j];
            lambda[i] = std::max(0.0, lambda[i] - s / W[i * m + i]);
          }
        if (sweeps % 10 == 9 && error(W, q, lambda) <= tolerance)
          return true;
      }
    return error(W, q, lambda) <= tolerance;
  }
} // namespace palpate
