// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

// Active node / Tip = sphere: a rigid sphere of radius Tip radius whose
// centre follows the haptic interaction point, in frictionless unilateral
// contact with the surface. Its placement and the checks that it meets the
// surface nodes are node_selection_sphere_fit.cc's and
// node_selection_sphere_offer.cc's.

#include <palpate/mesh/node_selection_impl.h>
#include <palpate/mesh/probe_tip.h>
#include <palpate/scene/scene.h>

#include <deal.II/base/parameter_handler.h>

namespace palpate
{
  namespace
  {
    /** The sphere: placed touching the surface at HIP = 0. */
    class SphereTip : public ProbeTip
    {
    public:
      explicit SphereTip(const double radius)
        : radius(radius)
      {}

      /** No entries of its own: it reads Active node / Tip radius. */
      static void
      declare_parameters(dealii::ParameterHandler &)
      {}

      static std::unique_ptr<ProbeTip>
      create(const dealii::ParameterHandler &, const Scene &scene)
      {
        return std::make_unique<SphereTip>(
          scene.parameters.boundary_conditions.active_node.tip_radius);
      }

      static void
      check_scene(const Scene &scene)
      {
        check_radius(scene, "a sphere");
      }

      bool
      is_sphere() const override
      {
        return true;
      }

      void
      place(const Scene &scene,
            const Mesh  &mesh,
            const std::set<unsigned int> &,
            NodeSelection                     &selection,
            const NodeSelection::SphereSizing &sizing) const override
      {
        selection.sphere_tip = true;
        internal::place_sphere_tip(scene, mesh, selection, sizing);
      }

      /** Where the sphere rests, so that a user can see which way a push
       * goes into the organ (against the normal). */
      std::string
      report(const Scene &, const NodeSelection &nodes) const override
      {
        return "a rigid sphere of radius " +
               Utilities::to_string(1000 * radius, 4) +
               " mm in frictionless contact with the surface; at HIP = 0 it "
               "touches the surface from outside, its centre at (" +
               Utilities::to_string(nodes.sphere_center, 4) + ") m, normal (" +
               Utilities::to_string(nodes.active_normal, 3) + ")" +
               (nodes.sphere_lift > 0 ?
                  ", lifted " +
                    Utilities::to_string(1000 * nodes.sphere_lift, 3) +
                    " mm along the normal so that it presses on no other "
                    "node (the surface is concave there)" :
                  std::string());
      }

      std::string
      effect(const NodeSelection &) const override
      {
        return "contact with a rigid sphere";
      }

    private:
      const double radius;
    };
  } // namespace

  PALPATE_REGISTER_PROBE_TIP(
    SphereTip,
    "sphere",
    "a rigid sphere of radius Tip radius, whose centre moves with the HIP, "
    "in frictionless unilateral contact with the surface (no node is glued "
    "to it; the force is the resultant of the contact pressure, zero off the "
    "surface). At HIP = 0 the sphere touches the surface from outside, along "
    "the outward normal, at the point of the surface nearest to Point "
    "(Selection = nearest surface node) or at the node (Selection = node "
    "id); palpate solve --to X moves it by X. The contact acts at the "
    "surface nodes: a state where the sphere went between them (its centre "
    "less than half its radius from the deformed surface, as a sphere "
    "smaller than the triangles it pushes does) is a failure point, not a "
    "force")
} // namespace palpate
