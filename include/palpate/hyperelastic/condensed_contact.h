// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

#ifndef palpate_hyperelastic_condensed_contact_h
#define palpate_hyperelastic_condensed_contact_h

#include <palpate/base/utilities.h>
#include <palpate/hyperelastic/contact_lcp.h>
#include <palpate/hyperelastic/hyperelastic_system.h>

#include <array>
#include <vector>

namespace palpate
{
  class LinearSolver;

  /**
   * The sphere's frictionless contact condensed onto the surface nodes
   * near it (Contact solver = condensed), for a Newton method whose
   * factorised tangent K leaves the contact out.
   *
   * For the candidates (nodes touching the sphere or within a quarter
   * radius of it) it keeps the compliance columns Z = K^-1 P^T, three per
   * node (P picks a node's x, y, z DoFs): how the whole body moves under
   * a unit force on that node. They are made by one block solve with the
   * kept factors when a node becomes a candidate, and stay valid until the
   * factors change (reset()): the sphere's contact set moving costs a few
   * new columns, never a factorisation.
   *
   * On the candidates, with H = P Z (3m x 3m) and the contact forces'
   * own stiffness G (per node in contact -lambda/rho (I - n n^T): the
   * force turns with the normal as the node slides on the sphere, which on
   * soft tissue is a third of a surface node's stiffness), the tangent
   * K + P^T G P has the compliance H (I + G H)^-1 there (Woodbury), and
   * W = C H (I + G H)^-1 C^T along the normals C: the small dense problem
   * the contact is solved on (ContactLCP).
   *
   * Not thread-safe; each StateSolver owns one. Its work arrays are kept
   * from call to call.
   */
  class CondensedContact
  {
  public:
    explicit CondensedContact(const HyperelasticSystem &system);

    /** The kept factors changed (or are of another matrix): drop every
     * column, and the block use_block() gave. */
    void
    reset();

    /**
     * The kept factors are a Schur complement's (SchurFactors) whose
     * compliance @p block (k x k, row-major) on the DoFs with
     * @p slot[e] >= 0 (their row in it) is known: while every candidate's
     * DoFs are among them, H is read from it and the step's response to
     * the candidates' forces is one solve, instead of three columns per
     * candidate. Both are kept by reference until reset().
     */
    void
    use_block(const std::vector<int> &slot, const std::vector<double> &block);

    /**
     * Turn @p step, on entry K^-1 (-R) with the contact forces lambda =
     * beta x_lambda held as loads in R, into the Newton step with the
     * contact solved: the contact problem on the candidates at unknowns
     * @p x (their @p rows) for the new forces lambda', and the step's
     * displacements and multipliers for them. Gaps are met to
     * @p tolerance (m). False if the linear solver fails.
     */
    bool
    step(LinearSolver                                      &solver,
         const std::vector<double>                         &x,
         const std::vector<HyperelasticSystem::ContactRow> &rows,
         std::vector<double>                               &step,
         const double                                       tolerance);

    /**
     * The probe's stiffness -d force / d target (N/m, row-major 3 x 3)
     * at the converged unknowns @p x (their @p rows), with the set of
     * nodes in contact held: into @p stiffness. False if the linear
     * solver fails or the condensed tangent is singular.
     */
    bool
    stiffness(LinearSolver                                      &solver,
              const std::vector<double>                         &x,
              const std::vector<HyperelasticSystem::ContactRow> &rows,
              std::array<double, 9>                             &stiffness);

    /** Candidates of the last step, and compliance columns made since the
     * last reset() (three per node). */
    unsigned int
    n_candidates() const;
    unsigned int
    n_columns() const;

    /** The contact problem's solver (its iteration counts). */
    const ContactLCP &
    contact_problem() const;

  private:
    /** Columns for the candidates that have none, then H. False if the
     * linear solver fails. */
    bool
    condense(LinearSolver                                      &solver,
             const std::vector<HyperelasticSystem::ContactRow> &rows);

    /** G, the LU factors of A = I + G H (with @p with_curvature; else
     * G = 0 and A = I), S = A^-1 C^T and W = C H S. False if A is
     * singular. */
    bool
    assemble_W(const std::vector<double>                         &x,
               const std::vector<HyperelasticSystem::ContactRow> &rows,
               const bool with_curvature);

    /**
     * The contact problem on W for the new forces, and the step for them
     * added to @p step (which holds K^-1 (-R); its candidates' part is
     * in v0). With @p settled_only, nothing is changed and false returned
     * if the active-set method did not settle (W with G may be
     * indefinite, and then has no Gauss-Seidel fallback).
     */
    bool
    solve_contact(const std::vector<double>                         &x,
                  const std::vector<HyperelasticSystem::ContactRow> &rows,
                  std::vector<double>                               &step,
                  const double                                       tolerance,
                  const bool settled_only);

    /** step += Z v for a vector @p v of the candidates' 3m DoFs: from the
     * columns, or by one solve when H is from the block. False if that
     * solve fails. */
    bool
    add_columns(const std::vector<double> &v, std::vector<double> &step);

    const HyperelasticSystem &system;
    const unsigned int        n;
    const double              beta;

    std::vector<int>          slot_of; // [candidate k] -> first column, or -1
    std::vector<double>       columns; // 3 per slot, n values each
    std::vector<unsigned int> candidates, missing;
    std::vector<double> fresh, H, G, A, S, W, factors, q, lambda, lambda_old, v,
      v0, y;
    std::vector<unsigned int> pivot, pivot_W;
    /** Whether G, made by the last assemble_W(), is not zero. */
    bool curved = false;
    // use_block()'s block, whether the last condense() read H from it, and
    // the solver of the current step (add_columns() solves with it then).
    const std::vector<int>    *block_slot   = nullptr;
    const std::vector<double> *block_values = nullptr;
    bool                       from_block   = false;
    LinearSolver              *solver_now   = nullptr;
    std::vector<double>        response;
    // The candidates' DoFs (3 per candidate, -1 where fixed).
    std::vector<int> candidate_eq;
    ContactLCP       lcp;
  };
} // namespace palpate

#endif
