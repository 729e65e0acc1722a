// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

#include <palpate/hyperelastic/inverse_block.h>

#include <algorithm>
#include <cmath>

extern "C"
{
  // LAPACK (OpenBLAS's): Cholesky factorisation and inverse.
  void
  dpotrf_(const char *uplo, const int *n, double *a, const int *lda, int *info);
  void
  dpotri_(const char *uplo, const int *n, double *a, const int *lda, int *info);
  void
  dgemm_(const char   *transa,
         const char   *transb,
         const int    *m,
         const int    *n,
         const int    *k,
         const double *alpha,
         const double *a,
         const int    *lda,
         const double *b,
         const int    *ldb,
         const double *beta,
         double       *c,
         const int    *ldc);
}

namespace palpate
{
  InverseBlock::InverseBlock(const SparsityCSR &pattern)
    : pattern(pattern)
    , library(MumpsLibrary::acquire())
  {
    upper_triangle(pattern, irn, jcn, upper);
    entries.resize(upper.size());
    nested_dissection = nested_dissection_positions(pattern);
  }



  InverseBlock::~InverseBlock()
  {
    terminate();
  }



  void
  InverseBlock::terminate()
  {
    factored = false;
    if (!initialized)
      return;
    const auto lock = library.lock();
    id.job          = -2;
    library.call(&id);
    initialized = false;
    id          = {};
  }



  const std::string &
  InverseBlock::message() const
  {
    return message_;
  }



  // compute(), a step: MUMPS's order of the unknowns, the METIS order of
  // the others first and the block's @p unknowns last, in their order.
  void
  InverseBlock::order_block_last(const std::vector<unsigned int> &unknowns)
  {
    const unsigned int n = pattern.n_rows, k = unknowns.size();
    // The METIS order of the other unknowns, then S in its given order
    // (MUMPS wants PERM_IN(LISTVAR_SCHUR(i)) = n - k + i).
    schur_list.resize(k);
    std::vector<char> in_block(n, 0);
    for (unsigned int i = 0; i < k; ++i)
      {
        schur_list[i]         = unknowns[i] + 1;
        in_block[unknowns[i]] = 1;
      }
    std::vector<unsigned int> order(n);
    for (unsigned int i = 0; i < n; ++i)
      order[nested_dissection[i] - 1] = i;
    permutation.resize(n);
    unsigned int next = 1;
    for (const unsigned int i : order)
      if (!in_block[i])
        permutation[i] = next++;
    for (unsigned int i = 0; i < k; ++i)
      permutation[unknowns[i]] = n - k + 1 + i;
  }



  // compute(), a step: MUMPS's analysis and factorisation with the Schur
  // complement S_A of the last @p k unknowns (the library's lock held by
  // the caller); false, with the message, if either fails.
  bool
  InverseBlock::factorize_with_schur(const unsigned int k)
  {
    const unsigned int n = pattern.n_rows;
    if (!library.initialize(id))
      {
        message_ = "MUMPS could not be initialised, INFOG(1) = " +
                   std::to_string(id.infog[0]);
        return false;
      }
    initialized = true;
    id.icntl[6] = 1; // ICNTL(7): the ordering given in PERM_IN
    // ICNTL(19) = 3: the complete Schur complement, centralised by
    // columns (a 1 x 1 process grid).
    id.icntl[18]     = 3;
    id.size_schur    = k;
    id.listvar_schur = schur_list.data();
    id.nprow = id.npcol = 1;
    id.mblock = id.nblock = 100;
    id.n                  = n;
    id.nnz                = irn.size();
    id.irn                = irn.data();
    id.jcn                = jcn.data();
    id.perm_in            = permutation.data();
    id.job                = 1;
    library.call(&id);
    if (id.infog[0] < 0)
      {
        message_ = "MUMPS analysis with a Schur complement failed, INFOG(1) "
                   "= " +
                   std::to_string(id.infog[0]);
        return false;
      }
    schur.assign(std::size_t(k) * k, 0.0);
    id.schur_lld = k;
    id.schur     = schur.data();
    id.a         = entries.data();
    if (!library.factorize(id))
      {
        message_ = id.infog[0] == -10 ?
                     "MUMPS: the matrix is numerically singular" :
                     "MUMPS factorisation with a Schur complement failed, "
                     "INFOG(1) = " +
                       std::to_string(id.infog[0]);
        return false;
      }
    return true;
  }



  // compute(), a step: @p inverse = S_A^-1 (k x k, full) from the Schur
  // complement; false, with the message, if S_A is not positive definite.
  bool
  InverseBlock::invert_schur(const unsigned int k, std::vector<double> &inverse)
  {
    // (A^-1)_SS = S_A^-1 by LAPACK's Cholesky (S_A is symmetric positive
    // definite for a stable state's compliance) and its inverse: blocked
    // kernels for the k^3 flops, in double.
    schur_inverse.assign(schur.begin(), schur.end());
    const int size = k;
    int       info = 0;
    dpotrf_("U", &size, schur_inverse.data(), &size, &info);
    if (info != 0)
      {
        message_ = "the compliance block is not positive definite";
        return false;
      }
    dpotri_("U", &size, schur_inverse.data(), &size, &info);
    if (info != 0)
      {
        message_ = "the compliance block could not be inverted";
        return false;
      }
    // The upper triangle (column-major) holds the inverse.
    for (unsigned int c = 0; c < k; ++c)
      for (unsigned int r = 0; r <= c; ++r)
        inverse[std::size_t(r) * k + c] = inverse[std::size_t(c) * k + r] =
          schur_inverse[std::size_t(c) * k + r];
    return true;
  }



  bool
  InverseBlock::compute(const std::vector<double>       &values,
                        const std::vector<unsigned int> &unknowns,
                        std::vector<double>             &inverse)
  {
    const unsigned int n = pattern.n_rows, k = unknowns.size();
    factored = false; // whatever happens, not the old factors
    inverse.assign(std::size_t(k) * k, 0.0);
    if (k == 0)
      return true;
    if (k >= n)
      {
        message_ = "the block is the whole matrix";
        return false;
      }
    for (std::size_t e = 0; e < upper.size(); ++e)
      entries[e] = static_cast<float>(values[upper[e]]);
    for (const float v : entries)
      if (!std::isfinite(v))
        {
          message_ = "the matrix has NaN, infinite or (in single precision) "
                     "too large entries";
          return false;
        }

    order_block_last(unknowns);

    terminate(); // the Schur unknowns are fixed at the analysis
    const auto lock = library.lock();
    if (!factorize_with_schur(k))
      return false;

    if (!invert_schur(k, inverse))
      return false;
    block_inverse = inverse;
    factored      = true;
    return true;
  }



  bool
  InverseBlock::solve_many(std::vector<double> &block, const unsigned int n_rhs)
  {
    if (!factored)
      {
        message_ = "no factors to solve with";
        return false;
      }
    if (n_rhs == 0)
      return true;
    const int n = pattern.n_rows, k = id.size_schur, columns = n_rhs;
    rhs.assign(block.begin(), block.end());
    reduced.resize(std::size_t(k) * n_rhs);
    // Right-hand sides that are mostly zero (the condensed contact's
    // compliance columns, all on the patch's nodes) go in as a sparse
    // matrix: for forces on S alone the forward elimination visits none
    // but S's branch.
    const bool sparse =
      sparse_columns(rhs, n_rhs, sparse_pointer, sparse_row, sparse_value);
    if (sparse_row.empty())
      return true; // B = 0 (which MUMPS refuses with a reduced RHS)
    const auto lock = library.lock();
    id.nrhs         = columns;
    id.lrhs         = n;
    id.rhs          = rhs.data();
    id.redrhs       = reduced.data();
    id.lredrhs      = k;
    if (sparse)
      {
        id.icntl[19]   = 1;
        id.nz_rhs      = sparse_row.size();
        id.irhs_ptr    = sparse_pointer.data();
        id.irhs_sparse = sparse_row.data();
        id.rhs_sparse  = sparse_value.data();
      }
    // The forward elimination, which leaves the right-hand sides
    // condensed on S in REDRHS (ICNTL(26) = 1); then the Schur unknowns'
    // solution x_S = S_A^-1 y_S by the block in double; then the backward
    // substitution from it (ICNTL(26) = 2).
    id.icntl[25] = 1;
    id.job       = 3;
    library.call(&id);
    if (id.infog[0] >= 0)
      {
        reduced_double.assign(reduced.begin(), reduced.end());
        solution_double.resize(reduced_double.size());
        const double one = 1, zero = 0;
        dgemm_("N",
               "N",
               &k,
               &columns,
               &k,
               &one,
               block_inverse.data(),
               &k,
               reduced_double.data(),
               &k,
               &zero,
               solution_double.data(),
               &k);
        reduced.assign(solution_double.begin(), solution_double.end());
        id.icntl[25] = 2;
        library.call(&id);
      }
    id.icntl[25] = 0;
    id.icntl[19] = 0;
    id.nrhs      = 1;
    if (id.infog[0] < 0)
      {
        message_ = "MUMPS solve with a Schur complement failed, INFOG(1) = " +
                   std::to_string(id.infog[0]);
        return false;
      }
    for (std::size_t i = 0; i < block.size(); ++i)
      {
        block[i] = rhs[i];
        if (!std::isfinite(block[i]))
          {
            message_ = "MUMPS returned a non-finite solution";
            return false;
          }
      }
    return true;
  }



  SchurFactors::SchurFactors(InverseBlock &block)
    : block(block)
  {}



  void
  SchurFactors::analyze(const SparsityCSR &)
  {}



  bool
  SchurFactors::factorize(const std::vector<double> &)
  {
    message_ = "the factors of a Schur complement are made by "
               "InverseBlock::compute()";
    return false;
  }



  bool
  SchurFactors::solve(std::vector<double> &rhs)
  {
    return solve_many(rhs, 1);
  }



  bool
  SchurFactors::solve_many(std::vector<double> &columns,
                           const unsigned int   n_rhs)
  {
    if (block.solve_many(columns, n_rhs))
      return true;
    message_ = block.message();
    return false;
  }



  bool
  SchurFactors::exact() const
  {
    return false;
  }



  std::string
  SchurFactors::name() const
  {
    return "MUMPS in single precision with a Schur complement on the "
           "contact patch";
  }
} // namespace palpate
