// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

// Fixed nodes / Selection = half-space: the nodes x with
// (x - Half-space point) . Half-space normal >= 0 (metres, after Scale
// factor).

#include <palpate/mesh/fixed_region.h>
#include <palpate/mesh/mesh.h>
#include <palpate/scene/scene.h>

#include <deal.II/base/parameter_handler.h>

#include <algorithm>
#include <cmath>

namespace palpate
{
  namespace
  {
    /** The nodes in the half-space, of them the surface ones if Surface
     * nodes only. */
    class HalfSpaceRegion : public FixedRegion
    {
    public:
      HalfSpaceRegion(const Utilities::Point3 &point,
                      const Utilities::Point3 &normal,
                      const bool               surface_only)
        : point(point)
        , normal(normal)
        , surface_only(surface_only)
      {}

      /** No entries of its own: it reads Fixed nodes / Half-space point,
       * Half-space normal and Surface nodes only. */
      static void
      declare_parameters(dealii::ParameterHandler &)
      {}

      static std::unique_ptr<FixedRegion>
      create(const dealii::ParameterHandler &, const Scene &scene)
      {
        const auto &f = scene.parameters.boundary_conditions.fixed_nodes;
        return std::make_unique<HalfSpaceRegion>(f.half_space_point,
                                                 f.half_space_normal,
                                                 f.surface_nodes_only);
      }

      static void
      check_scene(const Scene &scene)
      {
        const auto &n =
          scene.parameters.boundary_conditions.fixed_nodes.half_space_normal;
        if (std::max({std::abs(n[0]), std::abs(n[1]), std::abs(n[2])}) == 0)
          throw scene.error("Boundary conditions/Fixed nodes/Half-space normal",
                            "the normal is the zero vector",
                            "give the direction pointing into the fixed "
                            "half-space, e.g. 0, 0, -1.");
      }

      Selected
      select(const Scene &, const Mesh &mesh) const override
      {
        return select_contained(mesh, surface_only);
      }

      std::string
      entry() const override
      {
        return "Boundary conditions/Fixed nodes/Half-space point";
      }

      std::string
      description(const Selected &) const override
      {
        return "nodes x with (x - (" + Utilities::to_string(point, 4) +
               ")) . (" + Utilities::to_string(normal, 4) + ") >= 0" +
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
        return Utilities::dot(Utilities::minus(x, point), normal) >= 0;
      }

    private:
      const Utilities::Point3 point, normal;
      const bool              surface_only;
    };
  } // namespace

  PALPATE_REGISTER_FIXED_REGION(HalfSpaceRegion,
                                "half-space",
                                "the nodes x with (x - Half-space point) . "
                                "Half-space normal >= 0")
} // namespace palpate
