// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

#ifndef palpate_hyperelastic_inverse_block_h
#define palpate_hyperelastic_inverse_block_h

#include <palpate/hyperelastic/linear_solver.h>
#include <palpate/hyperelastic/mumps_library.h>

#include <string>
#include <vector>

namespace palpate
{
  /**
   * The block (A^-1)_SS of the inverse of a sparse symmetric matrix A on a
   * few of its unknowns S: a contact patch's compliance.
   *
   * MUMPS eliminates every other unknown and returns the Schur complement
   * S_A = A_SS - A_SI A_II^-1 A_IS (ICNTL(19)), whose inverse is that
   * block. For k unknowns this is one factorisation with S ordered last
   * and a dense k x k inversion, where the block from a full factorisation
   * takes k right-hand sides through the whole triangular factors: on the
   * shipped liver's patches (180-330 unknowns) the solves alone took
   * 120-150 ms, twice a factorisation (doc/benchmarks/contact-patch.md).
   *
   * The Schur unknowns are fixed by MUMPS's analysis, so each call
   * analyses anew (the matrix's METIS ordering, computed once, with S
   * moved last: about 10 ms on the liver). Its own MUMPS instance, in
   * single precision (half the time of double, as for the Newton steps'
   * factors; the patch keeps H in single precision anyway): the caller's
   * factors stay as they are.
   * Not thread-safe; one per state solver.
   */
  class InverseBlock
  {
  public:
    /** For matrices of @p pattern (kept by reference: it must outlive
     * this). */
    explicit InverseBlock(const SparsityCSR &pattern);
    ~InverseBlock();

    /**
     * (A^-1)_SS for the matrix with @p values (in the pattern's order) and
     * the distinct @p unknowns S (0-based), into @p inverse (row-major,
     * k x k in the order of @p unknowns). False, with message(), if A is
     * singular or the block is not positive definite (a compliance of a
     * stable state is).
     */
    bool
    compute(const std::vector<double>       &values,
            const std::vector<unsigned int> &unknowns,
            std::vector<double>             &inverse);

    const std::string &
    message() const;

  private:
    void
    terminate();

    const SparsityCSR       &pattern;
    MumpsLibrary::Lease      library;
    SMUMPS_STRUC_C           id          = {};
    bool                     initialized = false;
    std::vector<int>         irn, jcn, nested_dissection, permutation;
    std::vector<int>         schur_list;
    std::vector<std::size_t> upper;
    std::vector<float>       entries, schur;
    std::vector<double>      schur_inverse;
    std::string              message_;
  };
} // namespace palpate

#endif
