// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

#include <palpate/mesh/mesh.h>
#include <palpate/mesh/node_selection_impl.h>
#include <palpate/scene/scene.h>

#include <algorithm>
#include <cmath>
#include <vector>

namespace palpate
{
  namespace internal
  {
    namespace
    {
      /**
       * The refusal of a sphere of radius @p R pushed farther towards the
       * fixed nodes than a radius is offered for (@p fit.supported false).
       */
      [[noreturn]] void
      refuse_beyond_support(const Scene     &scene,
                            const double     R,
                            const SphereFit &fit)
      {
        // Beyond towards_support no radius is offered: the one the checks
        // find can be a failure point there (above); the push is what to
        // change.
        const double no_deeper =
          std::floor(towards_support * fit.support * 1e4) / 1e4;
        throw scene.error(
          "Boundary conditions/Active node/Tip radius",
          "a sphere of " + Utilities::to_string(R, 3) + " m radius " +
            sphere_problem(R, fit),
          "a push no deeper than " + Utilities::to_string(no_deeper, 3) +
            " m along the surface's inward normal (Prescribed displacement, "
            "--to, the trajectory), for which a radius is then offered. None "
            "is for this push, " +
            Utilities::to_string_apart(fit.depth, no_deeper) +
            " m deep, more than " + Utilities::to_string(towards_support, 3) +
            " of the way to the nearest fixed node (" +
            Utilities::to_string(fit.support, 3) +
            " m from the active node): the radius these checks find for so "
            "deep a push was measured to fail at some sites, Newton "
            "stagnating as the contact patch grows or the tissue squeezed "
            "against the fixed nodes (on the liver of liver-indenter.prm "
            "every push to 0.25 of the way converged, failure points from "
            "0.26; such a push already asks 5 - 8 N, about what a haptic "
            "device renders). Or fixed nodes farther from the probe "
            "(Boundary conditions / Fixed nodes).");
      }
    } // namespace



    void
    place_sphere_tip(const Scene                       &scene,
                     const Mesh                        &mesh,
                     NodeSelection                     &selection,
                     const NodeSelection::SphereSizing &sizing)
    {
      const auto     &a   = scene.parameters.boundary_conditions.active_node;
      const double    R   = a.tip_radius;
      const SphereFit fit = fit_sphere(scene, mesh, selection, R);
      if (fit.passes)
        {
          selection = fit.placed;
          return;
        }
      if (!fit.supported)
        refuse_beyond_support(scene, R, fit);
      // The radius to offer: the smallest that passes, found by trying
      // radii 2 % apart from what the figures at R ask for. R's figures
      // alone do not say what another radius needs: it touches another
      // patch, with another normal (worked out from them, about one offer
      // in six fails the checks when used). Nor is the rule monotonic (a
      // larger sphere looks at more triangles), so the offer is "a radius
      // that passes", not "at least".
      const double largest = 0.25 * mesh.diameter();
      double       offer =
        std::ceil(
          std::max(
            {2 * fit.hole, fit.longest / 1.5, fit.depth / deepest_push, 1e-4}) *
          1e4) /
        1e4;
      const auto first_passing = [&](double r) {
        while (r <= largest && !fit_sphere(scene, mesh, selection, r).passes)
          r = std::ceil(r * 1.02 * 1e4) / 1e4;
        return r;
      };
      offer = first_passing(offer);
      // Not the smallest that passes but the first from 10 % above it: the
      // smallest just clears the spacing and can be a failure point where
      // 1.1 times it converges (doc/formulation.md, "The sphere's checks").
      if (offer <= largest)
        if (const double above =
              first_passing(std::ceil(offer * 1.1 * 1e4) / 1e4);
            above <= largest)
          offer = above;
      // Tried by the sizing's static solves where a layer that solves gave
      // one, so that what is offered has converged: the checks are
      // geometric and cannot foresee where the contact Newton stagnates
      // (a few offers in a hundred that pass them are failure points).
      const NodeSelection::TriedOffer tried =
        offer <= largest && sizing ?
          sizing(scene, mesh, selection, offer, first_passing) :
          NodeSelection::TriedOffer();
      // A push no deeper than half the radius needs no margin.
      const double shallow_enough = std::floor(0.5 * R * 1e4) / 1e4;
      const bool   p2             = scene.displacement_degree() == 2;
      throw scene.error(
        "Boundary conditions/Active node/Tip radius",
        "a sphere of " + Utilities::to_string(R, 3) + " m radius " +
          sphere_problem(R, fit),
        (offer <= largest ?
           "use a radius of " + Utilities::to_string(offer, 6) + " m" +
             tried.push +
             " (it passes these checks here, 10 % or more above the "
             "smallest that does: found by trying radii" :
           std::string("no radius up to a quarter of the "
                       "body passes these checks here (") +
             "tried radii") +
          " 2 % apart; a sphere must be at least twice the nearest node's "
          "distance and two thirds of the longest edge within two radii of "
          "its path, up to " +
          Utilities::to_string(margin, 2) +
          " times those when pushed deeper than its radius (dragged along "
          "the surface: rising from half a radius deep), where a sphere "
          "that just clears them slips between the nodes, "
          "and at least the depth over " +
          Utilities::to_string(deepest_push, 3) +
          ", as one pushed nearly its diameter deep goes through the "
          "surface" +
          tried.why +
          "), or a mesh finer near the probe (Mesh / Source = "
          "surface with Refinement size about a third of the radius)" +
          (!fit.meets ? std::string() :
                        ", or a push (Prescribed displacement, --to, the "
                        "trajectory) no longer than " +
                          Utilities::to_string(shallow_enough, 3) + " m") +
          (p2 || fit.required > 1 ?
             std::string(".") :
             std::string(", or Polynomial degree = 2 (the edge "
                         "midpoints become contact nodes).")));
    }
  } // namespace internal
} // namespace palpate
