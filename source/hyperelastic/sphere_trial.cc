// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

#include <palpate/hyperelastic/sphere_trial.h>
#include <palpate/hyperelastic/state_solver.h>
#include <palpate/scene/scene.h>

#include <exception>
#include <ostream>

namespace palpate
{
  double
  sphere_push_reached(const Scene         &scene,
                      const Mesh          &mesh,
                      const NodeSelection &placed)
  {
    const auto &push =
      scene.parameters.boundary_conditions.active_node.prescribed_displacement;
    try
      {
        StateSolver solver(mesh, placed, scene.parameters);
        // The path parameter of the last converged increment, and of the
        // one before: how far a failure point got. Its last increment may
        // converge and the end still be refused (the sphere through the
        // surface, a non-finite force): then it got as far as the one
        // before, and counting the last would call a failure point
        // converged and offer its radius.
        double reached = 0, before = 0;
        solver.set_increment_observer(
          [&reached, &before](const State &, const double t) {
            before  = reached;
            reached = t;
          });
        const State end = solver.solve(solver.rest_state(), push);
        if (end.converged)
          return 1;
        return reached < 1 ? reached : before;
      }
    catch (const std::exception &)
      {
        // A solver that cannot be set up for this radius (its contact
        // candidates, the linear solver's memory): not a radius to offer.
        return 0;
      }
  }



  SphereTrial
  sphere_trial(std::ostream *progress)
  {
    if (progress == nullptr)
      return &sphere_push_reached;
    return [progress](const Scene         &with,
                      const Mesh          &on,
                      const NodeSelection &placed) {
      const auto &a = with.parameters.boundary_conditions.active_node;
      *progress << "palpate: the Tip radius fails the sphere's checks; "
                   "trying "
                << Utilities::to_string(a.tip_radius, 3)
                << " m by a static solve to "
                << Utilities::to_string(a.prescribed_displacement, 4)
                << " m before offering it ... " << std::flush;
      const double reached = sphere_push_reached(with, on, placed);
      *progress << (reached >= 1 ? std::string("converged") :
                    reached > 0  ? "stopped at " +
                                    Utilities::to_string(reached, 2) +
                                    " of the way" :
                                  std::string("did not converge"))
                << std::endl;
      return reached;
    };
  }
} // namespace palpate
