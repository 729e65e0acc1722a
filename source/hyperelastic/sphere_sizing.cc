// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

// The sizing of a sphere its checks refused (NodeSelection::SphereSizing):
// the radius the refusal offers, tried by static solves here, in the layer
// that can solve, since the checks below it are geometric.

#include <palpate/hyperelastic/sphere_trial.h>
#include <palpate/mesh/mesh.h>
#include <palpate/mesh/node_selection_impl.h>
#include <palpate/scene/scene.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <functional>
#include <vector>

namespace palpate
{
  namespace
  {
    /** "a, b, c" with 3 digits each. */
    std::string
    list(const std::vector<double> &values)
    {
      std::string text;
      for (const double v : values)
        text += (text.empty() ? "" : ", ") + Utilities::to_string(v, 3);
      return text;
    }

    /**
     * Where tried_offer() solves: the scene's push, or at rest (@p at_rest)
     * the 26 grid points around rest.
     */
    std::vector<Utilities::Point3>
    trial_targets(const Scene &scene, const bool at_rest)
    {
      // At rest (an interaction's scene) the states first computed are the
      // grid points around it, the corners of the cells that touch it: the
      // 26 one spacing away are tried, the diagonal ones too: on
      // liver-stvk.prm, 0.0171 m at Node id 36 converges at the six along
      // the axes and is a failure point at (0.01, 0, -0.01). The six along
      // the axes first: a radius that fails mostly fails there, and is
      // dropped sooner.
      std::vector<Utilities::Point3> targets;
      if (!at_rest)
        targets.push_back(scene.parameters.boundary_conditions.active_node
                            .prescribed_displacement);
      else
        {
          const double h = scene.parameters.state_space.grid_spacing;
          for (const unsigned int along : {1u, 2u, 3u})
            for (int i = -1; i <= 1; ++i)
              for (int j = -1; j <= 1; ++j)
                for (int k = -1; k <= 1; ++k)
                  if (static_cast<unsigned int>(std::abs(i) + std::abs(j) +
                                                std::abs(k)) == along)
                    targets.push_back({{i * h, j * h, k * h}});
        }
      return targets;
    }

    /** Whether a sphere of radius @p r passes the checks pushed to each of
     * @p targets. */
    bool
    passes_at_all(const Scene                          &scene,
                  const Mesh                           &mesh,
                  const NodeSelection                  &selection,
                  const std::vector<Utilities::Point3> &targets,
                  const double                          r)
    {
      Scene with = scene;
      for (const auto &to : targets)
        {
          with.parameters.boundary_conditions.active_node
            .prescribed_displacement = to;
          if (!internal::fit_sphere(with, mesh, selection, r).passes)
            return false;
        }
      return true;
    }

    /**
     * The refusal when, at rest, every radius tried (@p tried) fails some
     * of the 26 grid points around rest; @p untried: larger radii than
     * the last, @p r, were left untried for time.
     */
    [[noreturn]] void
    refuse_at_rest(const Scene       &scene,
                   const std::string &tried,
                   const bool         untried,
                   const double       r)
    {
      throw scene.error(
        "Boundary conditions/Active node/Tip radius",
        "no sphere found here: radii that pass the checks (" + tried +
          " m) were tried by static solves to the 26 grid points around "
          "rest (State space / Grid spacing), and with each some "
          "did not converge (failure points, no force there)" +
          // (Taylor-Hood: the first radius's trials may take minutes.)
          (untried ? "; larger ones were not tried (after the first radius, "
                     "trials go on only within 10 s)" :
                     ""),
        "a mesh finer near the probe (Mesh / Source = surface with "
        "Refinement size about a third of the radius), another Point or "
        "Node id, or a smaller Grid spacing" +
          std::string(untried ?
                        ", or try a larger Tip radius yourself, e.g. " +
                          Utilities::to_string(r, 3) + " m (not solved here)" :
                        ""));
    }



    /**
     * With no radius converging to the push, a shorter push along the
     * same line with the radius that got farthest (@p best, to
     * @p best_reached of the way; @p radii those tried): what to name,
     * or the refusal. (Shorter, it needs no larger a radius: the checks'
     * margin grows with the depth and the slide.)
     */
    template <typename Reached>
    NodeSelection::TriedOffer
    shorter_push(const Scene               &scene,
                 const Utilities::Point3   &push,
                 const std::vector<double> &radii,
                 const double               best,
                 const double               best_reached,
                 const Reached             &reached)
    {
      const std::string   tried = list(radii);
      std::vector<double> parts;
      for (double part =
             std::floor(0.9 * std::max(best_reached, 0.0) * 100) / 100;
           part >= 0.05 && parts.size() < 2;
           part = std::floor(0.5 * part * 100) / 100)
        {
          const Utilities::Point3 shorter = {
            {part * push[0], part * push[1], part * push[2]}};
          if (reached(best, shorter) >= 1)
            {
              std::vector<double> others;
              for (const double r : radii)
                if (r != best)
                  others.push_back(r);
              return {" and, as the push (Prescribed displacement, --to, "
                      "the trajectory), " +
                        Utilities::to_string(part, 3) + " times this one: " +
                        Utilities::to_string(shorter, 4) + " m",
                      "; a static solve with these converged, while to this "
                      "push it stopped at " +
                        Utilities::to_string(best_reached, 2) +
                        " of the way, a failure point" +
                        (others.empty() ? std::string() :
                                          ", as with " + list(others) + " m") +
                        " (Newton found no way on where the contact set "
                        "keeps changing)"};
            }
          parts.push_back(part);
        }
      throw scene.error(
        "Boundary conditions/Active node/Tip radius",
        "no sphere found for this push: radii that pass the checks here (" +
          tried +
          " m) were tried by a static solve to it, and none converged (the "
          "farthest got " +
          Utilities::to_string(std::max(best_reached, 0.0), 2) +
          " of the way)" +
          (parts.empty() ? std::string() :
                           ", nor to " + list(parts) + " times the push"),
        "a shorter push (Prescribed displacement, --to, the trajectory), a "
        "mesh finer near the probe (Mesh / Source = surface with Refinement "
        "size about a third of the radius), or other fixed nodes");
    }



    /**
     * Try the radius @p offer a refusal names (it passes the checks) by a
     * static solve to the scene's push, or at rest to the 26 grid points
     * around it (where it must pass the checks too); if it does not
     * converge, the next radii 25 % apart that pass, and if none does, a
     * shorter push with the radius that got farthest. @p offer becomes the
     * radius to name. Throws the refusal itself when nothing tried
     * converges.
     */
    NodeSelection::TriedOffer
    tried_offer(const Scene                         &scene,
                const Mesh                          &mesh,
                const NodeSelection                 &selection,
                const SphereTrial                   &trial,
                double                              &offer,
                const std::function<double(double)> &first_passing)
    {
      const double largest = 0.25 * mesh.diameter();
      const auto  &push    = scene.parameters.boundary_conditions.active_node
                           .prescribed_displacement;
      const bool at_rest = !(Utilities::norm(push) > 0);
      const std::vector<Utilities::Point3> targets =
        trial_targets(scene, at_rest);
      // The part of @p to a solve with radius r reaches, if r's sphere
      // passes the checks for that push (else -1).
      const auto reached = [&](const double r, const Utilities::Point3 &to) {
        Scene with                                                 = scene;
        with.parameters.boundary_conditions.active_node.tip_radius = r;
        with.parameters.boundary_conditions.active_node
          .prescribed_displacement = to;
        const internal::SphereFit f =
          internal::fit_sphere(with, mesh, selection, r);
        return f.passes ? trial(with, mesh, f.placed) : -1.0;
      };
      // At rest a radius is tried only if it passes the checks at all the
      // targets (geometric, milliseconds): solving one that cannot be
      // offered would spend the 10 s the next radii have, and could leave
      // no radius to name where one converges at all 26.
      const auto passes_everywhere = [&](const double r) {
        return passes_at_all(scene, mesh, selection, targets, r);
      };
      const auto next_passing = [&](double r) {
        r = first_passing(r);
        while (at_rest && r <= largest && !passes_everywhere(r))
          r = first_passing(std::ceil(r * 1.02 * 1e4) / 1e4);
        return r;
      };
      offer = next_passing(offer);
      if (at_rest && offer > largest)
        throw scene.error(
          "Boundary conditions/Active node/Tip radius",
          "no sphere found here: no radius up to a quarter of the body (" +
            Utilities::to_string(largest, 3) +
            " m) passes the sphere's checks at all the 26 grid points "
            "around rest (State space / Grid spacing), the states an "
            "interaction computes first",
          "a mesh finer near the probe (Mesh / Source = surface with "
          "Refinement size about a third of the radius), another Point or "
          "Node id, or a smaller Grid spacing");
      // The least of the targets (stopping at the first that fails).
      const auto reached_all = [&](const double r) {
        double least = 1;
        for (const auto &to : targets)
          if ((least = std::min(least, reached(r, to))) < 1)
            break;
        return least;
      };
      // Up to three radii, the next ones only within 10 s: at Node id 27,
      // 0.9 - 2 times the offer all failed within 0.36 - 0.58 of the push,
      // so more would only cost time. A solve takes 2 - 5 s on the graded
      // liver, a minute with Taylor-Hood (whose refusal then tries one
      // radius and one push).
      const auto          start = std::chrono::steady_clock::now();
      double              best = offer, best_reached = -1;
      std::vector<double> radii;
      unsigned int        n_tried = 0;
      double              r       = offer;
      for (; r <= largest && n_tried < 3 &&
             (n_tried == 0 || std::chrono::steady_clock::now() - start <
                                std::chrono::seconds(10));
           r = next_passing(std::ceil(r * 1.25 * 1e4) / 1e4))
        {
          const double part = reached_all(r);
          ++n_tried;
          if (part >= 1)
            {
              offer = r;
              return {"",
                      n_tried == 1 ?
                        std::string() :
                        "; a static solve with it converged" +
                          (radii.empty() ?
                             std::string() :
                             ", with " + list(radii) + " m it did not")};
            }
          if (part >= 0) // (a radius failing the checks is not solved)
            radii.push_back(r);
          if (part > best_reached)
            best = r, best_reached = part;
        }
      const std::string tried = list(radii);
      if (at_rest)
        refuse_at_rest(scene, tried, n_tried < 3 && r <= largest, r);
      // None converged: a shorter push along the same line, with the
      // radius that got farthest, tried too.
      offer = best;
      return shorter_push(scene, push, radii, best, best_reached, reached);
    }



  } // namespace



  NodeSelection::SphereSizing
  sphere_sizing(std::ostream *progress)
  {
    return [trial = sphere_trial(
              progress)](const Scene                         &scene,
                         const Mesh                          &mesh,
                         const NodeSelection                 &selection,
                         double                              &offer,
                         const std::function<double(double)> &first_passing) {
      return tried_offer(scene, mesh, selection, trial, offer, first_passing);
    };
  }



  NodeSelection
  select_nodes(const Scene &scene, const Mesh &mesh, std::ostream *progress)
  {
    return NodeSelection::create(scene, mesh, sphere_sizing(progress));
  }
} // namespace palpate
