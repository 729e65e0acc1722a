// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

#include <palpate/base/exceptions.h>
#include <palpate/base/plugins.templates.h>
#include <palpate/hyperelastic/linear_solver.h>
#include <palpate/hyperelastic/mumps_library.h>
#include <palpate/scene/parameters.h>

#include <Amesos.h>
#include <Amesos_BaseSolver.h>
#include <Epetra_CrsMatrix.h>
#include <Epetra_LinearProblem.h>
#include <Epetra_Map.h>
#include <Epetra_MpiComm.h>
#include <Epetra_Vector.h>
#include <dmumps_c.h>
#include <klu.h>
#include <metis.h>
#include <mpi.h>
#include <smumps_c.h>
#include <umfpack.h>

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <map>
#include <mutex>
#include <sstream>

// METIS (GKlib) brackets every call with gk_sigtrap() / gk_siguntrap(),
// which set SIGTERM and SIGABRT to a handler that longjmps back into
// METIS, and then put the previous handler back with signal(): with
// glibc's System V semantics (SA_RESETHAND), so palpate's stop handler
// would come back as a one-shot. A second SIGTERM within the 0.5 s that
// make two deliveries one stop (`timeout` signals a process and its
// group) would then kill `palpate precompute` at once: no stop summary,
// the store's lock left. And a stop signal during METIS would run
// GKlib's longjmp in whatever thread took it. palpate defines
// the two functions itself (the dynamic linker binds libmetis's calls to
// the first definition, and libpalpate is searched before libmetis):
// they keep GKlib's jump-buffer count, which its setjmp indexes, and
// leave the signal dispositions alone. What GKlib loses is turning its
// own fatal errors (out of memory) into a METIS_ERROR return; these
// end the process as they would outside a METIS call.
extern "C"
{
  // GKlib: the calling thread's innermost jump buffer, -1 if none.
  extern thread_local int gk_cur_jbufs;

  int
  gk_sigtrap()
  {
    constexpr int max_jbufs = 128; // GKlib's MAX_JBUFS
    if (gk_cur_jbufs + 1 >= max_jbufs)
      return 0;
    ++gk_cur_jbufs;
    return 1;
  }

  int
  gk_siguntrap()
  {
    if (gk_cur_jbufs == -1)
      return 0;
    --gk_cur_jbufs;
    return 1;
  }
}



namespace palpate
{
  long
  SparsityCSR::position(const unsigned int i, const unsigned int j) const
  {
    const auto begin = column.begin() + row_start[i];
    const auto end   = column.begin() + row_start[i + 1];
    const auto it    = std::lower_bound(begin, end, j);
    return (it != end && *it == j) ? it - column.begin() : -1;
  }



  /**
   * METIS nested dissection of the matrix graph, as MUMPS's PERM_IN: the
   * 1-based position of each unknown in the pivot order. METIS compresses
   * the three DoFs of a node (identical adjacency) by itself.
   */
  std::vector<int>
  nested_dissection_positions(const SparsityCSR &pattern)
  {
    std::vector<idx_t> xadj(1, 0), adjncy;
    for (unsigned int i = 0; i < pattern.n_rows; ++i)
      {
        for (unsigned int k = pattern.row_start[i];
             k < pattern.row_start[i + 1];
             ++k)
          if (pattern.column[k] != i)
            adjncy.push_back(pattern.column[k]);
        xadj.push_back(adjncy.size());
      }
    idx_t              n = pattern.n_rows;
    std::vector<idx_t> perm(n), iperm(n);
    idx_t              options[METIS_NOPTIONS];
    METIS_SetDefaultOptions(options);
    options[METIS_OPTION_NUMBERING] = 0;
    if (METIS_NodeND(&n,
                     xadj.data(),
                     adjncy.data(),
                     nullptr,
                     options,
                     perm.data(),
                     iperm.data()) != METIS_OK)
      throw std::runtime_error("METIS nested dissection failed");
    std::vector<int> position(n);
    for (idx_t i = 0; i < n; ++i)
      position[i] = iperm[i] + 1;
    return position;
  }



  void
  upper_triangle(const SparsityCSR        &pattern,
                 std::vector<int>         &irn,
                 std::vector<int>         &jcn,
                 std::vector<std::size_t> &upper)
  {
    irn.clear();
    jcn.clear();
    upper.clear();
    for (unsigned int i = 0; i < pattern.n_rows; ++i)
      for (unsigned int k = pattern.row_start[i]; k < pattern.row_start[i + 1];
           ++k)
        if (pattern.column[k] >= i)
          {
            irn.push_back(i + 1);
            jcn.push_back(pattern.column[k] + 1);
            upper.push_back(k);
          }
  }



  std::unique_ptr<Epetra_CrsMatrix>
  epetra_matrix(const SparsityCSR &pattern, const Epetra_Map &map)
  {
    std::vector<int> per_row(pattern.n_rows);
    for (unsigned int i = 0; i < pattern.n_rows; ++i)
      per_row[i] = pattern.row_start[i + 1] - pattern.row_start[i];
    auto matrix =
      std::make_unique<Epetra_CrsMatrix>(Copy, map, map, per_row.data(), true);
    for (unsigned int i = 0; i < pattern.n_rows; ++i)
      {
        std::vector<int>    cols(pattern.column.begin() + pattern.row_start[i],
                              pattern.column.begin() +
                                pattern.row_start[i + 1]);
        std::vector<double> zeros(cols.size(), 0.0);
        matrix->InsertMyValues(i, cols.size(), zeros.data(), cols.data());
      }
    matrix->FillComplete();
    return matrix;
  }



  namespace
  {
    template <typename Real>
    bool
    all_finite(const std::vector<Real> &v)
    {
      for (const double x : v)
        if (!std::isfinite(x))
          return false;
      return true;
    }


    // ------------------------------------------------------------------
    // MUMPS through its C interface.
    //
    // Why not Trilinos' Amesos_Mumps (which "Amesos MUMPS" below still
    // offers for comparison): it calls exit() on any MUMPS error, so a
    // singular tangent at a failure point would kill the solver process;
    // its "MatrixType = symmetric" setting never reaches MUMPS (a bug in
    // Amesos 13), so the symmetric LDL^T factorisation, half the work of
    // LU, is unreachable; and it copies the matrix row by row into triplets
    // at every factorisation.
    // ------------------------------------------------------------------
    /** MUMPS in double precision (DMUMPS), the default. */
    struct Double
    {
      using Struct                = DMUMPS_STRUC_C;
      using Real                  = double;
      static constexpr bool exact = true;
    };

    /**
     * MUMPS in single precision (SMUMPS) for a mixed-precision solver: the
     * factors of the tangent in float, applied to double vectors. Half the
     * memory traffic of a solve and twice the flops per cycle of a
     * factorisation's dense kernels, at a relative accuracy of about 1e-7
     * times the condition number: a preconditioner, not a solver, so the
     * Newton method wraps it in GMRES (LinearSolver::exact() is false).
     */
    struct Single
    {
      using Struct                = SMUMPS_STRUC_C;
      using Real                  = float;
      static constexpr bool exact = false;
    };

    template <typename Precision>
    class Mumps : public LinearSolver
    {
    public:
      using Real = typename Precision::Real;

      explicit Mumps(const std::string &ordering)
        : library(MumpsLibrary::acquire())
        , ordering_name(ordering)
      {
        // METIS is not compiled into Debian's MUMPS (it would silently
        // fall back to AMF), so palpate computes the METIS nested
        // dissection itself and hands it over (ICNTL(7) = 1).
        static const std::map<std::string, int> icntl7 = {{"AMD", 0},
                                                          {"METIS", 1},
                                                          {"AMF", 2},
                                                          {"SCOTCH", 3},
                                                          {"PORD", 4},
                                                          {"QAMD", 6},
                                                          {"automatic", 7}};
        const auto                              it     = icntl7.find(ordering);
        if (it == icntl7.end())
          throw std::invalid_argument("unknown MUMPS ordering " + ordering);
        ordering_code = it->second;
      }

      ~Mumps() override
      {
        if (initialized)
          {
            const auto lock = library.lock();
            id.job          = -2;
            library.call(&id);
          }
      }

      void
      analyze(const SparsityCSR &pattern) override
      {
        // A new analysis replaces the old one: forget the old pattern's
        // entries (they would otherwise be kept and summed with the new
        // ones).
        permutation.clear();
        upper_triangle(pattern, irn, jcn, upper);
        values.resize(upper.size());

        const auto lock = library.lock();
        // A new analysis starts from a new MUMPS instance: the old one is
        // terminated first (JOB = -2 frees its analysis and factors).
        // Calling JOB = -1 over a live instance would lose it and all it
        // holds. Running JOB = 1 again on the old instance is allowed by
        // the MUMPS guide, but with Debian's MUMPS 5.5.1 and the AMD
        // ordering the next factorisation of a regular matrix then failed
        // as singular (tests/hyperelastic/mumps_reanalyze); a fresh
        // instance costs microseconds next to an analysis.
        if (initialized)
          {
            id.job = -2;
            library.call(&id);
            initialized = false;
            id          = {};
          }
        initialize();
        id.icntl[6] = ordering_code; // ICNTL(7): fill-reducing ordering

        id.n   = pattern.n_rows;
        id.nnz = irn.size();
        id.irn = irn.data();
        id.jcn = jcn.data();
        id.a   = nullptr; // the values come with factorize()
        id.rhs = nullptr;
        if (ordering_code == 1)
          {
            permutation = nested_dissection_positions(pattern);
            id.perm_in  = permutation.data();
          }
        id.job = 1; // analysis
        library.call(&id);
        if (id.infog[0] < 0)
          throw std::runtime_error("MUMPS analysis failed, INFOG(1) = " +
                                   std::to_string(id.infog[0]));
        static const std::map<int, std::string> used = {{0, "AMD"},
                                                        {1, "METIS"},
                                                        {2, "AMF"},
                                                        {3, "SCOTCH"},
                                                        {4, "PORD"},
                                                        {5, "METIS"},
                                                        {6, "QAMD"}};
        const auto u  = used.find(id.infog[6]); // INFOG(7): ordering used
        ordering_name = (u == used.end()) ? "?" : u->second;
      }

      bool
      factorize(const std::vector<double> &matrix) override
      {
        for (std::size_t k = 0; k < upper.size(); ++k)
          values[k] = static_cast<Real>(matrix[upper[k]]);
        if (!all_finite(values))
          {
            message_ = Precision::exact ?
                         "the matrix has NaN or infinite entries" :
                         "the matrix has NaN, infinite or (in single "
                         "precision) too large entries";
            return false;
          }
        id.a            = values.data();
        const auto lock = library.lock();
        if (!library.factorize(id))
          {
            message_ = id.infog[0] == -10 ?
                         "MUMPS: the tangent matrix is numerically singular" :
                         "MUMPS factorisation failed, INFOG(1) = " +
                           std::to_string(id.infog[0]);
            return false;
          }
        return true;
      }

      bool
      solve(std::vector<double> &rhs) override
      {
        return solve_many(rhs, 1);
      }

      bool
      solve_many(std::vector<double> &rhs, const unsigned int n_rhs) override
      {
        const std::size_t n = n_rhs > 0 ? rhs.size() / n_rhs : 0;
        // Several right-hand sides that are mostly zero go in as a sparse
        // matrix (sparse_columns()).
        const bool sparse =
          n_rhs > 1 &&
          sparse_columns(rhs, n_rhs, sparse_pointer, sparse_row, sparse_value);
        {
          if constexpr (!Precision::exact)
            work.assign(rhs.begin(), rhs.end());
          const auto lock = library.lock();
          if constexpr (Precision::exact)
            id.rhs = rhs.data();
          else
            id.rhs = work.data();
          id.nrhs = n_rhs;
          id.lrhs = n;
          if (sparse)
            {
              id.icntl[19]   = 1;
              id.nz_rhs      = sparse_row.size();
              id.irhs_ptr    = sparse_pointer.data();
              id.irhs_sparse = sparse_row.data();
              id.rhs_sparse  = sparse_value.data();
            }
          id.job = 3;
          library.call(&id);
          id.nrhs      = 1;
          id.icntl[19] = 0;
        }
        if constexpr (!Precision::exact)
          std::copy(work.begin(), work.end(), rhs.begin());
        if (id.infog[0] < 0)
          {
            message_ =
              "MUMPS solve failed, INFOG(1) = " + std::to_string(id.infog[0]);
            return false;
          }
        if (!all_finite(rhs))
          {
            message_ = "MUMPS returned a non-finite solution";
            return false;
          }
        return true;
      }

      std::string
      name() const override
      {
        return std::string(Precision::exact ?
                             "MUMPS (symmetric LDL^T, " :
                             "MUMPS in single precision as GMRES's "
                             "preconditioner (symmetric LDL^T, ") +
               ordering_name + " ordering)";
      }

      bool
      exact() const override
      {
        return Precision::exact;
      }

      std::string
      statistics() const override
      {
        // INFOG(29): entries in the factors; RINFOG(3): flops of the
        // elimination; INFOG(12): negative pivots (the saddle point's).
        std::ostringstream s;
        s << std::setprecision(3) << "factor " << double(id.infog[28])
          << " entries, " << id.rinfog[2] << " flops, " << id.infog[11]
          << " negative pivots";
        return s.str();
      }

    private:
      /**
       * Initialise the MUMPS instance (MumpsLibrary::Lease::initialize()),
       * with the caller holding its lock; a failure is an error at once
       * (everything after would work on a broken instance).
       */
      void
      initialize()
      {
        if (!library.initialize(id))
          {
            std::ostringstream s;
            s << "MUMPS could not be initialised (JOB = -1): INFOG(1) = "
              << id.infog[0] << ", INFO(1) = " << id.info[0]
              << ", INFO(2) = " << id.info[1]
              << "; see the MUMPS users' guide, section 'Error "
                 "diagnostics', for the code, or choose another linear "
                 "solver (Linear solver / Solver = UMFPACK or KLU)";
            throw std::runtime_error(s.str());
          }
        initialized = true;
      }

      /** The copy of MUMPS this solver calls: its own where one could be
       * loaded, so that solver workers factorise at the same time. */
      MumpsLibrary::Lease        library;
      typename Precision::Struct id          = {};
      bool                       initialized = false;
      int                        ordering_code;
      std::string                ordering_name;
      std::vector<MUMPS_INT>     irn, jcn, permutation;
      std::vector<std::size_t>   upper;
      std::vector<Real>          values, work;
      // A block of right-hand sides in compressed columns (1-based).
      std::vector<MUMPS_INT> sparse_pointer, sparse_row;
      std::vector<Real>      sparse_value;
    };

    // ------------------------------------------------------------------
    // UMFPACK (SuiteSparse): unsymmetric multifrontal LU.
    // ------------------------------------------------------------------
    class Umfpack : public LinearSolver
    {
    public:
      ~Umfpack() override
      {
        if (numeric)
          umfpack_di_free_numeric(&numeric);
        if (symbolic)
          umfpack_di_free_symbolic(&symbolic);
      }

      void
      analyze(const SparsityCSR &pattern) override
      {
        // A new analysis replaces the old one and its factors.
        if (numeric)
          umfpack_di_free_numeric(&numeric);
        if (symbolic)
          umfpack_di_free_symbolic(&symbolic);
        umfpack_di_defaults(control);
        n = pattern.n_rows;
        // The pattern is symmetric, so its CSR arrays are CSC arrays too.
        ap.assign(pattern.row_start.begin(), pattern.row_start.end());
        ai.assign(pattern.column.begin(), pattern.column.end());
        if (umfpack_di_symbolic(
              n, n, ap.data(), ai.data(), nullptr, &symbolic, control, info) !=
            UMFPACK_OK)
          throw std::runtime_error("UMFPACK symbolic analysis failed");
        x.resize(n);
      }

      bool
      factorize(const std::vector<double> &matrix) override
      {
        if (numeric)
          umfpack_di_free_numeric(&numeric);
        // UMFPACK reads our CSR arrays as CSC, i.e. it factors A^T; the
        // solve below uses UMFPACK_At, so the result is exact even where
        // round-off makes the tangent slightly unsymmetric.
        values           = matrix;
        const int status = umfpack_di_numeric(ap.data(),
                                              ai.data(),
                                              values.data(),
                                              symbolic,
                                              &numeric,
                                              control,
                                              info);
        if (status != UMFPACK_OK)
          {
            message_ = status == UMFPACK_WARNING_singular_matrix ?
                         "UMFPACK: the tangent matrix is singular" :
                         "UMFPACK factorisation failed, status " +
                           std::to_string(status);
            return false;
          }
        return true;
      }

      bool
      solve(std::vector<double> &rhs) override
      {
        const int status = umfpack_di_solve(UMFPACK_At,
                                            ap.data(),
                                            ai.data(),
                                            values.data(),
                                            x.data(),
                                            rhs.data(),
                                            numeric,
                                            control,
                                            info);
        if (status != UMFPACK_OK || !all_finite(x))
          {
            message_ = "UMFPACK solve failed, status " + std::to_string(status);
            return false;
          }
        rhs.swap(x);
        x.resize(n);
        return true;
      }

      std::string
      name() const override
      {
        return "UMFPACK (LU)";
      }

    private:
      int                 n = 0;
      std::vector<int>    ap, ai;
      std::vector<double> x;
      std::vector<double> values;
      void               *symbolic = nullptr;
      void               *numeric  = nullptr;
      double              control[UMFPACK_CONTROL];
      double              info[UMFPACK_INFO];
    };

    // ------------------------------------------------------------------
    // KLU (SuiteSparse): LU with BTF and AMD; refactorisation reuses the
    // pivot sequence of the first factorisation while it stays accurate.
    // ------------------------------------------------------------------
    class Klu : public LinearSolver
    {
    public:
      ~Klu() override
      {
        if (numeric)
          klu_free_numeric(&numeric, &common);
        if (symbolic)
          klu_free_symbolic(&symbolic, &common);
      }

      void
      analyze(const SparsityCSR &pattern) override
      {
        // A new analysis replaces the old one and its factors (which
        // factorize() would otherwise try to refactor with the new
        // pattern).
        if (numeric)
          klu_free_numeric(&numeric, &common);
        if (symbolic)
          klu_free_symbolic(&symbolic, &common);
        klu_defaults(&common);
        n = pattern.n_rows;
        ap.assign(pattern.row_start.begin(), pattern.row_start.end());
        ai.assign(pattern.column.begin(), pattern.column.end());
        symbolic = klu_analyze(n, ap.data(), ai.data(), &common);
        if (symbolic == nullptr)
          throw std::runtime_error("KLU analysis failed");
      }

      bool
      factorize(const std::vector<double> &matrix) override
      {
        values.assign(matrix.begin(), matrix.end());
        // Refactorising keeps the old pivot sequence; accept it only if
        // neither the pivots nor their growth went bad.
        if (numeric != nullptr &&
            klu_refactor(ap.data(),
                         ai.data(),
                         values.data(),
                         symbolic,
                         numeric,
                         &common) &&
            klu_rcond(symbolic, numeric, &common) && common.rcond > 1e-12 &&
            klu_rgrowth(ap.data(),
                        ai.data(),
                        values.data(),
                        symbolic,
                        numeric,
                        &common) &&
            common.rgrowth > 1e-8)
          return true;
        // First factorisation, or the old pivots went bad: pivot anew.
        if (numeric)
          klu_free_numeric(&numeric, &common);
        numeric =
          klu_factor(ap.data(), ai.data(), values.data(), symbolic, &common);
        if (numeric == nullptr || common.status != KLU_OK)
          {
            message_ = "KLU: the tangent matrix is singular";
            return false;
          }
        return true;
      }

      bool
      solve(std::vector<double> &rhs) override
      {
        // KLU read our CSR arrays as CSC, i.e. it factored A^T: solve with
        // the transpose to get A x = b exactly.
        if (!klu_tsolve(symbolic, numeric, n, 1, rhs.data(), &common) ||
            !all_finite(rhs))
          {
            message_ = "KLU solve failed";
            return false;
          }
        return true;
      }

      std::string
      name() const override
      {
        return "KLU (LU with refactorisation)";
      }

    private:
      int                 n = 0;
      std::vector<int>    ap, ai;
      std::vector<double> values;
      klu_symbolic       *symbolic = nullptr;
      klu_numeric        *numeric  = nullptr;
      klu_common          common;
    };

    // ------------------------------------------------------------------
    // Trilinos Amesos (Amesos_Mumps, Amesos_Klu), for comparison.
    // ------------------------------------------------------------------
    class AmesosSolver : public LinearSolver
    {
    public:
      explicit AmesosSolver(const std::string &type)
        : type(type)
        , comm(MPI_COMM_SELF)
      {}

      ~AmesosSolver() override
      {
        const auto lock = mumps_guard();
        solver.reset();
      }

      /** MUMPS's lock for Amesos_Mumps; nothing for the others. */
      std::unique_lock<std::mutex>
      mumps_guard() const
      {
        return type == "Amesos_Mumps" ?
                 std::unique_lock<std::mutex>(MumpsLibrary::shared_lock()) :
                 std::unique_lock<std::mutex>();
      }

      void
      analyze(const SparsityCSR &pattern) override
      {
        // A new analysis replaces the old one: the old Amesos solver refers
        // to the old problem, matrix and vectors, so it goes first.
        {
          const auto lock = mumps_guard();
          solver.reset();
        }
        map     = std::make_unique<Epetra_Map>(static_cast<int>(pattern.n_rows),
                                           0,
                                           comm);
        matrix  = epetra_matrix(pattern, *map);
        x       = std::make_unique<Epetra_Vector>(*map);
        b       = std::make_unique<Epetra_Vector>(*map);
        problem = std::make_unique<Epetra_LinearProblem>(matrix.get(),
                                                         x.get(),
                                                         b.get());
        // Amesos_Mumps calls the MUMPS linked into palpate, whose global
        // state the solvers without a private copy share: it takes their
        // lock (MumpsLibrary).
        const auto lock = mumps_guard();
        Amesos     factory;
        solver.reset(factory.Create(type, *problem));
        if (!solver)
          throw std::runtime_error("Trilinos Amesos has no " + type);
        row_start = &pattern.row_start;
        if (solver->SymbolicFactorization() != 0)
          throw std::runtime_error(type + " symbolic factorisation failed");
      }

      bool
      factorize(const std::vector<double> &values) override
      {
        for (int i = 0; i < matrix->NumMyRows(); ++i)
          {
            int     n;
            double *v;
            int    *cols;
            matrix->ExtractMyRowView(i, n, v, cols);
            std::copy(values.begin() + (*row_start)[i],
                      values.begin() + (*row_start)[i + 1],
                      v);
          }
        const auto lock = mumps_guard();
        if (solver->NumericFactorization() != 0)
          {
            message_ = type + " numeric factorisation failed";
            return false;
          }
        return true;
      }

      bool
      solve(std::vector<double> &rhs) override
      {
        std::copy(rhs.begin(), rhs.end(), &(*b)[0]);
        {
          const auto lock = mumps_guard();
          if (solver->Solve() != 0)
            {
              message_ = type + " solve failed";
              return false;
            }
        }
        std::copy(&(*x)[0], &(*x)[0] + rhs.size(), rhs.begin());
        if (!all_finite(rhs))
          {
            message_ = type + " returned a non-finite solution";
            return false;
          }
        return true;
      }

      std::string
      name() const override
      {
        return "Trilinos " + type;
      }

    private:
      std::string                           type;
      Epetra_MpiComm                        comm;
      std::unique_ptr<Epetra_Map>           map;
      std::unique_ptr<Epetra_CrsMatrix>     matrix;
      std::unique_ptr<Epetra_Vector>        x, b;
      std::unique_ptr<Epetra_LinearProblem> problem;
      std::unique_ptr<Amesos_BaseSolver>    solver;
      const std::vector<unsigned int>      *row_start = nullptr;
    };
  } // namespace



  bool
  LinearSolver::solve_many(std::vector<double> &block, const unsigned int n_rhs)
  {
    if (n_rhs == 0)
      return true;
    const std::size_t   n = block.size() / n_rhs;
    std::vector<double> column(n);
    for (unsigned int j = 0; j < n_rhs; ++j)
      {
        std::copy_n(block.begin() + j * n, n, column.begin());
        if (!solve(column))
          return false;
        std::copy(column.begin(), column.end(), block.begin() + j * n);
      }
    return true;
  }



  std::unique_ptr<LinearSolver>
  LinearSolver::create(const std::string &name, const std::string &ordering)
  {
    Parameters::LinearSolver p;
    p.solver   = name;
    p.ordering = ordering;
    return create(p, 0);
  }



  std::unique_ptr<LinearSolver>
  LinearSolver::create(const Parameters::LinearSolver &p,
                       const unsigned int              n_equations)
  {
    const std::string name = p.solver_for(n_equations);
    const auto        own  = p.own.find(name);
    if (LinearSolverRegistry::find(name) == nullptr)
      throw std::invalid_argument("unknown linear solver '" + name + "'");
    return LinearSolverRegistry::create(
      name, own == p.own.end() ? Plugins::Entries() : own->second, p);
  }



  namespace
  {
    /** The built-in solvers have no entries of their own (MUMPS's ordering
     * is the shared Linear solver / Ordering). */
    void
    no_own_entries(dealii::ParameterHandler &)
    {}

    [[maybe_unused]] const bool built_in_solvers_registered = [] {
      using Shared = Parameters::LinearSolver;
      using Own    = dealii::ParameterHandler;
      const std::vector<LinearSolverRegistry::Plugin> solvers = {
        {"MUMPS",
         "MUMPS's symmetric indefinite LDL^T through its C interface",
         &no_own_entries,
         [](const Own &, const Shared &p) -> std::unique_ptr<LinearSolver> {
           return std::make_unique<Mumps<Double>>(p.ordering);
         }},
        {"MUMPS single",
         "MUMPS in single precision, as the preconditioner of GMRES in "
         "double (mixed precision)",
         &no_own_entries,
         [](const Own &, const Shared &p) -> std::unique_ptr<LinearSolver> {
           return std::make_unique<Mumps<Single>>(p.ordering);
         }},
        {"UMFPACK",
         "SuiteSparse's UMFPACK (unsymmetric LU)",
         &no_own_entries,
         [](const Own &, const Shared &) -> std::unique_ptr<LinearSolver> {
           return std::make_unique<Umfpack>();
         }},
        {"KLU",
         "SuiteSparse's KLU",
         &no_own_entries,
         [](const Own &, const Shared &) -> std::unique_ptr<LinearSolver> {
           return std::make_unique<Klu>();
         }},
        {"Amesos MUMPS",
         "MUMPS through Trilinos Amesos, for comparison",
         &no_own_entries,
         [](const Own &, const Shared &) -> std::unique_ptr<LinearSolver> {
           return std::make_unique<AmesosSolver>("Amesos_Mumps");
         }},
        {"Amesos KLU",
         "KLU through Trilinos Amesos, for comparison",
         &no_own_entries,
         [](const Own &, const Shared &) -> std::unique_ptr<LinearSolver> {
           return std::make_unique<AmesosSolver>("Amesos_Klu");
         }}};
      for (const auto &plugin : solvers)
        LinearSolverRegistry::add_declared("linear solver", plugin);
      return true;
    }();
  } // namespace



  template class Plugins::Registry<LinearSolver, Parameters::LinearSolver>;
} // namespace palpate
