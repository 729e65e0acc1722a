// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

// Mesh / Source = blob: an organ-like blob of tetrahedra, generated in
// metres from the subsection Mesh / Blob; it needs no external data.

#include <palpate/mesh/generators.h>
#include <palpate/mesh/mesh_source.h>
#include <palpate/scene/scene.h>

#include <deal.II/base/parameter_handler.h>

namespace palpate
{
  namespace
  {
    // The blob's size: the entries only Source = blob reads.
    void
    check_blob_size(const Scene &scene)
    {
      using namespace Limits;
      const auto &p = scene.parameters;
      for (unsigned int d = 0; d < 3; ++d)
        {
          if (!(p.mesh.blob_semi_axes[d] > 0))
            throw scene.error(
              "Mesh/Blob/Semi-axes",
              "every semi-axis must be positive: a blob with a zero "
              "or negative semi-axis has no volume",
              "give three lengths in metres, e.g. 0.125, 0.09, 0.07.");
          else if (p.mesh.blob_semi_axes[d] < min_body_size / 4 ||
                   p.mesh.blob_semi_axes[d] > max_body_size / 2)
            throw scene.error(
              "Mesh/Blob/Semi-axes",
              "a semi-axis of " +
                Utilities::to_string(p.mesh.blob_semi_axes[d], 3) +
                " m; a body to palpate is " +
                Utilities::to_string(min_body_size / 2, 3) + " to " +
                Utilities::to_string(max_body_size, 3) +
                " m across, a semi-axis half that",
              "give three lengths in metres, e.g. 0.125, 0.09, 0.07.");
        }
    }



    /** The blob generator's body (generate_blob()). */
    class BlobSource : public MeshSource
    {
    public:
      /** No entries of its own: it reads the subsection Mesh / Blob. */
      static void
      declare_parameters(dealii::ParameterHandler &)
      {}

      static std::unique_ptr<MeshSource>
      create(const dealii::ParameterHandler &, const Scene &)
      {
        return std::make_unique<BlobSource>();
      }

      static void
      check_scene(const Scene &scene)
      {
        check_no_file_named(scene);
        check_blob_size(scene);
      }

      Mesh
      create_mesh(const Scene &scene) const override
      {
        return Mesh(generate_blob(scene.parameters.mesh),
                    1.0,
                    "the blob generator");
      }

      /** One refinement more. */
      std::optional<Finer>
      make_finer(Parameters::Mesh &m, const Scene &) const override
      {
        ++m.blob_refinements;
        return Finer{"",
                     "blob, " + std::to_string(m.blob_refinements) +
                       " refinements"};
      }
    };
  } // namespace

  PALPATE_REGISTER_MESH_SOURCE(
    BlobSource,
    "blob",
    "an organ-like blob made by palpate's generator (subsection Blob), "
    "which needs no external data")
} // namespace palpate
