// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

// A linear solver is one file (issue 28, doc/extending.md): this test
// defines a new one, "dense LU" (LAPACK's LU of the whole matrix), with an
// entry of its own, in this file only, and registers it. Without touching
// palpate:
// - Linear solver / Solver accepts it, and its subsection (Linear solver /
//   dense LU) is declared and read;
// - the state solver uses it: on the shipped beam pressed 2 mm, the force
//   and the displacements are MUMPS's to 1e-9 (relative), and its name is
//   what the state solver reports;
// - its own entry does what it says (a system larger than Largest size is
//   a linear solver failure, with the plug-in's message);
// - a value its check refuses is an input error naming the entry, the
//   file and the line, when the scene is read.

#include <palpate/base/exceptions.h>
#include <palpate/hyperelastic/linear_solver.h>
#include <palpate/hyperelastic/state_solver.h>
#include <palpate/mesh/mesh.h>
#include <palpate/mesh/node_selection.h>

#include <deal.II/base/parameter_handler.h>
#include <deal.II/lac/lapack_full_matrix.h>
#include <deal.II/lac/vector.h>

#include <cmath>

#include "../tests.h"

namespace
{
  /** LAPACK's LU factorisation of the whole matrix: exact, O(n^2) memory,
   * for small systems. */
  class DenseLU : public palpate::LinearSolver
  {
  public:
    explicit DenseLU(const unsigned int largest)
      : largest(largest)
    {}

    static void
    declare_parameters(dealii::ParameterHandler &prm)
    {
      prm.declare_entry("Largest size",
                        "3000",
                        dealii::Patterns::Integer(),
                        "The most equations it factorises (a dense matrix "
                        "of n^2 numbers).");
    }

    static void
    check_parameters(const dealii::ParameterHandler &own)
    {
      const long n = own.get_integer("Largest size");
      if (n < 1 || n > 20000)
        throw palpate::Plugins::EntryError(
          "Largest size",
          "must be from 1 to 20000 (" + std::to_string(n) + " given)",
          "a dense matrix of 20000 equations is 3.2 GB already.");
    }

    static std::unique_ptr<palpate::LinearSolver>
    create(const dealii::ParameterHandler &own,
           const palpate::Parameters::LinearSolver &)
    {
      check_parameters(own);
      return std::make_unique<DenseLU>(own.get_integer("Largest size"));
    }

    void
    analyze(const palpate::SparsityCSR &p) override
    {
      pattern = &p;
    }

    bool
    factorize(const std::vector<double> &values) override
    {
      const unsigned int n = pattern->n_rows;
      if (n > largest)
        {
          message_ = "the system has " + std::to_string(n) +
                     " equations, more than Largest size (" +
                     std::to_string(largest) + ")";
          return false;
        }
      lu.reinit(n, n);
      for (unsigned int i = 0; i < n; ++i)
        for (unsigned int k = pattern->row_start[i];
             k < pattern->row_start[i + 1];
             ++k)
          lu(i, pattern->column[k]) = values[k];
      lu.compute_lu_factorization();
      return true;
    }

    bool
    solve(std::vector<double> &rhs) override
    {
      dealii::Vector<double> b(rhs.begin(), rhs.end());
      lu.solve(b);
      std::copy(b.begin(), b.end(), rhs.begin());
      return true;
    }

    std::string
    name() const override
    {
      return "dense LU (LAPACK, at most " + std::to_string(largest) +
             " equations)";
    }

  private:
    const unsigned int               largest;
    const palpate::SparsityCSR      *pattern = nullptr;
    dealii::LAPACKFullMatrix<double> lu;
  };
} // namespace

PALPATE_REGISTER_LINEAR_SOLVER(DenseLU,
                               "dense LU",
                               "LAPACK's LU of the whole matrix (a test's)");



int
main(int argc, char **argv)
{
  palpate::Environment env(argc, argv);
  initlog();

  const std::string beam =
    read_file(palpate_source_dir + "/parameters/beam.prm");
  const auto scene_text = [&](const std::string &largest) {
    return beam + R"(
subsection Linear solver
  set Solver = dense LU
  subsection dense LU
    set Largest size = )" +
           largest + R"(
  end
end
)";
  };
  const palpate::Utilities::Point3 push = {{0, 0, -0.002}};

  // MUMPS, the reference.
  const palpate::Scene mumps_scene = shipped_scene("beam.prm");
  const Body           mumps_body(mumps_scene);
  palpate::StateSolver mumps(mumps_body.mesh,
                             mumps_body.nodes,
                             mumps_scene.parameters);
  const palpate::State reference = mumps.solve(mumps.rest_state(), push);

  // The plug-in, chosen by the scene.
  write_file("dense.prm", scene_text("3000"));
  const palpate::Scene scene = palpate::Scene::read("dense.prm");
  const Body           body(scene);
  palpate::StateSolver dense(body.mesh, body.nodes, scene.parameters);
  const palpate::State state     = dense.solve(dense.rest_state(), push);
  double               largest_u = 0, difference = 0;
  for (unsigned int i = 0; i < state.solution.size(); ++i)
    {
      largest_u = std::max(largest_u, std::abs(reference.solution[i]));
      difference =
        std::max(difference,
                 std::abs(state.solution[i] - reference.solution[i]));
    }
  const double force_difference =
    palpate::Utilities::distance(state.force, reference.force);
  deallog << "the scene chooses it: " << dense.linear_solver_name()
          << std::endl;
  deallog << "pressed 2 mm: " << (state.converged ? "converged" : state.message)
          << ", force = MUMPS's to 1e-9: "
          << ok(force_difference <=
                1e-9 * palpate::Utilities::norm(reference.force))
          << ", displacements to 1e-9: " << ok(difference <= 1e-9 * largest_u)
          << std::endl;

  // Its own entry: a system larger than Largest size is refused.
  write_file("dense-small.prm", scene_text("100"));
  const palpate::Scene small = palpate::Scene::read("dense-small.prm");
  palpate::StateSolver too_small(body.mesh, body.nodes, small.parameters);
  const palpate::State refused = too_small.solve(too_small.rest_state(), push);
  deallog << "Largest size = 100: "
          << (refused.converged ? "converged (WRONG)" :
                                  palpate::to_string(refused.status))
          << ", the plug-in's message: "
          << ok(refused.message.find("more than Largest size (100)") !=
                std::string::npos)
          << std::endl;

  // A value its check refuses, when the scene is read.
  write_file("dense-huge.prm", scene_text("1000000"));
  try
    {
      palpate::Scene::read("dense-huge.prm");
      deallog << "Largest size = 1000000: accepted (WRONG)" << std::endl;
    }
  catch (const palpate::InputError &e)
    {
      deallog << "Largest size = 1000000: " << e.entry() << ": " << e.problem()
              << " (line " << e.line() << ")" << std::endl;
    }
}
