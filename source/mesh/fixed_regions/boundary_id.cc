// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

// Fixed nodes / Selection = boundary id: the nodes of the surface faces
// whose boundary id is one of Boundary ids (a Gmsh file's physical tags of
// triangles, the beam generator's sides).

#include <palpate/mesh/fixed_region.h>
#include <palpate/mesh/mesh.h>
#include <palpate/scene/scene.h>

#include <deal.II/base/parameter_handler.h>

#include <sstream>
#include <vector>

namespace palpate
{
  namespace
  {
    /** The nodes on the boundary faces with the ids Boundary ids. */
    class BoundaryIdRegion : public FixedRegion
    {
    public:
      explicit BoundaryIdRegion(const std::vector<unsigned int> &ids)
        : ids(ids)
      {}

      /** No entries of its own: it reads Fixed nodes / Boundary ids. */
      static void
      declare_parameters(dealii::ParameterHandler &)
      {}

      static std::unique_ptr<FixedRegion>
      create(const dealii::ParameterHandler &, const Scene &scene)
      {
        return std::make_unique<BoundaryIdRegion>(
          scene.parameters.boundary_conditions.fixed_nodes.boundary_ids);
      }

      /** Every node of such a face, on the surface by definition (Surface
       * nodes only changes nothing). */
      Selected
      select(const Scene &, const Mesh &mesh) const override
      {
        const std::set<unsigned int> wanted(ids.begin(), ids.end());
        Selected                     selected;
        for (const auto &face : mesh.surface_faces())
          if (wanted.count(face.boundary_id))
            selected.fixed.insert(face.vertices.begin(), face.vertices.end());
        selected.in_region = selected.fixed.size();
        return selected;
      }

      std::string
      entry() const override
      {
        return "Boundary conditions/Fixed nodes/Boundary ids";
      }

      std::string
      description(const Selected &) const override
      {
        std::ostringstream description;
        description << "nodes on boundary faces with id";
        for (const auto id : ids)
          description << " " << id;
        return description.str();
      }

    private:
      /** As the scene lists them (the description repeats them so). */
      const std::vector<unsigned int> ids;
    };
  } // namespace

  PALPATE_REGISTER_FIXED_REGION(BoundaryIdRegion,
                                "boundary id",
                                "all nodes on boundary faces with the ids "
                                "Boundary ids")
} // namespace palpate
