// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

#ifndef palpate_hyperelastic_sphere_trial_h
#define palpate_hyperelastic_sphere_trial_h

#include <palpate/mesh/node_selection.h>

#include <iosfwd>

namespace palpate
{
  class Mesh;
  class Scene;

  /**
   * The NodeSelection::SphereTrial this layer gives: a static solve from
   * rest to @p scene's Prescribed displacement with its sphere (Tip
   * radius), the nodes @p placed for it. Returns the part of the push its
   * converged increments reached, 1 if it converged (0 if the solver could
   * not even be set up). Used only on a refusal, to try the radius it
   * offers: seconds on a 2,000-node organ.
   */
  double
  sphere_push_reached(const Scene         &scene,
                      const Mesh          &mesh,
                      const NodeSelection &placed);

  /**
   * sphere_push_reached(), each trial announced on @p progress if given (a
   * refusal that solves takes seconds, with Taylor-Hood a minute or two).
   */
  NodeSelection::SphereTrial
  sphere_trial(std::ostream *progress = nullptr);

  /**
   * NodeSelection::create() with sphere_push_reached() as its trial: a
   * refusal of a sphere's radius names one that converged; the trials
   * announced on @p progress, if given.
   */
  NodeSelection
  select_nodes(const Scene  &scene,
               const Mesh   &mesh,
               std::ostream *progress = nullptr);
} // namespace palpate

#endif
