// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

#ifndef palpate_hyperelastic_state_h
#define palpate_hyperelastic_state_h

#include <palpate/base/utilities.h>

#include <array>
#include <memory>
#include <string>
#include <vector>

namespace palpate
{
  struct ContactPatch;

  /** How the computation of a state ended. */
  enum class SolveStatus
  {
    /** Every increment converged: the state is an equilibrium. */
    converged,
    /** An increment did not converge within the iteration limit. */
    max_iterations,
    /** Every step the line search tried inverted an element (det F <= 0). */
    inverted_element,
    /** A residual or update became NaN or infinite. */
    not_finite,
    /** The sparse direct solver failed (singular tangent). */
    linear_solver_failure,
    /** A stop was asked for (StateSolver::set_stop_check()) before the
     * state converged: says nothing about the body, so never a failure
     * point to keep. */
    stopped,
    /** Every increment converged, but the sphere went through the surface
     * between its nodes (HyperelasticSystem::sphere_center_distance()):
     * the force is the mesh's, not the tissue's. (Last, so that the
     * numbers of the others in a state store stay as they were.) */
    sphere_through_surface
  };

  /** A short name for @p status, e.g. "max iterations". */
  std::string
  to_string(const SolveStatus status);

  /** What one Newton iteration did, and where its time went. */
  struct NewtonIteration
  {
    /** The increment of the staging this iteration belongs to (from 1). */
    unsigned int increment;
    /** Force residual relative to the force scale before the iteration. */
    double residual_before;
    /** Force residual relative to the force scale after the iteration. */
    double residual_after;
    /** Largest constraint violation |B u - g| after the iteration (m). */
    double constraint_after;
    /** Largest displacement correction of the step taken (m). */
    double correction;
    /** Line search step length taken (1 = full Newton step). */
    double step_length;
    /** Whether the tangent was factorised for this step (else GMRES with
     * a kept factorisation solved it), and GMRES iterations (0 if none). */
    bool         factorized        = true;
    unsigned int krylov_iterations = 0;
    /** Whether the step taken was Anderson-accelerated (Anderson depth). */
    bool accelerated = false;
    /** Wall-clock seconds: residual+tangent assembly, factorisation and
     * solve, line search (residual evaluations at trial points). */
    double assembly_time, solve_time, line_search_time;
  };

  /**
   * One static equilibrium state of the body with the active node at a
   * given position: the paper's C = (u, f). A State also records how it was
   * computed, so the engine and the benchmarks can learn from it.
   */
  struct State
  {
    /** Prescribed displacement of the active node from rest (m). */
    Utilities::Point3 active_displacement = {{0, 0, 0}};

    /**
     * The force the body exerts on the probe at the active node (N): the
     * Lagrange multiplier of the active node's constraint. This is what the
     * device renders.
     */
    Utilities::Point3 force = {{0, 0, 0}};

    /**
     * The active-node stiffness K = -df/dx (N/m, row-major 3x3, K[3 i + j]
     * = -d force_i / d x_j), the Schur complement of the converged tangent
     * on the probe's constraint: how the force changes when the probe
     * moves. Symmetric, as the force is the gradient of the strain energy.
     * Computed only when asked for (tricubic Hermite interpolation needs
     * it): valid if has_stiffness.
     */
    std::array<double, 9> stiffness     = {};
    bool                  has_stiffness = false;
    /** Seconds of wall_time spent on the stiffness. */
    double stiffness_time = 0;

    /** Nodal solution in deal.II DoF order (displacements, m). */
    std::vector<double> solution;

    /** All Lagrange multipliers (N): the active node's three, then those
     * of the fixed nodes if they are imposed by multipliers. */
    std::vector<double> multipliers;

    /** Whether this is an equilibrium (status == converged). */
    bool converged = true;

    /** How the computation ended. */
    SolveStatus status = SolveStatus::converged;

    /** For failures: what happened, in one sentence. */
    std::string message;

    /** Increments of the incremental staging (including cutbacks). */
    unsigned int increments = 0;

    /** Newton iterations over all increments. */
    unsigned int newton_iterations = 0;

    /** Most Newton iterations one increment needed. */
    unsigned int max_increment_iterations = 0;

    /** Factorisations the stiffness and the contact patch made (beside
     * those in history). */
    unsigned int stiffness_factorizations = 0;

    /** With State space / Interpolation = contact patch and a sphere: the
     * linearised contact problem the haptic loop solves around this state
     * (null otherwise, and for failure points). */
    std::shared_ptr<const ContactPatch> contact_patch;
    /** Seconds of wall_time spent on the contact patch. */
    double contact_patch_time = 0;

    /** Every Newton iteration, in order. */
    std::vector<NewtonIteration> history;

    /** Total wall-clock seconds spent computing this state. */
    double wall_time = 0;
  };
} // namespace palpate

#endif
