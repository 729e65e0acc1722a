// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

// AndersonAcceleration on the iteration the condensed path makes: steps
// x += P (b - A x) with P the inverse of an older matrix A0, where A =
// A0 + U U^T differs from it in a few modes (here 3: a low-rank change,
// as a tangent's between neighbouring states is mostly smooth). The
// plain iteration converges at the rate of those modes; Anderson with
// depth 4 combines the steps into GMRES's iterate and needs about as many
// steps as there are modes. Both must reach |b - A x| <= 1e-10 |b|; the
// accelerated iteration in at most 8 steps, and a reset after two (the
// caller's answer to new factors) must not keep it from converging.

#include <palpate/hyperelastic/anderson_acceleration.h>

#include <cmath>

#include "../tests.h"

namespace
{
  const unsigned int n = 60, rank = 3;

  /** A x for A = diag(1 + i) + U U^T, U's columns smooth. */
  std::vector<double>
  multiply(const std::vector<double> &x)
  {
    std::vector<double> y(n);
    for (unsigned int i = 0; i < n; ++i)
      y[i] = (1.0 + i) * x[i];
    for (unsigned int r = 0; r < rank; ++r)
      {
        double d = 0;
        for (unsigned int i = 0; i < n; ++i)
          d += std::sin((r + 1) * 0.05 * i) * x[i];
        for (unsigned int i = 0; i < n; ++i)
          y[i] += 1.4 * std::sin((r + 1) * 0.05 * i) * d / n * (1 + i);
      }
    return y;
  }

  /** Steps until |b - A x| <= 1e-10 |b| (at most 200); reset after
   * @p reset_at steps if not 0. */
  unsigned int
  iterate(palpate::AndersonAcceleration &anderson,
          const unsigned int             reset_at = 0)
  {
    std::vector<double> b(n), x(n, 0.0), f(n);
    double              nb = 0;
    for (unsigned int i = 0; i < n; ++i)
      {
        b[i] = std::cos(0.3 * i);
        nb += b[i] * b[i];
      }
    nb = std::sqrt(nb);
    for (unsigned int k = 0; k < 200; ++k)
      {
        const std::vector<double> ax = multiply(x);
        double                    r  = 0;
        for (unsigned int i = 0; i < n; ++i)
          {
            f[i] = (b[i] - ax[i]) / (1.0 + i); // P = A0^-1
            r += (b[i] - ax[i]) * (b[i] - ax[i]);
          }
        if (std::sqrt(r) <= 1e-10 * nb)
          return k;
        if (k == reset_at && reset_at > 0)
          anderson.reset();
        anderson.accelerate(x, f);
        for (unsigned int i = 0; i < n; ++i)
          x[i] += f[i];
      }
    return 200;
  }
} // namespace

int
main()
{
  initlog();
  palpate::AndersonAcceleration plain(0), accelerated(4), restarted(4);
  const unsigned int            p = iterate(plain);
  const unsigned int            a = iterate(accelerated);
  const unsigned int            r = iterate(restarted, 2);
  deallog << "plain steps converge: " << (p < 200 ? "yes" : "NO")
          << ", in more than 20 steps: " << (p > 20 ? "yes" : "NO")
          << std::endl;
  deallog << "Anderson depth 4: " << a
          << " steps (at most 8: " << (a <= 8 ? "yes" : "NO") << ")"
          << std::endl;
  deallog << "reset after 2 steps: converges: " << (r < 200 ? "yes" : "NO")
          << ", at most 8 steps more than without: "
          << (r <= a + 8 ? "yes" : "NO") << std::endl;
}
