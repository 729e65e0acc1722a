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



  bool
  InverseBlock::compute(const std::vector<double>       &values,
                        const std::vector<unsigned int> &unknowns,
                        std::vector<double>             &inverse)
  {
    const unsigned int n = pattern.n_rows, k = unknowns.size();
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

    terminate(); // the Schur unknowns are fixed at the analysis
    const auto lock = library.lock();
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
} // namespace palpate
