// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

// Mesh / Source = beam: a rectangular beam of tetrahedra, generated in
// metres from the subsection Mesh / Beam; it needs no external data.

#include <palpate/mesh/generators.h>
#include <palpate/mesh/mesh_source.h>
#include <palpate/scene/scene.h>

#include <deal.II/base/parameter_handler.h>

namespace palpate
{
  namespace
  {
    // The beam's size: the entries only Source = beam reads.
    void
    check_beam_size(const Scene &scene)
    {
      using namespace Limits;
      const auto  &p        = scene.parameters;
      const double dims[3]  = {p.mesh.beam_length,
                               p.mesh.beam_width,
                               p.mesh.beam_height};
      const char  *names[3] = {"Length", "Width", "Height"};
      const char  *words[3] = {"length", "width", "height"};
      for (unsigned int d = 0; d < 3; ++d)
        if (!(dims[d] > 0))
          throw scene.error(std::string("Mesh/Beam/") + names[d],
                            std::string("the beam's ") + words[d] +
                              " must be positive: a beam of zero or negative " +
                              words[d] + " has no volume",
                            std::string("set it in metres, e.g. ") +
                              (d == 0 ? "0.1." : "0.02."));
        else if (dims[d] < min_body_size / 2 || dims[d] > max_body_size)
          // As a mesh file's body (Mesh::create()): past these its
          // elements' volumes under- or overflow and the messages blame
          // the generated mesh.
          throw scene.error(std::string("Mesh/Beam/") + names[d],
                            std::string("a beam ") +
                              Utilities::to_string(dims[d], 3) + " m in " +
                              words[d] + "; a body to palpate is " +
                              Utilities::to_string(min_body_size / 2, 3) +
                              " to " + Utilities::to_string(max_body_size, 3) +
                              " m in each direction",
                            std::string("set it in metres, e.g. ") +
                              (d == 0 ? "0.1." : "0.02."));
      const double nodes = (p.mesh.beam_subdivisions_length + 1.) *
                           (p.mesh.beam_subdivisions_width + 1.) *
                           (p.mesh.beam_subdivisions_height + 1.);
      if (nodes > max_generated_nodes)
        throw scene.error("Mesh/Beam/Subdivisions",
                          "the beam would have " +
                            Utilities::to_string(nodes, 3) +
                            " nodes; at most " +
                            Utilities::to_string(max_generated_nodes, 3) +
                            " are allowed (a state of 1e5 nodes takes minutes, "
                            "far from haptic rates)",
                          "use fewer subdivisions, e.g. 10, 2, 2.");
    }



    /** The beam generator's body (generate_beam()). */
    class BeamSource : public MeshSource
    {
    public:
      /** No entries of its own: it reads the subsection Mesh / Beam. */
      static void
      declare_parameters(dealii::ParameterHandler &)
      {}

      static std::unique_ptr<MeshSource>
      create(const dealii::ParameterHandler &, const Scene &)
      {
        return std::make_unique<BeamSource>();
      }

      static void
      check_scene(const Scene &scene)
      {
        check_no_file_named(scene);
        check_beam_size(scene);
      }

      Mesh
      create_mesh(const Scene &scene) const override
      {
        return Mesh(generate_beam(scene.parameters.mesh),
                    1.0,
                    "the beam generator");
      }

      /** Twice the subdivisions along each side. */
      std::optional<Finer>
      make_finer(Parameters::Mesh &m, const Scene &) const override
      {
        m.beam_subdivisions_length *= 2;
        m.beam_subdivisions_width *= 2;
        m.beam_subdivisions_height *= 2;
        return Finer{"", "beam, twice the subdivisions"};
      }
    };
  } // namespace

  PALPATE_REGISTER_MESH_SOURCE(
    BeamSource,
    "beam",
    "a rectangular beam made by palpate's generator (subsection Beam), "
    "which needs no external data")
} // namespace palpate
