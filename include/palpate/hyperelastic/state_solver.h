// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

#ifndef palpate_hyperelastic_state_solver_h
#define palpate_hyperelastic_state_solver_h

#include <palpate/base/utilities.h>
#include <palpate/hyperelastic/state.h>
#include <palpate/scene/parameters.h>

#include <functional>
#include <memory>
#include <string>

namespace palpate
{
  class Mesh;
  class HyperelasticSystem;
  class LinearSolver;
  struct NodeSelection;

  /**
   * The paper's two-level solution method: computes the state with the
   * active node at a target position from a neighbouring state.
   *
   * The path from the neighbour's active-node position to the target is
   * split into n equal increments (incremental staging; n from the scene's
   * Number of increments and Maximum increment length). Each increment is
   * solved by Newton's method from the previous increment's state, with a
   * backtracking line search on the residual norm that also keeps every
   * element's det F > 0. An increment that fails may be halved and retried
   * (Maximum cutbacks).
   *
   * A state that cannot be computed is returned as a *failure point*: a
   * State with converged = false, its SolveStatus and a message. solve()
   * never throws on a numerical failure and never returns a NaN force.
   *
   * Each solver worker owns one StateSolver (the linear solver's symbolic
   * analysis is done once, in the constructor).
   */
  class StateSolver
  {
  public:
    /** Build the discrete system and analyse its sparsity pattern. */
    StateSolver(const Mesh                      &mesh,
                const NodeSelection             &nodes,
                const Parameters::AllParameters &parameters);

    ~StateSolver();

    /** The undeformed state: zero displacement, zero force. */
    State
    rest_state() const;

    /**
     * The state with the active node displaced by @p target (m) from its
     * rest position, computed from the state @p from by incremental staging
     * and Newton's method.
     */
    State
    solve(const State &from, const Utilities::Point3 &target);

    /**
     * The same, with @p behind, a converged state whose active node lies
     * on the line through @p from and @p target, on the other side of
     * @p from (the grid point behind the source, on the same grid line):
     * Newton then starts from the extrapolation of behind -> from to the
     * target, which is already on the target and second-order accurate,
     * instead of spending its first iteration on a tangent predictor. If
     * @p behind is null, not on that line, or not an equilibrium of this
     * body, this is solve(from, target). With @p behind2 too, the state
     * one more step behind at the same spacing, the start is the quadratic
     * through the three (third order), when the path is one increment.
     */
    State
    solve(const State             &from,
          const Utilities::Point3 &target,
          const State             *behind,
          const State             *behind2 = nullptr);

    /** The discrete system. */
    /**
     * Call @p observer with the state at the end of every converged
     * increment of the staging and its path parameter t in (0, 1] (1: the
     * target). Null: none (the default). For output that shows the path,
     * e.g. `palpate solve` with shape output.
     */
    void
    set_increment_observer(std::function<void(const State &, double)> observer);

    /**
     * Ask @p stop_check before every Newton iteration whether to give up:
     * if it returns true, solve() returns at once with the last
     * equilibrium reached on the way and SolveStatus::stopped (no retry,
     * no cut-back). For `palpate solve` under Ctrl-C, whose increments can
     * take minutes on a real organ. Null: never (the default).
     */
    void
    set_stop_check(std::function<bool()> stop_check);

    const HyperelasticSystem &
    system() const;

    /** The discrete system, e.g. to prescribe non-zero fixed displacements. */
    HyperelasticSystem &
    system();

    /** The sparse direct solver's name and settings. */
    std::string
    linear_solver_name() const;

    /** The sparse direct solver's statistics of its last factorisation. */
    std::string
    linear_solver_statistics() const;

    /** The Newton settings in use; may be changed between solves. */
    Parameters::NonlinearSolver &
    settings();

    /** Seconds spent in set-up: FE space, geometry cache, sparsity
     * pattern and the direct solver's symbolic analysis. */
    double
    setup_time() const;

  private:
    struct Impl;
    std::unique_ptr<Impl> impl;
  };
} // namespace palpate

#endif
