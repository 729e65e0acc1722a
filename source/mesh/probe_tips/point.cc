// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

// Active node / Tip = point: the paper's probe, the active node alone
// follows the haptic interaction point and the force is its multiplier.

#include <palpate/base/exceptions.h>
#include <palpate/base/plugins.h>
#include <palpate/mesh/probe_tip.h>
#include <palpate/scene/scene.h>

#include <deal.II/base/parameter_handler.h>

namespace palpate
{
  namespace
  {
    /** The active node alone: nothing to place, nothing to report. */
    class PointTip : public ProbeTip
    {
    public:
      /** No entries of its own, and it reads none: a point has no size. */
      static void
      declare_parameters(dealii::ParameterHandler &)
      {}

      static std::unique_ptr<ProbeTip>
      create(const dealii::ParameterHandler &, const Scene &)
      {
        return std::make_unique<PointTip>();
      }

      /** A radius set with a point is a tip the user meant and would not
       * get: the probe would silently be the single node. */
      static void
      check_scene(const Scene &scene)
      {
        const auto &a = scene.parameters.boundary_conditions.active_node;
        if (!(a.tip_radius > 0))
          return;
        // The fix offers the registered tips that take this radius: each
        // one's own check_scene() says so, a tip added later included (a
        // tip with radii of its own refuses Tip radius).
        std::string others;
        Scene       trial = scene;
        for (const auto &tip : ProbeTipRegistry::plugins())
          if (tip.name != "point")
            try
              {
                trial.parameters.boundary_conditions.active_node.tip = tip.name;
                Plugins::check_scene("probe tip", tip.name, trial);
                others += (others.empty() ? "Tip = " : " or Tip = ") + tip.name;
              }
            catch (const InputError &)
              {}
        throw scene.error("Boundary conditions/Active node/Tip radius",
                          "Tip radius = " +
                            Utilities::to_string(a.tip_radius, 4) +
                            " m, but Tip = point has no radius",
                          others.empty() ?
                            std::string("remove Tip radius.") :
                            "set " + others +
                              " (palpate --print-parameters describes each "
                              "tip), or remove Tip radius.");
      }
    };
  } // namespace

  PALPATE_REGISTER_PROBE_TIP(
    PointTip,
    "point",
    "the paper's probe, the active node follows the HIP and the force is "
    "its multiplier; the force of a point load is a property of the mesh "
    "(it tends to zero as the mesh is refined)")
} // namespace palpate
