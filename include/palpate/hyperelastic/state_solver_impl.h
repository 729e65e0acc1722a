// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

#ifndef palpate_hyperelastic_state_solver_impl_h
#define palpate_hyperelastic_state_solver_impl_h

// Not an interface: StateSolver's implementation, shared by its source
// files (state_solver.cc: Newton's method and the staging's driver;
// state_solver_staging.cc: the staging's checks and predictors, and
// solve()'s steps around each increment;
// state_solver_condensed.cc: the condensed contact's Newton steps).

#include <palpate/hyperelastic/anderson_acceleration.h>
#include <palpate/hyperelastic/condensed_contact.h>
#include <palpate/hyperelastic/effect.h>
#include <palpate/hyperelastic/hyperelastic_system.h>
#include <palpate/hyperelastic/inverse_block.h>
#include <palpate/hyperelastic/linear_solver.h>
#include <palpate/hyperelastic/state_solver.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <functional>
#include <memory>
#include <string>
#include <vector>

namespace palpate
{
  namespace internal
  {
    /**
     * GMRES with right preconditioning for A x = b, from x = 0: Arnoldi
     * with modified Gram-Schmidt and Givens rotations, no restart.
     * @p precondition applies M^-1 in place (the kept factorisation of an
     * earlier tangent). On success @p b holds x with |b - A x| <= @p
     * tolerance |b|, and the number of iterations is returned; 0 if it
     * did not converge in @p max_iterations (then @p b is unchanged) or the
     * preconditioner failed.
     *
     * Why GMRES: the tangent with the multiplier rows is symmetric but
     * indefinite, and so is an LDL^T preconditioner, which rules out CG and
     * MINRES; GMRES needs neither property, and with a preconditioner
     * from a nearby state it converges in a few iterations.
     */
    unsigned int
    gmres(const SparsityCSR                                &pattern,
          const std::vector<double>                        &matrix,
          const std::function<bool(std::vector<double> &)> &precondition,
          std::vector<double>                              &b,
          const double                                      tolerance,
          const unsigned int                                max_iterations,
          std::vector<std::vector<double>>                 &V,
          std::vector<std::vector<double>>                 &Z);
  } // namespace internal



  struct StateSolver::Impl
  {
    Impl(const Mesh                      &mesh,
         const NodeSelection             &nodes,
         const Parameters::AllParameters &p)
      : settings(p.nonlinear_solver)
      , anderson(p.nonlinear_solver.anderson_depth)
    {
      // What each state keeps beside its force is what the interpolation
      // that renders the states reads, as its plug-in declares it.
      const Plugins::StateContents kept = p.state_space.state_contents();
      settings.compute_stiffness = settings.compute_stiffness || kept.stiffness;
      // The patch holds every node the sphere can touch from the cells
      // around the state (its centre within h of the state's in each
      // axis), and a quarter radius more for the surface springing back
      // towards the sphere when it is lifted.
      if (kept.contact_patch)
        patch_reach = 1.25 * p.boundary_conditions.active_node.tip_radius;
      grid_spacing     = p.state_space.grid_spacing;
      const auto start = std::chrono::steady_clock::now();
      system           = std::make_unique<HyperelasticSystem>(mesh, nodes, p);
      // The load effects the scene switches on, and only those.
      for (const auto &effect : Effect::create_enabled(p.effects))
        effect->apply(*system, p);
      settings.reuse_factorization = settings.reuse_for(system->n_equations());
      settings.reuse_by_size       = false;
      // The ordering by the system's size unless the scene fixes it: the
      // fill of nested dissection grows more slowly with the mesh than
      // AMF's, which is cheaper to compute and as good on small meshes.
      ordering = p.linear_solver.ordering_for(system->n_equations());
      Parameters::LinearSolver chosen = p.linear_solver;
      chosen.ordering                 = ordering;
      linear_solver = LinearSolver::create(chosen, system->n_equations());
      linear_solver->analyze(system->sparsity());
      if (system->has_contact())
        condensed = std::make_unique<CondensedContact>(*system);
      setup_time = Utilities::seconds_since(start);
    }

    /** What one Newton solve of one increment ended with. */
    struct Outcome
    {
      SolveStatus  status = SolveStatus::converged;
      std::string  message;
      unsigned int iterations = 0;
    };

    /** s = R_u . dx_u: the derivative of the energy along the step dx
     * once the constraints hold. */
    double
    directional_derivative(const std::vector<double> &residual,
                           const std::vector<double> &dx) const
    {
      const unsigned int n = system->n_equations() - system->n_multipliers();
      double             s = 0;
      for (unsigned int i = 0; i < n; ++i)
        s += residual[i] * dx[i];
      return s;
    }

    /**
     * Newton's method for the active node at @p target, from @p x. With
     * @p may_cut_back (the increment can still be halved), a Newton
     * iteration that stagnates is given up early, so that the halved
     * increment gets the iterations instead.
     */
    Outcome
    newton(std::vector<double>     &x,
           const Utilities::Point3 &target,
           State                   &state,
           const bool               may_cut_back = false);

    // newton()'s steps.
    /** Before the first iteration: the factors and the contact patch of
     * an earlier increment (another target) no longer count as the
     * state's, and Anderson's history restarts. */
    void
    forget_earlier_increments();

    /** The outcome of Newton iteration @p iteration whose every trial
     * step inverts an element; @p record closed and added to @p state. */
    Outcome
    inverted_step(NewtonIteration   &record,
                  State             &state,
                  const unsigned int iteration) const;

    /** Take the line search's best trial (step length @p best_alpha) as
     * the iterate @p x, complete @p record at force scale @p scale and add
     * it to @p state; returns the full step's length for converged(), or
     * -1 if it says nothing of being close. */
    double
    accept_step(std::vector<double> &x,
                NewtonIteration     &record,
                State               &state,
                const double         best_alpha,
                const double         scale,
                const bool           condensed_path);

    /** On the condensed path after @p record: whether the next iteration
     * is to @p refactorize, with @p previous_rate and @p steps_on_factors
     * brought up to date (or, after an accelerated step that failed, a
     * plain step first: anderson restarts). */
    void
    plan_next_condensed(const NewtonIteration   &record,
                        const Utilities::Point3 &target,
                        const State             &state,
                        bool                    &refactorize,
                        double                  &previous_rate,
                        unsigned int            &steps_on_factors);

    /** Assemble the residual and tangent at the accepted iterate @p x
     * (its force scale into @p scale, the time into @p assembly_time);
     * false, @p outcome saying so, if they are not finite. */
    bool
    reassemble(const std::vector<double> &x,
               const Utilities::Point3   &target,
               const unsigned int         iteration,
               double                    &scale,
               double                    &assembly_time,
               Outcome                   &outcome);

    // solve()'s steps.
    /** The secant predictor: @p x plus @p r times its change since
     * @p previous, if the residual there (at the increment's @p end) is
     * finite; whether @p x was moved. */
    bool
    secant_predictor(std::vector<double>       &x,
                     const std::vector<double> &previous,
                     const double               r,
                     const Utilities::Point3   &end);

    /** Newton's method for an increment's @p end from @p x, retried from
     * the last equilibrium @p saved if a @p predicted start failed; its
     * iterations are counted in @p state. */
    Outcome
    solve_increment(std::vector<double>       &x,
                    const std::vector<double> &saved,
                    const Utilities::Point3   &end,
                    State                     &state,
                    const bool                 may_cut_back,
                    const bool                 predicted);

    /** Tell the increment observer, if any, of the converged state @p x
     * at @p end, parameter @p t of the path. */
    void
    notify_observer(const std::vector<double> &x,
                    const Utilities::Point3   &end,
                    const double               t) const;

    /** @p state from the unknowns @p x a solve reached: a failure point
     * (@p failure says why) unless @p ok and the end is acceptable, else
     * converged, with its derivatives. */
    void
    finish(const std::vector<double> &x,
           bool                       ok,
           Outcome                   &failure,
           State                     &state);

    /**
     * The Newton step of Contact solver = condensed into `step` (from
     * `residual` at @p x), with the factors renewed first if
     * @p refactorize (with the contact patch's Schur complement if
     * @p with_patch); fills @p record's solver fields. False if the linear
     * solver failed.
     */
    bool
    condensed_step(const std::vector<double> &x,
                   const Utilities::Point3   &target,
                   NewtonIteration           &record,
                   bool                       refactorize,
                   bool                       with_patch);

    /** The line search along the step just made (the plain step if an
     * accelerated one does not reduce the residual at full length), its
     * time in @p record, and the cost model's update: the step length
     * taken (negative if every step tried inverts an element) and the
     * force scale there. */
    std::pair<double, double>
    step_length(const std::vector<double> &x,
                const Utilities::Point3   &target,
                NewtonIteration           &record,
                bool                       condensed_path,
                unsigned int               iteration);

    /**
     * Whether the next condensed Newton iteration should factorise the
     * tangent anew, after the iteration @p record (its relative residual
     * before and after), the rate of the one before it and the
     * @p steps_on_factors taken in this Newton solve since factors were
     * last made (all of them if none were).
     */
    bool
    worth_refactorizing(const NewtonIteration &record,
                        const double           previous_rate,
                        const unsigned int     steps_on_factors) const;

    /** With Anderson depth > 0: record the condensed step just made and
     * turn it into the accelerated one (the plain one kept in plain_step);
     * the history restarts on new factors (@p factorized_now) or a new set
     * of nodes in contact. Whether the step was changed. */
    bool
    accelerate(const std::vector<double> &x, bool factorized_now);

    /** Assemble the contact-free tangent at @p x and factorise it; the
     * compliance columns of the old factors are dropped. */
    bool
    factorize_contact_free(const std::vector<double> &x,
                           const Utilities::Point3   &target);

    /** What a converged @p state at @p x carries beside its field: the
     * probe's stiffness if asked for, the contact patch with
     * Interpolation = contact patch. */
    void
    derivatives(State &state, const std::vector<double> &x);

    /** The contact patch of the converged @p state at @p x, its
     * compliance from the contact-free tangent there (inverse_block), or
     * from the factors factorize_with_patch() made at an iterate of its
     * last Newton solve. False if that fails. */
    bool
    contact_patch(State &state, const std::vector<double> &x);

    /**
     * Assemble the contact-free tangent at @p x and factorise it with the
     * DoFs of the contact patch's nodes there as a Schur complement
     * (inverse_block): the patch's compliance block into patch_block, and
     * its factors become the kept ones. False if that fails (then the
     * condensed path has no kept factors) or there is no node within reach
     * (then the state's patch is the empty one, patch_of_state, and the
     * kept factors stay).
     */
    bool
    factorize_with_patch(const std::vector<double> &x,
                         const Utilities::Point3   &target);

    /** Whether the contact patch's factors are to be made now, in the
     * Newton solve for @p target of @p state at relative residual
     * @p residual: a patch is wanted, this is the state's last increment,
     * the iterate is close enough to the state (or, with a tolerance too
     * coarse for that, a step from converging) and none were made yet. */
    bool
    patch_factors_due(const double             residual,
                      const Utilities::Point3 &target,
                      const State             &state) const
    {
      return patch_reach > 0 && condensed && settings.condensed_contact &&
             settings.patch_factor_residual > 0 && !patch_of_state &&
             !patch_factors_tried &&
             residual <= std::max(settings.patch_factor_residual,
                                  10 * settings.residual_tolerance) &&
             target == state.active_displacement;
    }

    /** The factors the condensed path's steps solve with: the linear
     * solver's, or the Schur complement's of the last patch. */
    LinearSolver &
    kept_factors()
    {
      return kept_are_schur ? *schur_factors : *linear_solver;
    }

    /** The active-node stiffness of a converged state from the condensed
     * contact problem on the kept factors (Contact solver = condensed). */
    bool
    condensed_stiffness(State &state);

    /** Whether Newton must stop before iteration @p iteration (the
     * residual in `residual`, its force scale @p scale): not finite, a
     * stop asked for, or out of iterations; @p outcome then says so. */
    bool
    halt(const unsigned int iteration,
         const double       scale,
         Outcome           &outcome) const;

    /** The failure of a solve that used up its Newton work. */
    static Outcome
    out_of_work(const unsigned int iterations);

    /** How many increments a path of @p length takes: Number of
     * increments, more if they would be longer than Maximum increment
     * length or (with a sphere) its radius. */
    double
    increments_needed(const double length) const;

    /** Whether @p from is a start for a solve to @p target: a finite
     * target, and a converged, finite state of this body. If not, @p state
     * is the failure point that says so. */
    bool
    admissible_start(const State             &from,
                     const Utilities::Point3 &target,
                     State                   &state) const;

    /** A converged state behind @p from on the line to @p target (and a
     * second one behind it, for one increment) as the increment before the
     * first: sets @p previous and @p previous_t for the secant predictor,
     * or leaves them empty. */
    void
    predictor_from_behind(const State               &from,
                          const Utilities::Point3   &target,
                          const State               *behind,
                          const State               *behind2,
                          const unsigned int         n,
                          const std::vector<double> &x,
                          std::vector<double>       &previous,
                          double                    &previous_t) const;

    /** Whether the sphere at @p target clears the body's free equilibrium
     * (free_equilibrium, once known): no node touches it and its centre
     * is a radius from the surface. That equilibrium is then the state
     * at @p target. */
    bool
    clears_free_equilibrium(const Utilities::Point3 &target) const;

    /** The failure point of a target @p length (m) away, more than 1000
     * increments: @p state at the start @p x, refused. */
    State
    too_far(const std::vector<double> &x, double length, State &state) const;

    /** If the sphere at @p target clears the free equilibrium: @p x is
     * that equilibrium, the state at @p target without a Newton solve
     * (true). */
    bool
    start_free(const Utilities::Point3 &target, std::vector<double> &x);

    /** The failure of a Newton step whose linear solve failed, at
     * @p iteration. */
    Outcome
    linear_solver_failure(unsigned int iteration, bool condensed_path);

    /** Keep @p x as the free equilibrium if the converged @p state has no
     * contact force (and none is kept yet). */
    void
    remember_if_free(const State &state, const std::vector<double> &x);

    /** Whether the converged end @p x (in @p state) is one to hand out: a
     * finite force and, with a sphere, a sphere still outside the deformed
     * surface. Otherwise @p failure says why. */
    bool
    acceptable_end(const std::vector<double> &x,
                   State                     &state,
                   Outcome                   &failure) const;

    /** Why an increment to @p target that did not converge (@p o) may
     * have failed, read from its last iterate @p x, as a clause to append
     * to its message (empty if nothing is known): a sphere near the end
     * acceptable_end() refuses. */
    std::string
    failure_cause(const std::vector<double> &x,
                  const Utilities::Point3   &target,
                  const Outcome             &o) const;

    /** The Newton step K dx = -R into `step` (from `residual`), exactly or
     * by GMRES on a kept factorisation; fills @p record's solver fields.
     * False if the linear solver failed. */
    bool
    newton_step(NewtonIteration &record);

    /** The step length along `step` from @p x: the accepted trial is left
     * in best_x and best_residual. Returns (alpha, force scale there);
     * alpha < 0 when every step tried inverts an element. */
    /** Why the Newton solve stagnates after @p record (its last
     * accepted step), or "": no progress from a start outside the basin,
     * or a line search cutting every step short (counted in
     * @p short_steps). */
    std::string
    stagnation(const State           &state,
               const NewtonIteration &record,
               const unsigned int     iteration,
               const bool             may_cut_back,
               unsigned int          &short_steps) const;

    std::pair<double, double>
    line_search(const std::vector<double> &x,
                const Utilities::Point3   &target,
                const unsigned int         iteration);

    /**
     * Whether @p residual is an equilibrium: force residual below the
     * tolerance relative to the force scale and the constraints satisfied;
     * or, where round-off keeps the residual from going lower, a negligible
     * last full Newton step and a residual within 1000 times the tolerance.
     */
    bool
    converged(const std::vector<double> &residual,
              const double               force_scale,
              const double               last_correction) const
    {
      // Nothing non-finite is ever an equilibrium: with an infinite force
      // scale (E = 1e300) every residual would pass the relative test.
      const double L         = system->length_scale();
      const double violation = system->constraint_violation(residual);
      const double r         = system->force_residual_norm(residual);
      if (!std::isfinite(force_scale) || !(force_scale > 0) ||
          !std::isfinite(violation) || !std::isfinite(r))
        return false;
      if (violation > settings.increment_tolerance * L)
        return false;
      if (r <= settings.residual_tolerance * force_scale)
        return true;
      return last_correction >= 0 &&
             last_correction <= settings.increment_tolerance * L &&
             r <= 1e3 * settings.residual_tolerance * force_scale;
    }

    /**
     * GMRES on the tangent in matrix to @p tolerance, preconditioned by the
     * linear solver's factors (of this tangent or an earlier one): @p rhs
     * holds b on entry and x on success. The iterations; 0 if it failed,
     * and then @p rhs is unchanged.
     */
    unsigned int
    preconditioned_gmres(std::vector<double> &rhs, const double tolerance)
    {
      return internal::gmres(
        system->sparsity(),
        matrix,
        [this](std::vector<double> &v) { return linear_solver->solve(v); },
        rhs,
        tolerance,
        settings.max_krylov_iterations,
        krylov_v,
        krylov_z);
    }

    /**
     * Factorise the tangent in matrix and solve with it in place: a direct
     * solve, or with mixed precision GMRES to @p tolerance preconditioned
     * by the fresh factors (one to three iterations, counted in
     * @p krylov_iterations); if the single-precision factors fail, MUMPS in
     * double from then on. False if the linear solver fails.
     */
    bool
    factorize_and_solve(std::vector<double> &rhs,
                        const double         tolerance,
                        unsigned int        &krylov_iterations)
    {
      factorized = factorized_current = contact_free_factors = false;
      kept_are_schur                                         = false;
      krylov_iterations                                      = 0;
      bool solved = linear_solver->factorize(matrix);
      if (solved && linear_solver->exact())
        solved = linear_solver->solve(rhs);
      else if (solved)
        {
          krylov_iterations = preconditioned_gmres(rhs, tolerance);
          solved            = krylov_iterations > 0;
        }
      // rhs is still b after a failed factorisation or GMRES.
      if (!solved && fall_back_to_double())
        solved = linear_solver->factorize(matrix) && linear_solver->solve(rhs);
      factorized = factorized_current = solved;
      return solved;
    }

    /**
     * A mixed-precision solver whose GMRES failed on a tangent (single
     * precision too coarse for it): replace it by MUMPS in double for the
     * rest of this solver's life. True if it did (the caller retries).
     */
    bool
    fall_back_to_double()
    {
      if (linear_solver->exact())
        return false;
      linear_solver = LinearSolver::create("MUMPS", ordering);
      linear_solver->analyze(system->sparsity());
      factorized = factorized_current = contact_free_factors = false;
      kept_are_schur                                         = false;
      return true;
    }

    std::unique_ptr<HyperelasticSystem>        system;
    std::unique_ptr<LinearSolver>              linear_solver;
    std::string                                ordering;
    Parameters::NonlinearSolver                settings;
    double                                     setup_time = 0;
    std::function<void(const State &, double)> observer;
    std::function<bool()>                      stop_check;
    // The condensed path's acceleration, the plain step it started from,
    // and which candidates' rows were in contact after the last step (a
    // change restarts it unless settings.anderson_across_contact_changes);
    // whether this Newton solve has retried a failed accelerated step
    // plain (plan_next_condensed()).
    AndersonAcceleration anderson;
    std::vector<double>  plain_step;
    std::vector<char>    in_contact, was_in_contact;
    bool                 plain_retried = false;
    // The contact patches' compliance (made when the first is wanted),
    // its factors as a solver, and whether they are the kept factors.
    std::unique_ptr<InverseBlock> inverse_block;
    std::unique_ptr<SchurFactors> schur_factors;
    bool                          kept_are_schur = false;
    std::vector<double>           patch_tangent;
    // The patch's nodes, DoFs and compliance block from the factors of
    // the state's last Newton solve (patch_of_state), made once its
    // relative residual is below settings.patch_factor_residual: the
    // tangent there is the converged one's to that order, and the Newton
    // steps after it and the next state's iterate on them.
    bool patch_of_state = false;
    // Whether this Newton solve tried them (once: a failed partial
    // factorisation, say of a tangent single precision cannot take, is
    // not tried again at every step).
    bool                      patch_factors_tried = false;
    std::vector<unsigned int> patch_nodes, patch_unknowns;
    std::vector<double>       patch_block;
    std::vector<int>          schur_slot; // DoF -> row

    std::vector<HyperelasticSystem::ContactRow> patch_rows;
    // With Interpolation = contact patch: how far a patch's nodes may be
    // from the box of sphere centres around the state (m); 0: no patches.
    double patch_reach = 0;
    // The grid's spacing (m): where a patch tabulates its model's force.
    double grid_spacing = 0;

    // The body's equilibrium with the sphere touching nothing (empty
    // until a state shows it), and the rows of a check against it.
    std::vector<double>                                 free_equilibrium;
    mutable std::vector<HyperelasticSystem::ContactRow> free_rows;

    // Work vectors, reused from solve to solve.
    std::vector<double> residual, trial_residual, best_residual, matrix, step,
      trial, best_x;
    // Whether the linear solver holds a factorisation (of the tangent of
    // an earlier Newton step, in this state or an earlier one), and the
    // Krylov bases of GMRES.
    bool factorized = false;
    // Whether that factorisation is of the tangent in matrix.
    bool                             factorized_current = false;
    std::vector<std::vector<double>> krylov_v, krylov_z;

    // Condensed contact: whether the kept factors are of a contact-free
    // tangent (only then do the compliance columns of `condensed` hold),
    // and the candidates' rows at the current iterate.
    bool contact_free_factors = false;
    // Whether they were made in the last Newton solve (the state's last
    // increment), and the relative residual of the iterate they were made
    // at.
    bool   factors_of_state  = false;
    double factored_residual = 0;
    // Seconds of a condensed Newton iteration on kept factors and of one
    // that factorises (with the compliance columns after it): running
    // averages, 0 until measured.
    double iteration_cost = 0, refactorization_cost = 0;
    std::vector<HyperelasticSystem::ContactRow> rows;
    std::unique_ptr<CondensedContact>           condensed;

    /**
     * The active-node stiffness of a converged @p state, from the tangent
     * of its last Newton step (in matrix). That tangent is one iterate
     * behind the converged state, which Newton's quadratic convergence
     * puts within about 1e-4 of the state's own stiffness (measured
     * against finite differences on liver501: 1.4e-4 StVK, 3.8e-4
     * neo-Hookean): far below what interpolation on a grid can resolve,
     * for no assembly and, after an exact Newton step, no factorisation.
     * Moving the probe by dg changes the residual by dR = -probe_load dg
     * (for a point probe -beta dg at its constraint rows; for a sphere the
     * rows of the nodes in contact), so K dx = probe_load dg gives the
     * change of the state, probe_force_change() turns it into df, and
     * -df/dg is the stiffness: three solves
     * with the factorisation (direct if it is of this tangent, else GMRES
     * to 1e-6 preconditioned by it, else - when GMRES needs more than
     * Maximum Krylov iterations - a new factorisation, which then also
     * preconditions the next states). False if the linear solver fails.
     */
    bool
    active_stiffness(State &state);
  };
} // namespace palpate

#endif
