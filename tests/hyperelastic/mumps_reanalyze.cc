// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

// A sparse direct solver can analyse a new sparsity pattern after it has
// factorised and solved with an old one: analyze, factorize and solve a
// tridiagonal system (n = 6), then a 2-D five-point system (n = 16), then
// the first system again. Each solve must be exact to round-off (to 1e-6,
// single precision's round-off on these small, well-conditioned systems,
// for MUMPS single, whose solve() is a preconditioner); before
// the fix, MUMPS kept the first pattern's entries (summing duplicates, or
// reading entries of the wrong pattern) and initialised a second MUMPS
// instance over the first. Every solver is checked, MUMPS above all.

#include <palpate/hyperelastic/linear_solver.h>

#include <cmath>
#include <map>
#include <utility>

#include "../tests.h"

namespace
{
  /** A symmetric positive definite system: pattern, values, solution. */
  struct System
  {
    palpate::SparsityCSR pattern;
    std::vector<double>  values;
  };

  /** Build a system from its rows: column -> value, sorted by column. */
  System
  from_rows(const std::vector<std::map<unsigned int, double>> &rows)
  {
    System s;
    s.pattern.n_rows = rows.size();
    s.pattern.row_start.push_back(0);
    for (const auto &row : rows)
      {
        for (const auto &[j, a] : row)
          {
            s.pattern.column.push_back(j);
            s.values.push_back(a);
          }
        s.pattern.row_start.push_back(s.pattern.column.size());
      }
    return s;
  }

  /** -u'' + u on n points: tridiagonal, diagonal 3, off-diagonal -1. */
  System
  tridiagonal(const unsigned int n)
  {
    std::vector<std::map<unsigned int, double>> rows(n);
    for (unsigned int i = 0; i < n; ++i)
      {
        rows[i][i] = 3;
        if (i > 0)
          rows[i][i - 1] = -1;
        if (i + 1 < n)
          rows[i][i + 1] = -1;
      }
    return from_rows(rows);
  }

  /** The five-point Laplacian plus identity on an m x m grid. */
  System
  five_point(const unsigned int m)
  {
    std::vector<std::map<unsigned int, double>> rows(m * m);
    for (unsigned int y = 0; y < m; ++y)
      for (unsigned int x = 0; x < m; ++x)
        {
          const unsigned int i = y * m + x;
          rows[i][i]           = 5;
          if (x > 0)
            rows[i][i - 1] = -1;
          if (x + 1 < m)
            rows[i][i + 1] = -1;
          if (y > 0)
            rows[i][i - m] = -1;
          if (y + 1 < m)
            rows[i][i + m] = -1;
        }
    return from_rows(rows);
  }

  /** y = A x. */
  std::vector<double>
  multiply(const System &s, const std::vector<double> &x)
  {
    std::vector<double> y(s.pattern.n_rows, 0.0);
    for (unsigned int i = 0; i < s.pattern.n_rows; ++i)
      for (unsigned int k = s.pattern.row_start[i];
           k < s.pattern.row_start[i + 1];
           ++k)
        y[i] += s.values[k] * x[s.pattern.column[k]];
    return y;
  }

  double
  norm(const std::vector<double> &v)
  {
    double sum = 0;
    for (const double x : v)
      sum += x * x;
    return std::sqrt(sum);
  }

  /** Analyse, factorise and solve @p s; log the relative residual. */
  void
  analyze_and_solve(palpate::LinearSolver &solver,
                    const System          &s,
                    const std::string     &what)
  {
    std::vector<double> exact(s.pattern.n_rows);
    for (unsigned int i = 0; i < exact.size(); ++i)
      exact[i] = 1.0 + i;
    const std::vector<double> b = multiply(s, exact);
    std::vector<double>       x = b;
    deallog << "  " << what << " (n = " << s.pattern.n_rows << "): ";
    try
      {
        solver.analyze(s.pattern);
      }
    catch (const std::exception &e)
      {
        deallog << "analysis threw: " << e.what() << std::endl;
        return;
      }
    if (!solver.factorize(s.values))
      {
        deallog << "factorisation failed: " << solver.message() << std::endl;
        return;
      }
    if (!solver.solve(x))
      {
        deallog << "solve failed: " << solver.message() << std::endl;
        return;
      }
    std::vector<double> r = multiply(s, x);
    for (unsigned int i = 0; i < r.size(); ++i)
      r[i] -= b[i];
    const double tolerance = solver.exact() ? 1e-12 : 1e-6;
    deallog << "residual < " << (solver.exact() ? "1e-12" : "1e-6") << ": "
            << (norm(r) / norm(b) < tolerance ? "yes" : "NO") << std::endl;
  }
} // namespace

int
main(int argc, char **argv)
{
  palpate::Environment env(argc, argv);
  initlog();

  // The patterns outlive the solvers (LinearSolver::analyze keeps them).
  const System first = tridiagonal(6), second = five_point(4);
  for (const auto &[name, ordering] : every_linear_solver())
    {
      const auto solver = palpate::LinearSolver::create(name, ordering);
      deallog << name << " (" << ordering << ")" << std::endl;
      analyze_and_solve(*solver, first, "first analysis, tridiagonal");
      analyze_and_solve(*solver, second, "second analysis, five-point");
      analyze_and_solve(*solver, first, "third analysis, tridiagonal again");
    }
}
