// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

// The incremental staging's checks and predictors (StateSolver::Impl): how
// many increments a path takes, whether a start and an end may be used, the
// predictor from the states behind, and the steps of solve() around each
// increment's Newton solve (the secant predictor, the retry from the last
// equilibrium, the observer, the state at the end).

#include <palpate/hyperelastic/state_solver_impl.h>

#include <algorithm>
#include <cmath>

namespace palpate
{
  StateSolver::Impl::Outcome
  StateSolver::Impl::out_of_work(const unsigned int iterations)
  {
    Outcome o;
    o.status  = SolveStatus::max_iterations;
    o.message = "gave up after " + std::to_string(iterations) +
                " Newton iterations in all (the increments, their cutbacks "
                "and retries): a path this hard is a failure point (Nonlinear "
                "solver / Maximum Newton iterations, Maximum cutbacks and "
                "Number of increments together allow more)";
    return o;
  }



  double
  StateSolver::Impl::increments_needed(const double length) const
  {
    // A sphere moves at most its radius per increment. A longer jump can
    // carry it past a surface node without ever touching it (the contact
    // is node to sphere): a 2 mm sphere pushed 1 cm into the liver in one
    // increment ended inside the organ, between its nodes, with no node in
    // contact and a force of 0 N.
    double max_length = settings.max_increment_length;
    if (system->has_contact())
      max_length = max_length > 0 ?
                     std::min(max_length, system->sphere_radius()) :
                     system->sphere_radius();
    const double n = settings.n_increments;
    return max_length > 0 ?
             std::max(n, std::ceil(length / max_length - 1e-12)) :
             n;
  }



  bool
  StateSolver::Impl::admissible_start(const State             &from,
                                      const Utilities::Point3 &target,
                                      State                   &state) const
  {
    for (const double t : target)
      if (!std::isfinite(t))
        {
          state.converged = false;
          state.status    = SolveStatus::not_finite;
          state.message   = "the target position is not finite";
          state.solution  = from.solution;
          state.multipliers.assign(from.multipliers.size(), 0.0);
          state.force = {{0, 0, 0}};
          return false;
        }

    // The start must be an equilibrium of this body.
    bool usable = from.converged && from.solution.size() == system->n_dofs() &&
                  from.multipliers.size() == system->n_multipliers();
    for (const double v : from.active_displacement)
      usable = usable && std::isfinite(v);
    for (unsigned int i = 0; usable && i < from.solution.size(); ++i)
      usable = std::isfinite(from.solution[i]);
    if (!usable)
      {
        state.converged = false;
        state.status    = SolveStatus::not_finite;
        state.message =
          "the starting state is not a converged state of this body";
        state.solution.assign(system->n_dofs(), 0.0);
        state.multipliers.assign(system->n_multipliers(), 0.0);
        state.force = {{0, 0, 0}};
        return false;
      }
    return true;
  }



  void
  StateSolver::Impl::predictor_from_behind(const State               &from,
                                           const Utilities::Point3   &target,
                                           const State               *behind,
                                           const State               *behind2,
                                           const unsigned int         n,
                                           const std::vector<double> &x,
                                           std::vector<double>       &previous,
                                           double &previous_t) const
  {
    const auto   a      = from.active_displacement;
    const double length = Utilities::distance(a, target);
    if (behind != nullptr && behind->converged &&
        behind->solution.size() == from.solution.size() &&
        behind->multipliers.size() == from.multipliers.size() && length > 0)
      {
        Utilities::Point3 back, ahead;
        for (unsigned int d = 0; d < 3; ++d)
          {
            back[d]  = a[d] - behind->active_displacement[d];
            ahead[d] = target[d] - a[d];
          }
        const double b      = Utilities::norm(back);
        double       cosine = 0;
        for (unsigned int d = 0; d < 3; ++d)
          cosine += back[d] * ahead[d];
        cosine /= std::max(b * length, 1e-300);
        if (b > 0 && cosine > 1 - 1e-9)
          {
            bool finite = true;
            for (const double v : behind->solution)
              finite = finite && std::isfinite(v);
            if (finite)
              {
                previous   = system->from_state(*behind);
                previous_t = -b / length;
                // With a second state behind, at the same spacing on the
                // same line, and one increment: the quadratic through the
                // three, 3 x - 3 x_b + x_bb at the target (third order).
                // The secant predictor below computes x + (x - previous),
                // so previous becomes the point that makes it that.
                if (behind2 != nullptr && behind2->converged && n == 1 &&
                    std::abs(b - length) <= 1e-9 * length &&
                    behind2->solution.size() == from.solution.size() &&
                    behind2->multipliers.size() == from.multipliers.size())
                  {
                    double off = 0;
                    for (unsigned int d = 0; d < 3; ++d)
                      off = std::max(off,
                                     std::abs(behind2->active_displacement[d] -
                                              (a[d] - 2 * back[d])));
                    bool finite2 = off <= 1e-9 * length;
                    for (const double v : behind2->solution)
                      finite2 = finite2 && std::isfinite(v);
                    if (finite2)
                      {
                        const std::vector<double> bb =
                          system->from_state(*behind2);
                        for (unsigned int i = 0; i < previous.size(); ++i)
                          previous[i] = 3 * previous[i] - bb[i] - x[i];
                      }
                  }
              }
          }
      }
  }



  namespace
  {
    // What to change when the sphere goes, or is going, between the
    // surface nodes.
    std::string
    through_surface_fix()
    {
      return "The contact acts at nodes, and a sphere smaller than the "
             "surface triangles where it pushes slips past the node it "
             "pushes, so its force would be the mesh's. Use a larger Tip "
             "radius, a mesh finer near the probe (Mesh / Source = surface "
             "with Refinement size about a third of the radius), or "
             "Polynomial degree = 2";
    }
  } // namespace



  bool
  StateSolver::Impl::acceptable_end(const std::vector<double> &x,
                                    State                     &state,
                                    Outcome                   &failure) const
  {
    if (!(std::isfinite(state.force[0]) && std::isfinite(state.force[1]) &&
          std::isfinite(state.force[2])))
      {
        // The last line of defence: a force sent to a device is finite.
        failure.status = SolveStatus::not_finite;
        failure.message =
          "the force is not finite (are the material constants within "
          "their physical range?)";
        return false;
      }
    if (system->has_contact())
      {
        const double R = system->sphere_radius();
        const double d =
          system->sphere_center_distance(x, state.active_displacement);
        // Between the nodes the surface sags into a sphere smaller than
        // its triangles by up to about h^2 / 8R, so a sphere that nodes
        // hold may overlap the triangles a little; one that no node holds
        // must not. (A 6 mm sphere moved sideways into liver501 was 2.55 mm
        // into the surface with no node touching: 0 N.)
        const bool held =
          state.force[0] != 0 || state.force[1] != 0 || state.force[2] != 0;
        if (d < 0.5 * R || (!held && d < 0.9 * R))
          {
            failure.status = SolveStatus::sphere_through_surface;
            failure.message =
              "the sphere (radius " + Utilities::to_string(1000 * R, 3) +
              " mm) went between the surface nodes: its centre is " +
              Utilities::to_string(1000 * std::abs(d), 3) + " mm " +
              (d < 0 ? "inside the deformed surface" :
               held  ? "from the deformed surface, less than half its radius" :
                       "from the deformed surface and no node touches it") +
              ". " + through_surface_fix();
            return false;
          }
      }
    return true;
  }



  std::string
  StateSolver::Impl::failure_cause(const std::vector<double> &x,
                                   const Utilities::Point3   &target,
                                   const Outcome             &o) const
  {
    if (!system->has_contact() || o.status != SolveStatus::max_iterations)
      return "";
    // Pressed past the mesh's limit the nodes under the sphere slide
    // round it towards its equator and the node-to-sphere contact has no
    // state to converge to: Newton stagnates just before the depth at
    // which a converged state is refused (acceptable_end()). A box of
    // 5 mm tetrahedra under a 10 mm sphere: converged at 8 mm deep,
    // stagnated at 8.5 mm with the centre 0.75 R from the deformed
    // surface, converged with the contact in the matrix at 9 mm and
    // refused there (0.40 R). Held by nodes a sphere is R less the sag of
    // the triangles between them, h^2 / 8R, away: 0.875 R at h = R.
    const double R = system->sphere_radius();
    const double d = system->sphere_center_distance(x, target);
    if (!std::isfinite(d) || d >= 0.8 * R)
      return "";
    return "; at its last iterate the sphere was sinking between the "
           "surface nodes: its centre was " +
           Utilities::to_string(1000 * d, 3) +
           " mm from the deformed surface, " + Utilities::to_string(d / R, 2) +
           " of its radius (held by the nodes a sphere is about one radius "
           "away). " +
           through_surface_fix() + ", or press less deep";
  }


  bool
  StateSolver::Impl::clears_free_equilibrium(
    const Utilities::Point3 &target) const
  {
    if (!settings.free_start || free_equilibrium.empty())
      return false;
    // No node touching it, and its centre a radius from the surface
    // between the nodes too (a sphere can slip between them:
    // acceptable_end()).
    system->contact_rows(free_equilibrium, target, free_rows);
    for (const auto &r : free_rows)
      if (r.gap <= 0)
        return false;
    return system->sphere_center_distance(free_equilibrium, target) >=
           system->sphere_radius();
  }



  State
  StateSolver::Impl::too_far(const std::vector<double> &x,
                             const double               length,
                             State                     &state) const
  {
    system->to_state(x, state);
    state.converged = false;
    state.status    = SolveStatus::max_iterations;
    state.message   = "the target is " + Utilities::to_string(length, 3) +
                    " m away: more than 1000 increments";
    state.force = {{0, 0, 0}};
    return state;
  }



  bool
  StateSolver::Impl::start_free(const Utilities::Point3 &target,
                                std::vector<double>     &x)
  {
    if (!clears_free_equilibrium(target))
      return false;
    // Its residual is the one accepted when it was kept: the contact rows,
    // the only ones the target changes, hold with no force. No Newton
    // solve makes factors or a patch for this state.
    x                = free_equilibrium;
    factors_of_state = patch_of_state = false;
    return true;
  }



  void
  StateSolver::Impl::remember_if_free(const State               &state,
                                      const std::vector<double> &x)
  {
    // Only the sphere's contact depends on the target; with no force from
    // it this is the body under its other loads alone. (Kept once: every
    // such state is the same equilibrium, to the solver's tolerance.)
    if (system->has_contact() && free_equilibrium.empty() && state.converged &&
        state.force[0] == 0 && state.force[1] == 0 && state.force[2] == 0)
      free_equilibrium = x;
  }



  // solve(), a step: the secant predictor, @p x moved by @p r times its
  // change since @p previous, taken if the residual at @p end is finite
  // there (true).
  bool
  StateSolver::Impl::secant_predictor(std::vector<double>       &x,
                                      const std::vector<double> &previous,
                                      const double               r,
                                      const Utilities::Point3   &end)
  {
    std::vector<double> guess = x;
    for (unsigned int i = 0; i < x.size(); ++i)
      guess[i] += r * (x[i] - previous[i]);
    if (system->assemble(guess, end, residual, nullptr))
      {
        x.swap(guess);
        return true;
      }
    return false;
  }



  // solve(), a step: Newton's method for one increment's @p end from
  // @p x, and from the last equilibrium @p saved again if it failed from a
  // @p predicted start.
  StateSolver::Impl::Outcome
  StateSolver::Impl::solve_increment(std::vector<double>       &x,
                                     const std::vector<double> &saved,
                                     const Utilities::Point3   &end,
                                     State                     &state,
                                     const bool                 may_cut_back,
                                     const bool                 predicted)
  {
    Outcome o = newton(x, end, state, may_cut_back);
    state.newton_iterations += o.iterations;
    if (o.status != SolveStatus::converged &&
        o.status != SolveStatus::stopped && predicted)
      {
        // The extrapolation can overshoot into an unstable region:
        // start again from the last equilibrium.
        x                   = saved;
        const Outcome retry = newton(x, end, state, may_cut_back);
        state.newton_iterations += retry.iterations;
        o.iterations += retry.iterations;
        o.status  = retry.status;
        o.message = retry.message;
      }
    return o;
  }



  // solve(), a step: the observer (if any) told of the converged
  // increment's state at @p end, parameter @p t of the path.
  void
  StateSolver::Impl::notify_observer(const std::vector<double> &x,
                                     const Utilities::Point3   &end,
                                     const double               t) const
  {
    if (observer)
      {
        State at;
        at.active_displacement = end;
        system->to_state(x, at);
        observer(at, t);
      }
  }



  // solve(), a step: @p state from the unknowns @p x reached; a failure
  // point (@p failure, or an end not to hand out) unless @p ok, else the
  // converged state with its derivatives.
  void
  StateSolver::Impl::finish(const std::vector<double> &x,
                            bool                       ok,
                            Outcome                   &failure,
                            State                     &state)
  {
    system->to_state(x, state);
    if (ok)
      ok = acceptable_end(x, state, failure);
    if (!ok)
      {
        // A failure point: keep the last equilibrium reached on the way,
        // but never hand out its force as the target's.
        state.converged = false;
        state.status    = failure.status;
        state.message   = failure.message;
        state.force     = {{0, 0, 0}};
      }
    else
      {
        derivatives(state, x);
        remember_if_free(state, x);
      }
  }
} // namespace palpate
