// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

// Effects / Surface traction: a load on part of the surface.

#include <palpate/base/utilities.h>
#include <palpate/hyperelastic/effect.h>
#include <palpate/hyperelastic/hyperelastic_system.h>
#include <palpate/mesh/mesh.h>

#include <deal.II/base/parameter_handler.h>

#include <set>

namespace palpate
{
  namespace
  {
    /**
     * A dead-load traction t (Pa, per reference area) on the boundary faces
     * with one boundary id: a pressure or shear load, e.g. a neighbouring
     * organ resting on this one. It keeps its direction and size as the
     * body deforms, and is scaled by the staging's load factor.
     */
    class SurfaceTraction : public Effect
    {
    public:
      SurfaceTraction(const unsigned int       boundary_id,
                      const Utilities::Point3 &t)
        : boundary_id(boundary_id)
        , t(t)
      {}

      static void
      declare_parameters(dealii::ParameterHandler &prm)
      {
        prm.declare_entry("Traction boundary id",
                          "1",
                          dealii::Patterns::Integer(0, 255),
                          "The boundary id of the loaded faces: a Gmsh "
                          "physical surface tag, a VTK cell data "
                          "'boundary id'; the generated beam numbers its "
                          "faces 0 (x = 0), 1 (x = L), 2, 3 (y), 4, 5 (z).");
        prm.declare_entry(
          "Traction",
          "0, 0, 0",
          // 1 MPa at most: about 100 times the stiffest soft tissue's
          // modulus; beyond, the load and not the material fails a solve.
          dealii::Patterns::List(
            dealii::Patterns::Double(-1e6, 1e6), 3, 3, ","),
          "The traction vector t (Pa = N/m^2) on those faces, each component "
          "between -1e6 and 1e6 Pa (1 MPa; a neighbouring organ's weight is "
          "of the order of 100 Pa).");
      }

      static std::unique_ptr<Effect>
      create(const dealii::ParameterHandler &prm)
      {
        return std::make_unique<SurfaceTraction>(
          prm.get_integer("Traction boundary id"),
          Utilities::parse_point(prm.get("Traction")));
      }

      void
      check(const Mesh &mesh) const override
      {
        unsigned int faces = 0;
        double       area  = 0;
        loaded(mesh, faces, area);
        if (faces > 0)
          return;
        std::set<unsigned int> ids;
        for (const auto &face : mesh.surface_faces())
          ids.insert(face.boundary_id);
        std::string list;
        for (const unsigned int id : ids)
          list += (list.empty() ? "" : ", ") + std::to_string(id);
        throw Plugins::EntryError(
          "Traction boundary id",
          "no boundary face of the mesh has id " + std::to_string(boundary_id) +
            ", so the surface traction would load nothing",
          "use one of the mesh's boundary ids: " + list + ".");
      }

      std::string
      description(const Mesh &mesh,
                  const Parameters::AllParameters &) const override
      {
        unsigned int faces = 0;
        double       area  = 0;
        loaded(mesh, faces, area);
        return "surface traction (" + Utilities::to_string(t, 4) + " Pa on " +
               std::to_string(faces) + " faces with boundary id " +
               std::to_string(boundary_id) + ", " +
               Utilities::to_string(area, 4) + " m^2)";
      }

      void
      apply(HyperelasticSystem &system,
            const Parameters::AllParameters &) const override
      {
        system.add_surface_traction(boundary_id, t);
      }

    private:
      /** The number and the area (m^2) of the loaded faces. */
      void
      loaded(const Mesh &mesh, unsigned int &faces, double &area) const
      {
        const auto &x = mesh.vertices();
        for (const auto &face : mesh.surface_faces())
          if (face.boundary_id == boundary_id)
            {
              const auto a =
                Utilities::minus(x[face.vertices[1]], x[face.vertices[0]]);
              const auto b =
                Utilities::minus(x[face.vertices[2]], x[face.vertices[0]]);
              ++faces;
              area += 0.5 * Utilities::norm(Utilities::cross(a, b));
            }
      }

      const unsigned int      boundary_id;
      const Utilities::Point3 t;
    };
  } // namespace

  PALPATE_REGISTER_EFFECT(SurfaceTraction,
                          "Surface traction",
                          "a surface traction: a dead load t per reference "
                          "area (a pressure or shear, e.g. a neighbouring "
                          "organ resting on this one) on the boundary faces "
                          "with Traction boundary id")
} // namespace palpate
