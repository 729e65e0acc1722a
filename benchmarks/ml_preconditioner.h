// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors
//
// An algebraic multigrid V-cycle (Trilinos ML, smoothed aggregation) as a
// linear solver plug-in that is not exact: the Newton method then uses it
// only as GMRES's preconditioner, as it uses MUMPS single. For the
// organ-speed benchmark's lever "AMG instead of MUMPS" (issue 25: measure
// an algebraic multigrid against MUMPS on the same states). A plug-in in
// the benchmark's own files: nothing else in palpate knows it.

#ifndef palpate_benchmarks_ml_preconditioner_h
#define palpate_benchmarks_ml_preconditioner_h

#include <palpate/hyperelastic/linear_solver.h>

#include <deal.II/base/parameter_handler.h>

#include <Epetra_CrsMatrix.h>
#include <Epetra_Map.h>
#include <Epetra_MpiComm.h>
#include <Epetra_Vector.h>
#include <Teuchos_ParameterList.hpp>
#include <ml_MultiLevelPreconditioner.h>

#include <atomic>
#include <memory>

namespace ml_lever
{
  /** How often the hierarchy was built and applied, over all instances. */
  inline std::atomic<unsigned long> setups{0}, applications{0}, failures{0};

  class MlPreconditioner : public palpate::LinearSolver
  {
  public:
    MlPreconditioner()
      : comm(MPI_COMM_SELF)
    {}

    static void
    declare_parameters(dealii::ParameterHandler &)
    {}

    static std::unique_ptr<palpate::LinearSolver>
    create(const dealii::ParameterHandler &,
           const palpate::Parameters::LinearSolver &)
    {
      return std::make_unique<MlPreconditioner>();
    }

    void
    analyze(const palpate::SparsityCSR &pattern) override
    {
      preconditioner.reset();
      map =
        std::make_unique<Epetra_Map>(static_cast<int>(pattern.n_rows), 0, comm);
      matrix    = palpate::epetra_matrix(pattern, *map);
      x         = std::make_unique<Epetra_Vector>(*map);
      b         = std::make_unique<Epetra_Vector>(*map);
      row_start = &pattern.row_start;
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
      // Smoothed aggregation with an ILU(0) smoother: the multiplier rows
      // of the sphere's contact have a zero diagonal while in contact,
      // which rules out Jacobi, Gauss-Seidel and Chebyshev smoothers.
      Teuchos::ParameterList list;
      ML_Epetra::SetDefaults("SA", list);
      list.set("ML output", 0);
      list.set("smoother: type", "IFPACK");
      list.set("smoother: ifpack type", "ILU");
      list.set("smoother: ifpack level-of-fill", 0.0);
      list.set("coarse: type", "Amesos-KLU");
      list.set("max levels", 4);
      preconditioner.reset();
      try
        {
          preconditioner =
            std::make_unique<ML_Epetra::MultiLevelPreconditioner>(*matrix,
                                                                  list);
        }
      catch (...)
        {
          ++failures;
          message_ = "ML set-up threw";
          return false;
        }
      ++setups;
      return true;
    }

    bool
    solve(std::vector<double> &rhs) override
    {
      std::copy(rhs.begin(), rhs.end(), &(*b)[0]);
      if (preconditioner->ApplyInverse(*b, *x) != 0)
        {
          ++failures;
          message_ = "ML V-cycle failed";
          return false;
        }
      std::copy(&(*x)[0], &(*x)[0] + rhs.size(), rhs.begin());
      ++applications;
      for (const double v : rhs)
        if (!std::isfinite(v))
          {
            ++failures;
            message_ = "ML V-cycle gave a non-finite vector";
            return false;
          }
      return true;
    }

    bool
    exact() const override
    {
      return false;
    }

    std::string
    name() const override
    {
      return "ML smoothed aggregation, ILU(0) smoother (a benchmark's)";
    }

  private:
    Epetra_MpiComm                                       comm;
    std::unique_ptr<Epetra_Map>                          map;
    std::unique_ptr<Epetra_CrsMatrix>                    matrix;
    std::unique_ptr<Epetra_Vector>                       x, b;
    std::unique_ptr<ML_Epetra::MultiLevelPreconditioner> preconditioner;
    const std::vector<unsigned int>                     *row_start = nullptr;
  };
} // namespace ml_lever

using ml_lever::MlPreconditioner;
PALPATE_REGISTER_LINEAR_SOLVER(MlPreconditioner,
                               "ML AMG",
                               "Trilinos ML smoothed aggregation as GMRES's "
                               "preconditioner (the organ-speed benchmark's)");

#endif
