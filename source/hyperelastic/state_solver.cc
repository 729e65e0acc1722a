// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

#include <palpate/hyperelastic/condensed_contact.h>
#include <palpate/hyperelastic/effect.h>
#include <palpate/hyperelastic/hyperelastic_system.h>
#include <palpate/hyperelastic/linear_solver.h>
#include <palpate/hyperelastic/state_solver.h>
#include <palpate/hyperelastic/state_solver_impl.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <functional>
#include <limits>
#include <tuple>

namespace palpate
{
  std::string
  to_string(const SolveStatus status)
  {
    switch (status)
      {
        case SolveStatus::converged:
          return "converged";
        case SolveStatus::max_iterations:
          return "max iterations";
        case SolveStatus::inverted_element:
          return "inverted element";
        case SolveStatus::not_finite:
          return "not finite";
        case SolveStatus::linear_solver_failure:
          return "linear solver failure";
        case SolveStatus::stopped:
          return "stopped";
        case SolveStatus::sphere_through_surface:
          return "sphere through the surface";
      }
    return "unknown";
  }



  namespace
  {
    using Clock = std::chrono::steady_clock;

    using Utilities::seconds_since;

    double
    norm(const std::vector<double> &v)
    {
      double s = 0;
      for (const double x : v)
        s += x * x;
      return std::sqrt(s);
    }

    double
    dot(const std::vector<double> &a, const std::vector<double> &b)
    {
      double s = 0;
      for (std::size_t i = 0; i < a.size(); ++i)
        s += a[i] * b[i];
      return s;
    }

    /** solve()'s path from @p a to @p target at parameter @p t: its end is
     * the target itself, bit for bit, for the last increment is told apart
     * by it (patch_factors_due()). */
    Utilities::Point3
    path_point(const Utilities::Point3 &a,
               const Utilities::Point3 &target,
               const double             t)
    {
      return t == 1 ? target :
                      Utilities::Point3{{a[0] + t * (target[0] - a[0]),
                                         a[1] + t * (target[1] - a[1]),
                                         a[2] + t * (target[2] - a[2])}};
    }
  } // namespace



  namespace internal
  {
    unsigned int
    gmres(const SparsityCSR                                &pattern,
          const std::vector<double>                        &matrix,
          const std::function<bool(std::vector<double> &)> &precondition,
          std::vector<double>                              &b,
          const double                                      tolerance,
          const unsigned int                                max_iterations,
          std::vector<std::vector<double>>                 &V,
          std::vector<std::vector<double>>                 &Z)
    {
      const std::size_t n    = b.size();
      const double      beta = norm(b);
      if (beta == 0)
        return 1;
      const unsigned int m = max_iterations;
      V.resize(m + 1);
      Z.resize(m);
      std::vector<double> H((m + 1) * m, 0.0), cs(m), sn(m), g(m + 1, 0.0);
      const auto          h = [&](const unsigned int i,
                         const unsigned int j) -> double          &{
        return H[i * m + j];
      };
      V[0].resize(n);
      for (std::size_t i = 0; i < n; ++i)
        V[0][i] = b[i] / beta;
      g[0] = beta;
      for (unsigned int j = 0; j < m; ++j)
        {
          Z[j] = V[j];
          if (!precondition(Z[j]))
            return 0;
          // w = A z_j
          std::vector<double> &w = V[j + 1];
          w.assign(n, 0.0);
          for (unsigned int r = 0; r < pattern.n_rows; ++r)
            {
              double sum = 0;
              for (unsigned int k = pattern.row_start[r];
                   k < pattern.row_start[r + 1];
                   ++k)
                sum += matrix[k] * Z[j][pattern.column[k]];
              w[r] = sum;
            }
          for (unsigned int i = 0; i <= j; ++i)
            {
              h(i, j) = dot(w, V[i]);
              for (std::size_t k = 0; k < n; ++k)
                w[k] -= h(i, j) * V[i][k];
            }
          h(j + 1, j) = norm(w);
          if (!std::isfinite(h(j + 1, j)))
            return 0;
          if (h(j + 1, j) > 0)
            for (double &x : w)
              x /= h(j + 1, j);
          for (unsigned int i = 0; i < j; ++i)
            {
              const double a = h(i, j), c = h(i + 1, j);
              h(i, j)     = cs[i] * a + sn[i] * c;
              h(i + 1, j) = -sn[i] * a + cs[i] * c;
            }
          const double r = std::hypot(h(j, j), h(j + 1, j));
          if (r == 0)
            return 0;
          cs[j]       = h(j, j) / r;
          sn[j]       = h(j + 1, j) / r;
          h(j, j)     = r;
          h(j + 1, j) = 0;
          g[j + 1]    = -sn[j] * g[j];
          g[j]        = cs[j] * g[j];
          // Give up early when the rate so far would need more than 1.5
          // times the allowed iterations: the caller then factorises, and
          // every iteration spent here is lost. On the liver with the
          // sphere, the first Newton step of a state (the contact set
          // changes) failed to converge in 7 of 8 states; this stops most
          // such tries after 4 iterations instead of 10, and left those
          // that converge (superlinearly, once the changed contact rows are
          // in the Krylov space) as they were: the same Krylov iterations
          // and factorisations per state (benchmarks/run organ-speed).
          if (j >= 3 && std::abs(g[j + 1]) > tolerance * beta)
            {
              const double rate =
                std::pow(std::abs(g[j + 1]) / beta, 1.0 / (j + 1));
              if (rate >= 1 || std::log(tolerance) / std::log(rate) > 1.5 * m)
                return 0;
            }
          if (std::abs(g[j + 1]) <= tolerance * beta)
            {
              // x = Z y with H y = g (upper triangular).
              std::vector<double> y(j + 1);
              for (int i = j; i >= 0; --i)
                {
                  double sum = g[i];
                  for (unsigned int k = i + 1; k <= j; ++k)
                    sum -= h(i, k) * y[k];
                  y[i] = sum / h(i, i);
                }
              b.assign(n, 0.0);
              for (unsigned int i = 0; i <= j; ++i)
                for (std::size_t k = 0; k < n; ++k)
                  b[k] += y[i] * Z[i][k];
              return j + 1;
            }
        }
      return 0;
    }
  } // namespace internal



  bool
  StateSolver::Impl::active_stiffness(State &state)
  {
    if (system->n_active_multipliers() == 0 || matrix.empty())
      return false;
    const std::vector<double> x = system->from_state(state);
    std::vector<double>       rhs;
    for (unsigned int j = 0; j < 3; ++j)
      {
        system->probe_load(x, state.active_displacement, j, rhs);
        bool solved = false;
        if (factorized_current && linear_solver->exact())
          solved = linear_solver->solve(rhs);
        else if (factorized)
          solved = preconditioned_gmres(rhs, 1e-6) > 0;
        if (!solved)
          {
            unsigned int krylov_iterations;
            solved = factorize_and_solve(rhs, 1e-6, krylov_iterations);
            ++state.stiffness_factorizations;
          }
        if (!solved)
          return false;
        const Utilities::Point3 df =
          system->probe_force_change(x, state.active_displacement, rhs, j);
        for (unsigned int i = 0; i < 3; ++i)
          state.stiffness[3 * i + j] = -df[i];
      }
    for (const double k : state.stiffness)
      if (!std::isfinite(k))
        return false;
    return true;
  }



  bool
  StateSolver::Impl::newton_step(NewtonIteration &record)
  {
    // The Newton step: K dx = -R. With a kept factorisation (of an
    // earlier tangent in this state, or of the last state this solver
    // computed, usually a neighbour) GMRES solves it in a few
    // preconditioned iterations, at a fraction of a factorisation. When
    // GMRES needs more than the allowed iterations the tangent has
    // drifted too far from the factorised one: factorise it.
    //
    // How exactly: to |K dx + R| <= 1e-4 |R|. Each Newton step then
    // cuts the residual by at least 1e-4, which within the three or
    // four steps a state takes is as good as quadratic convergence
    // (measured: the same Newton iterations per state as exact steps;
    // Eisenstat and Walker's adaptive forcing terms cost 0.9 more
    // iterations per state here), while GMRES from a neighbour's
    // factorisation reaches it in a few iterations. The convergence
    // test of the state is the same either way.
    step = residual;
    for (double &s : step)
      s = -s;
    const double eta         = 1e-4;
    record.factorized        = true;
    record.krylov_iterations = 0;
    if (settings.reuse_factorization && factorized)
      {
        record.krylov_iterations = preconditioned_gmres(step, eta);
        record.factorized        = record.krylov_iterations == 0;
      }
    return !record.factorized ||
           factorize_and_solve(step, eta, record.krylov_iterations);
  }



  std::pair<double, double>
  StateSolver::Impl::line_search(const std::vector<double> &x,
                                 const Utilities::Point3   &target,
                                 const unsigned int         iteration)
  {
    // Step length. While the active node's constraint is violated (the
    // first iteration of an increment), the step is the predictor that
    // moves the node onto its target: take the longest admissible one
    // of 1, 1/2, 1/4, ... Afterwards every Newton step keeps the
    // constraint (B dx = 0), the multipliers drop out of
    // s(alpha) = R(x + alpha dx) . dx = dPi/dalpha, and the line search
    // looks for a step where the energy Pi stops decreasing:
    // |s(alpha)| <= 0.8 |s(0)| (Crisfield's criterion), by regula falsi
    // on s. If dx is not a descent direction (s(0) >= 0: the tangent is
    // indefinite near a buckling point), it backtracks on the residual
    // norm instead. Without line search the full step is taken.
    const double phi0 = norm(residual);
    //
    // With a sphere the constraints are the contact conditions, which
    // stay violated while the active set changes from step to step:
    // only the first step of an increment (the probe has moved) is a
    // predictor; afterwards the residual norm must decrease, which
    // keeps the semi-smooth Newton method from cycling between active
    // sets (full steps cycled for 25 iterations on the liver).
    const bool predictor =
      system->constraint_violation(residual) >
        settings.increment_tolerance * system->length_scale() &&
      (iteration == 0 || !system->has_contact());
    const double s0 = directional_derivative(residual, step);
    // The energy of the mixed u-p formulation has a saddle in p, so
    // there the residual norm is the merit function.
    // So it is with contact, whose active set may change under the
    // step (the energy is then not smooth along it).
    const bool energy =
      !predictor && s0 < 0 && !system->has_pressure() && !system->has_contact();
    double alpha = 1, best_alpha = -1, best_merit = 0, best_scale = 0;
    double lower = 0, s_lower = s0, upper = -1, s_upper = 0;
    const unsigned int steps =
      settings.line_search ? settings.max_line_search_steps : 1;
    for (unsigned int k = 0; k < steps; ++k)
      {
        trial = x;
        for (unsigned int i = 0; i < x.size(); ++i)
          trial[i] += alpha * step[i];
        double trial_scale = 0;
        if (!system->assemble(
              trial, target, trial_residual, nullptr, &trial_scale))
          {
            // Inadmissible (an element inverts): shorten the step.
            upper   = alpha;
            s_upper = std::numeric_limits<double>::max();
            alpha   = 0.5 * (lower + alpha);
            continue;
          }
        const double phi   = norm(trial_residual);
        const double s     = directional_derivative(trial_residual, step);
        const double merit = energy ? std::abs(s) : phi;
        if (best_alpha < 0 || merit < best_merit)
          {
            best_alpha = alpha;
            best_merit = merit;
            best_scale = trial_scale;
            best_x.swap(trial);
            best_residual.swap(trial_residual);
          }
        if (predictor)
          break; // the longest admissible predictor step
        if (energy)
          {
            if (std::abs(s) <= 0.8 * std::abs(s0) || (s < 0 && upper < 0))
              break; // energy stationary enough, or still descending at the
                     // full step
            // Regula falsi on s between the bracket ends.
            if (s < 0)
              lower = alpha, s_lower = s;
            else
              upper = alpha, s_upper = s;
            alpha = (s_upper == std::numeric_limits<double>::max()) ?
                      0.5 * (lower + upper) :
                      lower - s_lower * (upper - lower) / (s_upper - s_lower);
            alpha = std::clamp(alpha,
                               lower + 0.05 * (upper - lower),
                               upper - 0.05 * (upper - lower));
          }
        else
          {
            if (phi <= (1 - 1e-4 * alpha) * phi0)
              break;
            // g(a) = phi(a)^2 has g'(0) = -2 g(0) along the Newton
            // step; minimise the quadratic through g(0), g'(0), g(a).
            const double g0 = phi0 * phi0;
            const double a =
              g0 * alpha * alpha / (phi * phi - g0 + 2 * g0 * alpha);
            alpha = std::clamp(a, 0.1 * alpha, 0.5 * alpha);
          }
      }
    return {best_alpha, best_scale};
  }



  std::string
  StateSolver::Impl::stagnation(const State           &state,
                                const NewtonIteration &record,
                                const unsigned int     iteration,
                                const bool             may_cut_back,
                                unsigned int          &short_steps) const
  {
    // Stagnation while the increment can still be halved, where the
    // residual norm is the line search's merit (a pressure field or
    // contact): four accepted steps that did not reduce it by a tenth.
    // Newton's method near a solution cuts it by far more, even while
    // the sphere's contact set settles (0.97 -> 0.04 in three steps):
    // this is a start outside the basin. A sphere moved 5 mm sideways
    // pressed nodes deep into it and the semi-smooth iteration wandered
    // at a relative residual of 1 for 20 iterations before it found the
    // way (1,607-node liver, doc/benchmarks/organ-speed.md); two half
    // increments cost less. (With the energy as merit the residual may
    // rise on the way to a solution: a locking StVK at nu = 0.4999
    // converges so, tests/hyperelastic/hard_cases.)
    const std::size_t n_history = state.history.size();
    if (may_cut_back && (system->has_pressure() || system->has_contact()) &&
        iteration >= 4 && n_history >= 5 &&
        state.history[n_history - 5].increment == state.increments &&
        record.residual_after >
          0.9 * state.history[n_history - 5].residual_after)
      {
        return "Newton stagnates: the relative residual " +
               Utilities::to_string(record.residual_after, 3) +
               " fell by less than a tenth in four iterations";
      }

    // A line search that keeps cutting the step to almost nothing is
    // not getting anywhere: stop instead of burning the iteration
    // budget (the state is a failure point either way).
    short_steps = record.step_length < 1e-2 ? short_steps + 1 : 0;
    if (short_steps == 4)
      {
        return "Newton stagnates: 4 line-search steps shorter than 1/100 "
               "(relative residual " +
               Utilities::to_string(record.residual_after, 3) + ")";
      }
    return "";
  }



  std::pair<double, double>
  StateSolver::Impl::step_length(const std::vector<double> &x,
                                 const Utilities::Point3   &target,
                                 NewtonIteration           &record,
                                 const bool                 condensed_path,
                                 const unsigned int         iteration)
  {
    // (The condensed step is never the predictor that only moves the
    // probe: its first step is already the contact's Newton step.)
    const auto start = Clock::now();
    auto [best_alpha, best_scale] =
      line_search(x, target, condensed_path ? 1 : iteration);
    if (record.accelerated && best_alpha != 1)
      {
        // The combined step did not reduce the residual at full length:
        // its linear model does not hold here. The plain step, and a new
        // history from it.
        step.swap(plain_step);
        anderson.reset();
        record.accelerated               = false;
        std::tie(best_alpha, best_scale) = line_search(x, target, 1);
      }
    record.line_search_time = seconds_since(start);
    if (condensed_path)
      {
        // What an iteration and a refactorisation cost on this machine and
        // body, as worth_refactorizing() weighs them.
        const double spent = record.solve_time + record.line_search_time;
        double      &cost =
          record.factorized ? refactorization_cost : iteration_cost;
        cost = cost > 0 ? 0.7 * cost + 0.3 * spent : spent;
      }
    return {best_alpha, best_scale};
  }



  // newton(), a step before the first iteration: factors count as the
  // state's only if made in its last increment (this Newton solve), those
  // of an increment before are of another target; nor does Anderson's
  // history carry over.
  void
  StateSolver::Impl::forget_earlier_increments()
  {
    factors_of_state    = false;
    patch_of_state      = false;
    patch_factors_tried = false;
    plain_retried       = false;
    anderson.reset();
  }



  // newton(), a step: the outcome of an iteration whose every trial step
  // inverts an element, with @p record closed as a step of length 0.
  StateSolver::Impl::Outcome
  StateSolver::Impl::inverted_step(NewtonIteration   &record,
                                   State             &state,
                                   const unsigned int iteration) const
  {
    Outcome outcome;
    record.step_length      = 0;
    record.correction       = 0;
    record.residual_after   = record.residual_before;
    record.constraint_after = system->constraint_violation(residual);
    state.history.push_back(record);
    outcome.status     = SolveStatus::inverted_element;
    outcome.iterations = iteration + 1;
    outcome.message    = settings.line_search ?
                           "every step the line search tried inverts an element" :
                           "the Newton step inverts an element";
    return outcome;
  }



  // newton(), a step: the line search's best trial taken as the iterate,
  // @p record completed (at force scale @p scale), the multipliers kept
  // forces; returns the full step's length for converged()'s round-off
  // test, or -1 if it says nothing.
  double
  StateSolver::Impl::accept_step(std::vector<double> &x,
                                 NewtonIteration     &record,
                                 State               &state,
                                 const double         best_alpha,
                                 const double         scale,
                                 const bool           condensed_path)
  {
    x.swap(best_x);
    residual.swap(best_residual);
    record.residual_after   = system->force_residual_norm(residual) / scale;
    record.constraint_after = system->constraint_violation(residual);
    record.step_length      = best_alpha;
    record.correction       = best_alpha * system->max_displacement(step);
    state.history.push_back(record);
    // The round-off test of converged() looks at the full Newton step:
    // a short line-search step says nothing about being close. Nor
    // does a quasi-Newton step on older factors: it is short while the
    // residual is still well above the tolerance.
    const double last_correction = !condensed_path || record.factorized ?
                                     system->max_displacement(step) :
                                     -1;
    // A multiplier the line search left between two forces is still a
    // force: never negative.
    if (condensed_path)
      for (const auto &r : rows)
        x[r.multiplier_eq] = std::max(0.0, x[r.multiplier_eq]);
    return last_correction;
  }



  // newton(), a step on the condensed path: whether the next iteration
  // makes new factors, after @p record, and the rate and count of steps on
  // the kept factors that decide it.
  void
  StateSolver::Impl::plan_next_condensed(const NewtonIteration   &record,
                                         const Utilities::Point3 &target,
                                         const State             &state,
                                         bool                    &refactorize,
                                         double                  &previous_rate,
                                         unsigned int &steps_on_factors)
  {
    steps_on_factors = record.factorized ? 0 : steps_on_factors + 1;
    // An accelerated step that did not cut the residual by a tenth: its
    // history combined steps from before the contact set moved that no
    // longer fit. The factors are not to blame yet: one plain step from a
    // new history (once a Newton solve), judged afresh, before new ones.
    if (settings.anderson_across_contact_changes && record.accelerated &&
        !record.factorized &&
        record.residual_after >= 0.9 * record.residual_before && !plain_retried)
      {
        plain_retried = true;
        anderson.reset();
        previous_rate = 0;
        refactorize   = patch_factors_due(record.residual_after, target, state);
        return;
      }
    refactorize =
      worth_refactorizing(record, previous_rate, steps_on_factors) ||
      patch_factors_due(record.residual_after, target, state);
    previous_rate =
      record.factorized ? 0 : record.residual_after / record.residual_before;
  }



  // newton(), a step: the residual and tangent at the accepted iterate
  // @p x for the next iteration; false, with @p outcome saying so, if they
  // are not finite.
  bool
  StateSolver::Impl::reassemble(const std::vector<double> &x,
                                const Utilities::Point3   &target,
                                const unsigned int         iteration,
                                double                    &scale,
                                double                    &assembly_time,
                                Outcome                   &outcome)
  {
    const auto start   = Clock::now();
    factorized_current = false;
    if (!system->assemble(x, target, residual, &matrix, &scale))
      {
        outcome.status     = SolveStatus::not_finite;
        outcome.iterations = iteration + 1;
        outcome.message = "the tangent cannot be assembled at an accepted step";
        return false;
      }
    assembly_time = seconds_since(start);
    return true;
  }



  StateSolver::Impl::Outcome
  StateSolver::Impl::newton(std::vector<double>     &x,
                            const Utilities::Point3 &target,
                            State                   &state,
                            const bool               may_cut_back)
  {
    // With Contact solver = condensed the same equilibrium (this residual,
    // this convergence test) is reached another way: the factors leave
    // the sphere's contact out and are kept while it moves
    // (condensed_step()). Each iteration then costs a residual, a
    // triangular solve, the compliance columns of candidates that joined
    // and a dense contact problem on a few dozen nodes; no tangent is
    // assembled unless it is factorised.
    const bool condensed_path = settings.condensed_contact && condensed;
    Outcome    outcome;
    double     scale = 0;

    auto start         = Clock::now();
    factorized_current = false;
    if (!system->assemble(
          x, target, residual, condensed_path ? nullptr : &matrix, &scale))
      {
        // The starting state is a converged neighbour, so this is only
        // reachable with a corrupt input state.
        outcome.status  = SolveStatus::not_finite;
        outcome.message = "the starting state is not admissible";
        return outcome;
      }
    double       assembly_time    = seconds_since(start);
    double       last_correction  = -1;
    unsigned int short_steps      = 0;
    double       previous_rate    = 0;
    unsigned int steps_on_factors = 0;
    bool         refactorize      = condensed_path && !contact_free_factors;
    forget_earlier_increments();

    for (unsigned int iteration = 0;; ++iteration)
      {
        if (converged(residual, scale, last_correction))
          {
            outcome.iterations = iteration;
            return outcome;
          }
        if (halt(iteration, scale, outcome))
          return outcome;

        NewtonIteration record;
        record.increment       = state.increments;
        record.residual_before = system->force_residual_norm(residual) / scale;
        record.assembly_time   = assembly_time;

        start = Clock::now();
        const bool with_patch =
          condensed_path &&
          patch_factors_due(record.residual_before, target, state);
        if (!(condensed_path ?
                condensed_step(x, target, record, refactorize, with_patch) :
                newton_step(record)))
          return linear_solver_failure(iteration, condensed_path);
        if (condensed_path)
          record.accelerated = accelerate(x, record.factorized);
        record.solve_time = seconds_since(start);

        const auto [best_alpha, best_scale] =
          step_length(x, target, record, condensed_path, iteration);
        if (best_alpha < 0)
          return inverted_step(record, state, iteration);
        scale = best_scale;
        last_correction =
          accept_step(x, record, state, best_alpha, scale, condensed_path);

        // Stagnation (a start outside the basin, or a line search that
        // gets nowhere): give up this Newton solve early.
        if (const std::string why =
              stagnation(state, record, iteration, may_cut_back, short_steps);
            !why.empty())
          {
            outcome.status     = SolveStatus::max_iterations;
            outcome.iterations = iteration + 1;
            outcome.message    = why;
            return outcome;
          }

        if (converged(residual, scale, last_correction))
          {
            outcome.iterations = iteration + 1;
            return outcome;
          }
        if (condensed_path)
          {
            plan_next_condensed(record,
                                target,
                                state,
                                refactorize,
                                previous_rate,
                                steps_on_factors);
            assembly_time = 0;
            continue;
          }
        if (!reassemble(x, target, iteration, scale, assembly_time, outcome))
          return outcome;
      }
  }



  StateSolver::Impl::Outcome
  StateSolver::Impl::linear_solver_failure(const unsigned int iteration,
                                           const bool         condensed_path)
  {
    Outcome outcome;
    outcome.status     = SolveStatus::linear_solver_failure;
    outcome.iterations = iteration;
    const LinearSolver &solver =
      condensed_path ? kept_factors() : *linear_solver;
    outcome.message =
      solver.message().empty() ? "GMRES did not converge" : solver.message();
    return outcome;
  }



  bool
  StateSolver::Impl::halt(const unsigned int iteration,
                          const double       scale,
                          Outcome           &outcome) const
  {
    outcome.iterations = iteration;
    if (!std::isfinite(scale) ||
        !std::isfinite(system->force_residual_norm(residual)))
      {
        outcome.status = SolveStatus::not_finite;
        outcome.message =
          "the residual or its force scale is not finite (force scale " +
          Utilities::to_string(scale, 3) +
          " N: are the material constants within their physical range?)";
        return true;
      }
    if (stop_check && stop_check())
      {
        outcome.status  = SolveStatus::stopped;
        outcome.message = "a stop was asked for";
        return true;
      }
    if (iteration == settings.max_newton_iterations)
      {
        outcome.status = SolveStatus::max_iterations;
        outcome.message =
          "Newton did not converge in " + std::to_string(iteration) +
          " iterations (relative residual " +
          Utilities::to_string(system->force_residual_norm(residual) / scale,
                               3) +
          ")";
        return true;
      }
    return false;
  }



  StateSolver::StateSolver(const Mesh                      &mesh,
                           const NodeSelection             &nodes,
                           const Parameters::AllParameters &parameters)
    : impl(std::make_unique<Impl>(mesh, nodes, parameters))
  {}



  StateSolver::~StateSolver() = default;



  State
  StateSolver::rest_state() const
  {
    State                     state;
    const std::vector<double> x = impl->system->rest_unknowns();
    impl->system->to_state(x, state);
    if (impl->settings.compute_stiffness &&
        impl->system->assemble(
          x, state.active_displacement, impl->residual, &impl->matrix))
      {
        impl->factorized_current = false;
        state.has_stiffness      = impl->active_stiffness(state);
      }
    if (impl->patch_reach > 0 && impl->system->has_contact())
      {
        impl->factors_of_state = false;
        impl->patch_of_state   = false;
        impl->contact_patch(state, x);
      }
    // With no load but the sphere's, the rest configuration is the free
    // equilibrium: its residual is round-off, far below the force scale
    // (at rest that is the floor 1e-12 E L^2; any other load makes the
    // residual of the order of the scale, and a converged state without
    // contact force shows the equilibrium later).
    double scale = 0;
    if (impl->system->has_contact() &&
        impl->system->assemble(
          x, state.active_displacement, impl->residual, nullptr, &scale) &&
        impl->system->force_residual_norm(impl->residual) <= 1e-3 * scale &&
        impl->system->constraint_violation(impl->residual) == 0)
      impl->remember_if_free(state, x);
    return state;
  }



  State
  StateSolver::solve(const State &from, const Utilities::Point3 &target)
  {
    return solve(from, target, nullptr);
  }



  State
  StateSolver::solve(const State             &from,
                     const Utilities::Point3 &target,
                     const State             *behind,
                     const State             *behind2)
  {
    const auto start = Clock::now();
    State      state;
    state.active_displacement = target;

    if (!impl->admissible_start(from, target, state))
      return state;

    const auto         &s = impl->settings;
    std::vector<double> x = impl->system->from_state(from);
    // A sphere that clears the body's free equilibrium leaves it there:
    // the state is that equilibrium, with no path to walk to it.
    const bool   free   = impl->start_free(target, x);
    const auto   a      = free ? target : from.active_displacement;
    const double length = Utilities::distance(a, target);
    // A path of more than 1000 increments is not a haptic interaction
    // but a mistake; refuse it rather than work for minutes.
    const double needed = impl->increments_needed(length);
    if (needed > 1000)
      return impl->too_far(x, length, state);
    const unsigned int n = static_cast<unsigned int>(needed);
    const auto point = [&](const double t) { return path_point(a, target, t); };

    // One increment from parameter t0 to t1 of the path, halved up to
    // max_cutbacks times if it fails. After the first increment, Newton
    // starts from the secant predictor: the previous increment's change,
    // extrapolated (it puts the active node on its new target, and is
    // usually much closer to equilibrium than the previous state).
    Impl::Outcome       failure;
    std::vector<double> previous; // converged unknowns one increment back
    double              previous_t = 0, current_t = 0;

    // A state behind the source on the line to the target is the
    // increment before the first one: the secant predictor below then
    // extrapolates it to the first increment's end.
    if (!free)
      impl->predictor_from_behind(
        from, target, behind, behind2, n, x, previous, previous_t);
    const unsigned int                                work_limit = 2000 + 8 * n;
    std::function<bool(double, double, unsigned int)> increment =
      [&](const double t0, const double t1, const unsigned int depth) {
        const std::vector<double> saved = x;
        const bool                predicted =
          !previous.empty() && t0 == current_t && current_t > previous_t &&
          impl->secant_predictor(x,
                                 previous,
                                 (t1 - t0) / (current_t - previous_t),
                                 point(t1));
        // All the Newton iterations one solve may take, its increments,
        // cutbacks and retries together: each limit alone is bounded, but
        // 1000 increments, 1000 iterations each and 30 cutbacks together
        // run for minutes. A state takes 4-8 per increment; this is far
        // beyond any that converges.
        if (state.newton_iterations >= work_limit)
          {
            x       = saved; // the last equilibrium, not the predictor's guess
            failure = Impl::out_of_work(state.newton_iterations);
            return false;
          }
        ++state.increments;
        const bool    may_cut_back = depth < s.max_cutbacks;
        Impl::Outcome o            = impl->solve_increment(
          x, saved, point(t1), state, may_cut_back, predicted);
        state.max_increment_iterations =
          std::max(state.max_increment_iterations, o.iterations);
        if (o.status == SolveStatus::converged)
          {
            impl->notify_observer(x, point(t1), t1);
            previous   = saved;
            previous_t = t0;
            current_t  = t1;
            return true;
          }
        const bool cut_back = depth < s.max_cutbacks &&
                              o.status != SolveStatus::inverted_element &&
                              o.status != SolveStatus::stopped;
        // Read from the failed iterate, before it is set back; only for
        // the increment that ends the solve.
        const std::string cause =
          cut_back ? std::string() : impl->failure_cause(x, point(t1), o);
        x = saved;
        if (cut_back)
          {
            const double middle = 0.5 * (t0 + t1);
            return increment(t0, middle, depth + 1) &&
                   increment(middle, t1, depth + 1);
          }
        failure = o;
        failure.message += " (increment to " +
                           Utilities::to_string(point(t1), 4) + " m)" + cause;
        return false;
      };

    bool ok = true;
    for (unsigned int i = 1; i <= n && ok && !free; ++i)
      ok = increment(double(i - 1) / n, double(i) / n, 0);

    impl->finish(x, ok, failure, state);
    state.wall_time = seconds_since(start);
    return state;
  }



  void
  StateSolver::set_increment_observer(
    std::function<void(const State &, double)> observer)
  {
    impl->observer = std::move(observer);
  }



  void
  StateSolver::set_stop_check(std::function<bool()> stop_check)
  {
    impl->stop_check = std::move(stop_check);
  }



  const HyperelasticSystem &
  StateSolver::system() const
  {
    return *impl->system;
  }



  HyperelasticSystem &
  StateSolver::system()
  {
    return *impl->system;
  }



  std::string
  StateSolver::linear_solver_name() const
  {
    return impl->linear_solver->name();
  }



  std::string
  StateSolver::linear_solver_statistics() const
  {
    return impl->linear_solver->statistics();
  }



  Parameters::NonlinearSolver &
  StateSolver::settings()
  {
    return impl->settings;
  }



  double
  StateSolver::setup_time() const
  {
    return impl->setup_time;
  }
} // namespace palpate
