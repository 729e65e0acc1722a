// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

#ifndef palpate_hyperelastic_sphere_trial_h
#define palpate_hyperelastic_sphere_trial_h

#include <palpate/mesh/node_selection.h>

#include <functional>
#include <iosfwd>

namespace palpate
{
  class Mesh;
  class Scene;

  /**
   * How far a static solve gets with a sphere: for @p scene (its Tip
   * radius and Prescribed displacement those to try) and the nodes
   * @p placed for it on @p mesh, the part of the push (0 - 1) reached by
   * converged increments, 1 if the push converged.
   */
  using SphereTrial = std::function<
    double(const Scene &scene, const Mesh &mesh, const NodeSelection &placed)>;

  /**
   * The SphereTrial of a static solve from rest to @p scene's Prescribed
   * displacement with its sphere (Tip radius), the nodes @p placed for it.
   * Returns the part of the push its converged increments reached, 1 if
   * it converged (0 if the solver could not even be set up). Used only on
   * a refusal, to try the radius it offers: seconds on a 2,000-node organ.
   */
  double
  sphere_push_reached(const Scene         &scene,
                      const Mesh          &mesh,
                      const NodeSelection &placed);

  /**
   * sphere_push_reached(), each trial announced on @p progress if given (a
   * refusal that solves takes seconds, with Taylor-Hood a minute or two).
   */
  SphereTrial
  sphere_trial(std::ostream *progress = nullptr);

  /**
   * The sizing a sphere's refusal asks for (sphere_sizing.cc): the radius
   * its checks offer tried by sphere_trial(@p progress) to the scene's
   * push, or at rest to the 26 grid points around it; if it does not
   * converge, up to two more radii 25 % apart within 10 s, then a shorter
   * push with the radius that got farthest.
   */
  NodeSelection::SphereSizing
  sphere_sizing(std::ostream *progress = nullptr);

  /**
   * NodeSelection::create() with sphere_sizing() as its sizing: a refusal
   * of a sphere's radius names one that converged; the trials announced
   * on @p progress, if given.
   */
  NodeSelection
  select_nodes(const Scene  &scene,
               const Mesh   &mesh,
               std::ostream *progress = nullptr);
} // namespace palpate

#endif
