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
   * The factors stay until the next compute(): solve_many() solves with
   * them (MUMPS condenses the right-hand sides on S, the block solves
   * there, MUMPS expands), so one partial factorisation of a state's
   * tangent gives both its patch's compliance and the factors its Newton
   * steps, and the next state's, iterate on.
   *
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

    /**
     * Solve A X = B in place for @p n_rhs right-hand sides stored one
     * after the other in @p block (n rows each), with the factors of the
     * last successful compute(): single precision, like the Newton steps'
     * own factors. False, with message(), if there are none or MUMPS fails.
     */
    bool
    solve_many(std::vector<double> &block, unsigned int n_rhs);

    const std::string &
    message() const;

  private:
    void
    terminate();

    /** compute(): MUMPS's order of the unknowns, in permutation and
     * schur_list: the METIS order of the others, then @p unknowns. */
    void
    order_block_last(const std::vector<unsigned int> &unknowns);

    /** compute(): MUMPS's analysis and factorisation with the Schur
     * complement of the last @p k unknowns, with the library's lock held;
     * false (message() says why) if either fails. */
    bool
    factorize_with_schur(const unsigned int k);

    /** compute(): the k x k @p inverse of the Schur complement, by
     * LAPACK's Cholesky; false (message() says why) if it has none. */
    bool
    invert_schur(const unsigned int k, std::vector<double> &inverse);

    const SparsityCSR       &pattern;
    MumpsLibrary::Lease      library;
    SMUMPS_STRUC_C           id          = {};
    bool                     initialized = false;
    bool                     factored    = false;
    std::vector<int>         irn, jcn, nested_dissection, permutation;
    std::vector<int>         schur_list;
    std::vector<std::size_t> upper;
    std::vector<float>       entries, schur;
    std::vector<double>      schur_inverse, block_inverse;
    // solve_many()'s work: the right-hand sides, their condensed parts and
    // the block's solution there.
    std::vector<float>  rhs, reduced, sparse_value;
    std::vector<int>    sparse_pointer, sparse_row;
    std::vector<double> reduced_double, solution_double;
    std::string         message_;
  };


  /**
   * An InverseBlock's factors seen as a LinearSolver, for the code that
   * solves through one (the Newton steps, CondensedContact's compliance
   * columns). Solves only: InverseBlock::compute() makes the factors, and
   * factorize() here refuses. Not exact (single precision), like the
   * Newton steps' own factors from 5,000 equations.
   */
  class SchurFactors : public LinearSolver
  {
  public:
    explicit SchurFactors(InverseBlock &block);

    void
    analyze(const SparsityCSR &pattern) override;

    bool
    factorize(const std::vector<double> &values) override;

    bool
    solve(std::vector<double> &rhs) override;

    bool
    solve_many(std::vector<double> &block, unsigned int n_rhs) override;

    bool
    exact() const override;

    std::string
    name() const override;

  private:
    InverseBlock &block;
  };
} // namespace palpate

#endif
