// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

// Active node / Tip = glued nodes: every free surface node within Tip
// radius of the active node moves with it, a rigid tip whose force is the
// sum of their multipliers.

#include <palpate/mesh/mesh.h>
#include <palpate/mesh/probe_tip.h>
#include <palpate/scene/scene.h>

#include <deal.II/base/parameter_handler.h>

#include <algorithm>
#include <limits>

namespace palpate
{
  namespace
  {
    /** The surface nodes within the radius, glued to the active node. */
    class GluedNodesTip : public ProbeTip
    {
    public:
      explicit GluedNodesTip(const double radius)
        : radius(radius)
      {}

      /** No entries of its own: it reads Active node / Tip radius. */
      static void
      declare_parameters(dealii::ParameterHandler &)
      {}

      static std::unique_ptr<ProbeTip>
      create(const dealii::ParameterHandler &, const Scene &scene)
      {
        return std::make_unique<GluedNodesTip>(
          scene.parameters.boundary_conditions.active_node.tip_radius);
      }

      static void
      check_scene(const Scene &scene)
      {
        check_radius(scene, "a glued tip");
      }

      /** The free surface nodes within the radius of the active node; a
       * fixed node cannot follow the probe. */
      void
      place(const Scene &,
            const Mesh                   &mesh,
            const std::set<unsigned int> &fixed,
            NodeSelection                &selection,
            const NodeSelection::SphereSizing &) const override
      {
        const auto &x                    = mesh.vertices();
        const auto &surface              = mesh.on_surface();
        const auto &active               = x[selection.active_vertex];
        selection.tip_neighbour_distance = std::numeric_limits<double>::max();
        for (unsigned int v = 0; v < x.size(); ++v)
          if (v != selection.active_vertex && surface[v] && !fixed.count(v))
            {
              const double d = Utilities::distance(x[v], active);
              selection.tip_neighbour_distance =
                std::min(selection.tip_neighbour_distance, d);
              if (d <= radius)
                selection.tip_vertices.push_back(v);
            }
      }

      /** A radius smaller than the mesh's spacing glues nothing: the line
       * says so, since the probe is then a point. */
      std::string
      report(const Scene &, const NodeSelection &nodes) const override
      {
        return "radius " + Utilities::to_string(1000 * radius, 4) +
               " mm: " + std::to_string(nodes.tip_vertices.size()) +
               " more surface nodes move with the probe (rigid tip)" +
               (nodes.tip_vertices.empty() ?
                  "; the nearest is " +
                    Utilities::to_string(1000 * nodes.tip_neighbour_distance,
                                         3) +
                    " mm away, so on this mesh the tip is a point probe (a "
                    "finer mesh, or a radius of at least that, makes a tip)" :
                  std::string());
      }

      std::string
      effect(const NodeSelection &nodes) const override
      {
        return "probe tip (" + std::to_string(1 + nodes.tip_vertices.size()) +
               " nodes)";
      }

    private:
      const double radius;
    };
  } // namespace

  PALPATE_REGISTER_PROBE_TIP(
    GluedNodesTip,
    "glued nodes",
    "every free surface node within Tip radius of the active node follows "
    "the haptic interaction point (HIP), and the force is the sum of their "
    "multipliers")
} // namespace palpate
