// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

#ifndef palpate_hyperelastic_linear_solver_h
#define palpate_hyperelastic_linear_solver_h

#include <palpate/base/plugins.h>

#include <memory>
#include <string>
#include <vector>

class Epetra_CrsMatrix;
class Epetra_Map;

namespace palpate
{
  namespace Parameters
  {
    struct LinearSolver;
  }

  /**
   * A square sparse matrix pattern in compressed row storage with sorted
   * column indices. palpate's systems are symmetric, so the pattern is
   * symmetric too and serves as compressed column storage as well.
   */
  struct SparsityCSR
  {
    unsigned int              n_rows = 0;
    std::vector<unsigned int> row_start; // n_rows + 1 entries
    std::vector<unsigned int> column;    // row_start[n_rows] entries

    /** Number of stored entries. */
    std::size_t
    n_nonzeros() const
    {
      return column.size();
    }

    /** Position of entry (i, j) in the value array, or -1 if not stored. */
    long
    position(const unsigned int i, const unsigned int j) const;
  };

  /**
   * METIS nested dissection of the graph of @p pattern, as MUMPS's
   * PERM_IN: the 1-based position of each unknown in the pivot order.
   * (Debian's MUMPS is built without METIS and would fall back to AMF.)
   */
  std::vector<int>
  nested_dissection_positions(const SparsityCSR &pattern);

  /**
   * The upper triangle of @p pattern as MUMPS's symmetric coordinate
   * input: 1-based rows @p irn and columns @p jcn, and @p upper, the
   * position of each in the pattern's value array.
   */
  void
  upper_triangle(const SparsityCSR        &pattern,
                 std::vector<int>         &irn,
                 std::vector<int>         &jcn,
                 std::vector<std::size_t> &upper);

  /**
   * The @p n_rhs right-hand sides stored one after the other in @p dense
   * as MUMPS's sparse input (ICNTL(20) = 1): 1-based column pointers, rows
   * and values of their non-zeros. Whether it is worth passing so: at
   * most one entry in 100 non-zero (unit forces at a few nodes, the
   * condensed contact's compliance columns), where MUMPS prunes the
   * forward elimination to the branches of the elimination tree they
   * touch.
   */
  template <typename Number, typename Value>
  bool
  sparse_columns(const std::vector<Number> &dense,
                 const unsigned int         n_rhs,
                 std::vector<int>          &pointer,
                 std::vector<int>          &row,
                 std::vector<Value>        &value)
  {
    const std::size_t n = n_rhs > 0 ? dense.size() / n_rhs : 0;
    pointer.assign(1, 1);
    row.clear();
    value.clear();
    for (unsigned int j = 0; j < n_rhs; ++j)
      {
        for (std::size_t i = 0; i < n; ++i)
          if (const Value v = dense[j * n + i]; v != 0)
            {
              row.push_back(i + 1);
              value.push_back(v);
            }
        pointer.push_back(row.size() + 1);
      }
    return 100 * row.size() <= dense.size();
  }

  /**
   * A sparse direct solver for the symmetric (indefinite) linearised
   * systems of the Newton method. analyze() runs the symbolic analysis
   * (ordering, elimination tree) of a sparsity pattern; factorize() then
   * computes only the numbers, at every Newton iteration. analyze() may be
   * called again for a new pattern: it drops the old analysis and factors.
   *
   * No method throws on a numerical failure: factorize() and solve() return
   * false (with message() set), so that the Newton solver can report a
   * failure point instead of dying. Each instance is used by one thread at a
   * time; different instances may run concurrently.
   */
  class LinearSolver
  {
  public:
    virtual ~LinearSolver() = default;

    /** Symbolic analysis of @p pattern (kept by reference: it must outlive
     * the solver, or the next analyze()). */
    virtual void
    analyze(const SparsityCSR &pattern) = 0;

    /** Numerical factorisation of the matrix with @p values (in the order
     * of the pattern's entries). */
    virtual bool
    factorize(const std::vector<double> &values) = 0;

    /** Solve A x = b in place: @p rhs holds b on entry, x on return. */
    virtual bool
    solve(std::vector<double> &rhs) = 0;

    /**
     * Solve A X = B in place for @p n_rhs right-hand sides stored one
     * after the other in @p block (column-major, n_rows each). The
     * default solves them one by one; MUMPS solves them in one pass over
     * its factors, which is several times cheaper per column than single
     * solves (the triangular solves become matrix-matrix products).
     */
    virtual bool
    solve_many(std::vector<double> &block, const unsigned int n_rhs);

    /**
     * Whether solve() solves A x = b to round-off. False for a
     * mixed-precision solver ("MUMPS single": single-precision factors),
     * whose solve() is only an approximate inverse: the Newton method then
     * uses it as GMRES's preconditioner, never as a solver.
     */
    virtual bool
    exact() const
    {
      return true;
    }

    /** The solver's name and settings, e.g. "MUMPS (LDL^T, METIS)". */
    virtual std::string
    name() const = 0;

    /** Size and cost of the last factorisation, e.g. "factor 2.1e5
     * entries, 3.4e7 flops", where the solver reports them. */
    virtual std::string
    statistics() const
    {
      return "";
    }

    /** What went wrong in the last failed call. */
    const std::string &
    message() const
    {
      return message_;
    }

    /**
     * A solver by scene name, from LinearSolverRegistry ("MUMPS", "MUMPS
     * single", "UMFPACK", "KLU", "Amesos MUMPS", "Amesos KLU", or one
     * registered elsewhere) with its own entries at their defaults;
     * @p ordering is the shared entry Linear solver / Ordering (MUMPS's
     * fill-reducing ordering; "by size" is AMF here).
     */
    static std::unique_ptr<LinearSolver>
    create(const std::string &name, const std::string &ordering);

    /**
     * The solver @p p names for a system of @p n_equations (Solver = by
     * size chooses by it), with its own entries from the scene. A value
     * the plug-in refuses throws Plugins::EntryError.
     */
    static std::unique_ptr<LinearSolver>
    create(const Parameters::LinearSolver &p, const unsigned int n_equations);

  protected:
    std::string message_;
  };

  /**
   * The linear solvers are plug-ins (doc/extending.md): `Linear solver /
   * Solver` chooses one by name; its own entries are in `Linear solver /
   * <its name>`, the shared ones (Ordering) in Parameters::LinearSolver,
   * the context its factory gets. Its file ends with
   *
   *     PALPATE_REGISTER_LINEAR_SOLVER(Pardiso, "Pardiso", "one line")
   *
   * where the class has `static void declare_parameters(ParameterHandler
   * &)` and `static std::unique_ptr<LinearSolver> create(const
   * ParameterHandler &own, const Parameters::LinearSolver &shared)`.
   */
  using LinearSolverRegistry =
    Plugins::Registry<LinearSolver, Parameters::LinearSolver>;

  /**
   * For solvers built on Trilinos (Amesos; the benchmarks' multigrid): an
   * Epetra matrix on @p map holding @p pattern's entries, all zero, filled
   * complete. Its column map is its row map, so the local column indices
   * are the pattern's, and a value array in the pattern's order is copied
   * in row by row.
   */
  std::unique_ptr<Epetra_CrsMatrix>
  epetra_matrix(const SparsityCSR &pattern, const Epetra_Map &map);
  extern template class Plugins::Registry<LinearSolver,
                                          Parameters::LinearSolver>;

/** Register the linear solver @p classname as @p name (the registry, and
 * its declaration for the scene's Linear solver subsection). */
#define PALPATE_REGISTER_LINEAR_SOLVER(classname, name, description) \
  PALPATE_REGISTER_DECLARED_PLUGIN(::palpate::LinearSolverRegistry,  \
                                   "linear solver",                  \
                                   classname,                        \
                                   name,                             \
                                   description)
} // namespace palpate

#endif
