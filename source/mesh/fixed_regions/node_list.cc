// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

// Fixed nodes / Selection = node list: the nodes Node ids lists, by the
// numbers the mesh file gives them.

#include <palpate/mesh/fixed_region.h>
#include <palpate/mesh/mesh.h>
#include <palpate/scene/scene.h>

#include <deal.II/base/parameter_handler.h>

#include <vector>

namespace palpate
{
  namespace
  {
    /** The listed nodes, on the surface or not (Surface nodes only does
     * not apply to a list). */
    class NodeListRegion : public FixedRegion
    {
    public:
      explicit NodeListRegion(const std::vector<long> &ids)
        : ids(ids)
      {}

      /** No entries of its own: it reads Fixed nodes / Node ids. */
      static void
      declare_parameters(dealii::ParameterHandler &)
      {}

      static std::unique_ptr<FixedRegion>
      create(const dealii::ParameterHandler &, const Scene &scene)
      {
        return std::make_unique<NodeListRegion>(
          scene.parameters.boundary_conditions.fixed_nodes.node_ids);
      }

      static void
      check_scene(const Scene &scene)
      {
        if (scene.parameters.boundary_conditions.fixed_nodes.node_ids.empty())
          throw scene.error("Boundary conditions/Fixed nodes/Node ids",
                            "Selection = node list, but the list is empty",
                            "list the node numbers to fix, separated by "
                            "commas.");
      }

      Selected
      select(const Scene &scene, const Mesh &mesh) const override
      {
        Selected selected;
        for (const long id : ids)
          {
            const auto v = mesh.vertex_of_node_id(id);
            if (!v)
              throw scene.error(entry(),
                                "the mesh has no node " + std::to_string(id),
                                "use node numbers as the mesh file numbers "
                                "them (Gmsh node tags, VTK point indices "
                                "from 0); the VTU output shows them as "
                                "'node id'.");
            selected.fixed.insert(*v);
          }
        selected.in_region = selected.fixed.size();
        return selected;
      }

      std::string
      entry() const override
      {
        return "Boundary conditions/Fixed nodes/Node ids";
      }

      std::string
      description(const Selected &selected) const override
      {
        return "node list (" + std::to_string(selected.fixed.size()) +
               " nodes)";
      }

    private:
      const std::vector<long> ids;
    };
  } // namespace

  PALPATE_REGISTER_FIXED_REGION(NodeListRegion,
                                "node list",
                                "an explicit list of node numbers, Node ids")
} // namespace palpate
