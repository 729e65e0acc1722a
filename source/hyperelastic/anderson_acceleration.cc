// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

#include <palpate/hyperelastic/anderson_acceleration.h>

#include <cmath>

namespace palpate
{
  AndersonAcceleration::AndersonAcceleration(const unsigned int depth)
    : max_depth(depth)
  {}



  void
  AndersonAcceleration::reset()
  {
    has_previous = false;
    dX.clear();
    dF.clear();
  }



  unsigned int
  AndersonAcceleration::depth() const
  {
    return max_depth;
  }



  bool
  AndersonAcceleration::accelerate(const std::vector<double> &x,
                                   std::vector<double>       &f)
  {
    if (max_depth == 0)
      return false;
    const std::size_t n = x.size();
    if (has_previous)
      {
        // The newest differences last; the oldest dropped beyond depth.
        if (dX.size() == max_depth)
          {
            dX.erase(dX.begin());
            dF.erase(dF.begin());
          }
        dX.emplace_back(n);
        dF.emplace_back(n);
        for (std::size_t i = 0; i < n; ++i)
          {
            dX.back()[i] = x[i] - x_previous[i];
            dF.back()[i] = f[i] - f_previous[i];
          }
      }
    x_previous   = x;
    f_previous   = f;
    has_previous = true;
    if (dF.empty())
      return false;

    // gamma = argmin |f - dF gamma| by modified Gram-Schmidt on dF's
    // columns, the newest first; a column nearly in the span of the
    // newer ones (a step that repeated an earlier one) is left out, as
    // it would only amplify round-off.
    const unsigned int m = dF.size();
    Q.resize(m);
    R.assign(m * m, 0.0);
    std::vector<unsigned int> kept;
    for (unsigned int c = 0; c < m; ++c)
      {
        const unsigned int   j = m - 1 - c;
        std::vector<double> &q = Q[kept.size()];
        q                      = dF[j];
        double n0              = 0;
        for (const double v : q)
          n0 += v * v;
        for (unsigned int k = 0; k < kept.size(); ++k)
          {
            double r = 0;
            for (std::size_t i = 0; i < n; ++i)
              r += Q[k][i] * q[i];
            R[k * m + kept.size()] = r;
            for (std::size_t i = 0; i < n; ++i)
              q[i] -= r * Q[k][i];
          }
        double nq = 0;
        for (const double v : q)
          nq += v * v;
        if (!(nq > 1e-16 * n0) || n0 == 0)
          continue;
        nq                               = std::sqrt(nq);
        R[kept.size() * m + kept.size()] = nq;
        for (double &v : q)
          v /= nq;
        kept.push_back(j);
      }
    if (kept.empty())
      return false;
    // R gamma = Q^T f, back substitution.
    const unsigned int k = kept.size();
    gamma.assign(k, 0.0);
    for (unsigned int a = 0; a < k; ++a)
      for (std::size_t i = 0; i < n; ++i)
        gamma[a] += Q[a][i] * f[i];
    for (int a = int(k) - 1; a >= 0; --a)
      {
        for (unsigned int b = a + 1; b < k; ++b)
          gamma[a] -= R[a * m + b] * gamma[b];
        gamma[a] /= R[a * m + a];
      }
    for (unsigned int a = 0; a < k; ++a)
      {
        const unsigned int j = kept[a];
        for (std::size_t i = 0; i < n; ++i)
          f[i] -= gamma[a] * (dX[j][i] + dF[j][i]);
      }
    return true;
  }
} // namespace palpate
