// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

// The Newton steps of Contact solver = condensed (StateSolver::Impl): when
// to renew the contact-free factors, the step with the contact solved on
// the candidates' compliance, and the probe's stiffness from it.

#include <palpate/hyperelastic/contact_patch.h>
#include <palpate/hyperelastic/patch_contact.h>
#include <palpate/hyperelastic/state_solver_impl.h>

#include <algorithm>
#include <cmath>

namespace palpate
{
  bool
  StateSolver::Impl::worth_refactorizing(
    const NewtonIteration &record,
    const double           previous_rate,
    const unsigned int     steps_on_factors) const
  {
    if (record.factorized)
      return false;
    const double r = record.residual_after;
    // An accelerated step is judged by its own ratio: the plain step
    // before it may have risen while the contact set moved, and the
    // history has taken that in.
    const double rate =
      settings.anderson_across_contact_changes && record.accelerated ?
        r / record.residual_before :
        std::max(r / record.residual_before, previous_rate);
    // A state whose stiffness is wanted needs factors of an iterate one
    // Newton step from it (condensed_stiffness()): made as soon as the
    // residual is that close, they also make the last steps exact.
    if (settings.compute_stiffness && !factors_of_state && r <= 1e-4)
      return true;
    // Factors of an older tangent cut the residual by a fixed ratio per
    // step. The relative residual's ratio, because once the sphere lets go
    // the residual is the internal force itself and stays at 1 relative
    // to it under any fixed factors, while exact steps reach rest in a few.
    if (previous_rate == 0)
      return false; // one ratio measured is no rate yet
    if (rate >= 0.9)
      return true;
    // Accelerated steps converge much faster than the plain rate says
    // (0.78 per plain step while the contact set settles, then 0.1-0.3
    // accelerated: doc/benchmarks/organ-speed.md), so the rate does not
    // predict what is left. Factors that still contract are kept until
    // three quarters of the iterations an increment may take are spent
    // on them (a fresh factorisation then converges in two or three).
    if (anderson.depth() > 0)
      return 4 * steps_on_factors >= 3 * settings.max_newton_iterations;
    // Otherwise: when the iterations left at this rate cost more than a
    // factorisation (and its columns) and the two or three exact steps
    // after it.
    const double left =
      std::log(settings.residual_tolerance / std::max(r, 1e-300)) /
      std::log(rate);
    // With the stiffness wanted, factors made this far from the state
    // will be made again at its end: they cost twice.
    const double factorization =
      (refactorization_cost > 0 ? refactorization_cost : 20 * iteration_cost) *
      (settings.compute_stiffness ? 2 : 1);
    return left * iteration_cost > factorization + 2 * iteration_cost;
  }



  bool
  StateSolver::Impl::factorize_contact_free(const std::vector<double> &x,
                                            const Utilities::Point3   &target)
  {
    // The tangent without the contact rows (every candidate's row is that
    // of a node out of contact): the same matrix whatever the active set,
    // so its factors serve while the sphere's contact set moves.
    if (!system->assemble(x, target, trial_residual, &matrix, nullptr, false))
      return false;
    factorized = factorized_current = contact_free_factors = false;
    kept_are_schur                                         = false;
    bool ok = linear_solver->factorize(matrix);
    if (!ok && fall_back_to_double())
      ok = linear_solver->factorize(matrix);
    factorized = contact_free_factors = ok;
    condensed->reset();
    return ok;
  }



  bool
  StateSolver::Impl::condensed_step(const std::vector<double> &x,
                                    const Utilities::Point3   &target,
                                    NewtonIteration           &record,
                                    const bool                 refactorize,
                                    const bool                 with_patch)
  {
    // The factors are of the contact-free tangent of some earlier iterate,
    // possibly of an earlier state, renewed only where that pays
    // (worth_refactorizing()). The step is then K^-1 (-R) with the
    // candidates' forces lambda = beta x_lambda held, the residual's
    // contact forces lambda_hat replaced by lambda (they differ where the
    // last step left a gap open or closed) and nothing on the contact rows,
    // turned by CondensedContact into the step with the contact solved.
    record.factorized = refactorize;
    if (refactorize)
      {
        factors_of_state  = true;
        factored_residual = record.residual_before;
        // Close to the state, the factors are made with the contact patch
        // as a Schur complement: the same factors for these steps, and the
        // patch's compliance without a factorisation of its own.
        patch_factors_tried = patch_factors_tried || with_patch;
        if (!(with_patch && factorize_with_patch(x, target)) &&
            !factorize_contact_free(x, target))
          return false;
      }
    const double beta = system->constraint_scale();
    system->contact_rows(x, target, rows);
    step = residual;
    for (const auto &r : rows)
      {
        const double lambda = beta * x[r.multiplier_eq];
        for (unsigned int a = 0; a < 3; ++a)
          if (r.eq[a] >= 0)
            step[r.eq[a]] += (r.lambda_hat - lambda) * r.n[a];
        step[r.multiplier_eq] = 0;
      }
    for (double &v : step)
      v = -v;
    return kept_factors().solve(step) &&
           condensed->step(kept_factors(),
                           x,
                           rows,
                           step,
                           1e-3 * settings.increment_tolerance *
                             system->length_scale());
  }



  bool
  StateSolver::Impl::accelerate(const std::vector<double> &x,
                                const bool                 factorized_now)
  {
    if (anderson.depth() == 0)
      return false;
    // The map the steps come from changes with the factors: then a new
    // history. It changes too with the set of nodes the step leaves
    // touching the sphere (the contact's map is smooth only while that set
    // holds), but a history across those changes still converges where
    // restarting at each leaves plain steps contracting by 0.75-0.98 while
    // the set settles, and new factors to follow (organ-speed.md); a step
    // the history fails is retried plain (plan_next_condensed()).
    bool contact_set_changed = false;
    if (!settings.anderson_across_contact_changes)
      {
        in_contact.resize(rows.size());
        for (unsigned int k = 0; k < rows.size(); ++k)
          in_contact[k] =
            x[rows[k].multiplier_eq] + step[rows[k].multiplier_eq] > 0;
        contact_set_changed = in_contact != was_in_contact;
        was_in_contact.swap(in_contact);
      }
    if (factorized_now || contact_set_changed)
      anderson.reset();
    plain_step = step;
    return anderson.accelerate(x, step);
  }



  bool
  StateSolver::Impl::condensed_stiffness(State &state)
  {
    // From the kept contact-free factors, like the Newton steps: within
    // their quasi-Newton distance of the converged tangent.
    const std::vector<double> x = system->from_state(state);
    // With no node in contact a small move of the sphere touches nothing:
    // the stiffness is zero (a state in the air, its free start made no
    // factors).
    system->contact_rows(x, state.active_displacement, rows);
    if (std::none_of(rows.begin(), rows.end(), [](const auto &r) {
          return r.lambda_hat > 0;
        }))
      {
        state.stiffness.fill(0.0);
        return true;
      }
    if (!contact_free_factors)
      return false;
    // The stiffness is exact for the tangent the factors are of: within
    // one Newton step of the state it is within that step's distance, as
    // active_stiffness() is; older factors (another state's, an early
    // iterate's) give it only to their quasi-Newton distance: 1 % on the
    // liver, a factor 2 under one node pushed 1.5 mm into the coarse beam
    // (tests/hyperelastic/condensed_contact). New factors here also start
    // the neighbouring state.
    if (!(factors_of_state && factored_residual <= 1e-4))
      {
        ++state.stiffness_factorizations;
        if (!factorize_contact_free(x, state.active_displacement))
          return false;
      }
    return condensed->stiffness(kept_factors(), x, rows, state.stiffness);
  }



  bool
  StateSolver::Impl::factorize_with_patch(const std::vector<double> &x,
                                          const Utilities::Point3   &target)
  {
    if (!inverse_block)
      {
        inverse_block = std::make_unique<InverseBlock>(system->sparsity());
        schur_factors = std::make_unique<SchurFactors>(*inverse_block);
      }
    system->contact_rows(x, target, patch_rows);
    contact_patch_nodes(
      patch_rows, grid_spacing, patch_reach, patch_nodes, patch_unknowns);
    if (patch_nodes.empty())
      {
        // No node within reach: the state's patch is the empty one, and
        // there is nothing to factorise it on (the kept factors stay).
        patch_of_state = true;
        return false;
      }
    // A new partial factorisation replaces the one the kept factors may
    // be, and the block the condensed contact reads.
    if (kept_are_schur)
      {
        contact_free_factors = kept_are_schur = false;
        condensed->reset();
      }
    if (!system->assemble(
          x, target, trial_residual, &patch_tangent, nullptr, false) ||
        !inverse_block->compute(patch_tangent, patch_unknowns, patch_block))
      return false;
    patch_of_state = true;
    // The condensed path iterates on these factors (the Newton steps
    // after them, the next state's): they are of the contact-free tangent
    // near the state, as its own would be. (The linear solver's own
    // factors, and what `factorized` says of them, stay as they are.)
    if (settings.condensed_contact && condensed)
      {
        contact_free_factors = kept_are_schur = true;
        condensed->reset();
        schur_slot.assign(system->n_equations(), -1);
        for (unsigned int i = 0; i < patch_unknowns.size(); ++i)
          schur_slot[patch_unknowns[i]] = i;
        condensed->use_block(schur_slot, patch_block);
      }
    return true;
  }



  bool
  StateSolver::Impl::contact_patch(State &state, const std::vector<double> &x)
  {
    // From the factors of an iterate of the state's last Newton solve if
    // it made them (patch_factors_due()), else a partial factorisation of
    // the converged tangent of its own.
    if (!patch_of_state)
      {
        // (An empty patch is made without factors.)
        const bool made = factorize_with_patch(x, state.active_displacement);
        if (!made && !patch_of_state)
          return false;
        state.stiffness_factorizations += made;
      }
    auto patch = make_contact_patch(*system,
                                    patch_nodes,
                                    patch_block,
                                    x,
                                    state.active_displacement,
                                    patch_rows);
    if (!patch)
      return false;
    tabulate_neighbours(*patch, grid_spacing);
    state.contact_patch = std::move(patch);
    return true;
  }



  void
  StateSolver::Impl::derivatives(State &state, const std::vector<double> &x)
  {
    using Clock = std::chrono::steady_clock;
    if (settings.compute_stiffness)
      {
        const auto start = Clock::now();
        state.has_stiffness =
          settings.condensed_contact && system->has_contact() ?
            condensed_stiffness(state) :
            active_stiffness(state);
        state.stiffness_time = Utilities::seconds_since(start);
      }
    if (patch_reach > 0 && system->has_contact())
      {
        const auto start = Clock::now();
        contact_patch(state, x);
        state.contact_patch_time = Utilities::seconds_since(start);
      }
  }
} // namespace palpate
