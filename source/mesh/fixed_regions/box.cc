// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

// Fixed nodes / Selection = box: the nodes inside an axis-aligned box, from
// Box lower corner to Box upper corner (metres, after Scale factor).

#include <palpate/mesh/fixed_region.h>
#include <palpate/mesh/mesh.h>
#include <palpate/scene/scene.h>

#include <deal.II/base/parameter_handler.h>

namespace palpate
{
  namespace
  {
    /** The nodes in the box, of them the surface ones if Surface nodes
     * only. */
    class BoxRegion : public FixedRegion
    {
    public:
      BoxRegion(const Utilities::Point3 &lower,
                const Utilities::Point3 &upper,
                const bool               surface_only)
        : lower(lower)
        , upper(upper)
        , surface_only(surface_only)
      {}

      /** No entries of its own: it reads Fixed nodes / Box lower corner,
       * Box upper corner and Surface nodes only. */
      static void
      declare_parameters(dealii::ParameterHandler &)
      {}

      static std::unique_ptr<FixedRegion>
      create(const dealii::ParameterHandler &, const Scene &scene)
      {
        const auto &f = scene.parameters.boundary_conditions.fixed_nodes;
        return std::make_unique<BoxRegion>(f.box_lower_corner,
                                           f.box_upper_corner,
                                           f.surface_nodes_only);
      }

      static void
      check_scene(const Scene &scene)
      {
        const auto &f = scene.parameters.boundary_conditions.fixed_nodes;
        for (unsigned int d = 0; d < 3; ++d)
          if (!(f.box_lower_corner[d] < f.box_upper_corner[d]))
            throw scene.error(
              "Boundary conditions/Fixed nodes/Box upper corner",
              "the box is empty: its upper corner is not above its "
              "lower corner in every coordinate",
              "make each coordinate of Box upper corner larger than "
              "that of Box lower corner.");
      }

      Selected
      select(const Scene &, const Mesh &mesh) const override
      {
        return select_contained(mesh, surface_only);
      }

      std::string
      entry() const override
      {
        return "Boundary conditions/Fixed nodes/Box lower corner";
      }

      std::string
      description(const Selected &) const override
      {
        return "nodes in the box [" + Utilities::to_string(lower, 4) + "] - [" +
               Utilities::to_string(upper, 4) + "] m" +
               (surface_only ? ", surface only" : "");
      }

      bool
      is_place() const override
      {
        return true;
      }

      bool
      contains(const Utilities::Point3 &x) const override
      {
        for (unsigned int d = 0; d < 3; ++d)
          if (!(x[d] >= lower[d] && x[d] <= upper[d]))
            return false;
        return true;
      }

    private:
      const Utilities::Point3 lower, upper;
      const bool              surface_only;
    };
  } // namespace

  PALPATE_REGISTER_FIXED_REGION(BoxRegion,
                                "box",
                                "the nodes inside the axis-aligned box from "
                                "Box lower corner to Box upper corner")
} // namespace palpate
