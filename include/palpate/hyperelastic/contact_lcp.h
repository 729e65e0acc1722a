// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

#ifndef palpate_hyperelastic_contact_lcp_h
#define palpate_hyperelastic_contact_lcp_h

#include <vector>

namespace palpate
{
  /** LU factorisation with partial pivoting of the m x m row-major @p A in
   * place, the row exchanges in @p pivot (m entries); false if A is
   * singular. No allocation: the haptic loop uses it too. */
  bool
  lu_factorize(double *A, const unsigned int m, unsigned int *pivot) noexcept;

  /** Solve A x = b in place of @p b with the factors of lu_factorize(). */
  void
  lu_solve(const double       *LU,
           const unsigned int  m,
           const unsigned int *pivot,
           double             *b) noexcept;

  /** lu_factorize() for vectors; @p pivot is resized to m. */
  bool
  lu_factorize(std::vector<double>       &A,
               const unsigned int         m,
               std::vector<unsigned int> &pivot);

  /** lu_solve() for vectors. */
  void
  lu_solve(const std::vector<double>       &LU,
           const unsigned int               m,
           const std::vector<unsigned int> &pivot,
           double                          *b);

  /**
   * The frictionless contact problem on a few nodes, condensed onto their
   * compliance: find lambda >= 0 with w = q + W lambda >= 0 and
   * lambda_i w_i = 0 (a linear complementarity problem, LCP). W (m x m,
   * row-major) is the compliance C K^-1 C^T of the contact candidates'
   * normal directions (m/N), q their gaps (m) if no force acted, lambda
   * their contact forces (N), w the gaps they leave.
   *
   * Solved by the primal-dual active-set method (Hintermueller, Ito and
   * Kunisch: a semi-smooth Newton method on min(lambda, w) = 0), warm
   * started from @p lambda: each iteration one LU solve on the active
   * block. With a warm start from the last Newton step it takes one or two
   * iterations. Where it cycles (W far from an M-matrix) and W is
   * positive definite, projected Gauss-Seidel from its best iterate
   * finishes. Everything is reused from call to call: no allocation once
   * the sizes were seen.
   */
  class ContactLCP
  {
  public:
    /**
     * Solve for @p lambda (in: a start, e.g. the last forces; out: the
     * solution) with gaps left within @p tolerance (m). False if neither
     * method met the tolerance (lambda is then the best found).
     */
    bool
    solve(const std::vector<double> &W,
          const std::vector<double> &q,
          std::vector<double>       &lambda,
          const double               tolerance,
          const bool                 positive_definite = true);

    /** Active-set iterations of the last solve (and Gauss-Seidel sweeps
     * if it needed them). */
    unsigned int iterations = 0, sweeps = 0;

  private:
    /** Solve W_AA x = b_A in place (in rhs) on the active set; false if
     * the block is singular. */
    bool
    solve_active(const std::vector<double> &W, const unsigned int m);

    /** Largest complementarity error of lambda: max of -lambda_i, -w_i
     * and min(lambda_i, w_i) scaled to a gap (m). */
    double
    error(const std::vector<double> &W,
          const std::vector<double> &q,
          const std::vector<double> &lambda);

    std::vector<char>         active;
    std::vector<unsigned int> index, pivot;
    std::vector<double>       block, rhs, w, best;
  };
} // namespace palpate

#endif
