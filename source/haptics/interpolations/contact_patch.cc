// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

// State space / Interpolation = contact patch: the sphere's contact solved
// at every tick against the contact patches of the corners of the HIP's
// tetrahedron in its cell (PatchContact::blend()), for the sphere where the
// hand is. Each state keeps its patch (the compliance of the surface nodes
// the sphere can touch from the cells around it), and the last complete
// cell's patches answer while data are missing.

#include <palpate/haptics/interpolation.h>
#include <palpate/hyperelastic/patch_contact.h>
#include <palpate/mesh/mesh.h>
#include <palpate/mesh/probe_tip.h>
#include <palpate/scene/scene.h>
#include <palpate/state_space/state_cache.h>
#include <palpate/state_space/state_grid.h>

#include <deal.II/base/parameter_handler.h>

#include <algorithm>

namespace palpate
{
  namespace
  {
    /**
     * The force from the contact patches of the HIP's tetrahedron. The
     * cache's read section stays open from one complete cell to the next,
     * so that the last complete cell's patches stay alive (the cache frees
     * a patch it lets go of only once no section can hold it) and answer
     * while data are missing.
     */
    class ContactPatchInterpolation : public Interpolation
    {
    public:
      /** Work space for patches of up to @p max_nodes surface nodes. */
      ContactPatchInterpolation(const StateGrid   &grid,
                                const StateCache  &cache,
                                const unsigned int max_nodes)
        : Interpolation(grid, cache)
        , contact(max_nodes, 256)
      {}

      /** The section left open for the last cell's patches ends with the
       * interpolation: nothing reads them any more. */
      ~ContactPatchInterpolation() override
      {
        if (section_open)
          cache.end_patch_reads();
      }

      /** No entries of its own: it reads the sphere's Tip radius. */
      static void
      declare_parameters(dealii::ParameterHandler &)
      {}

      /** Each state keeps its contact patch: the solver computes it with
       * the state's factorisation, the store keeps it. */
      static constexpr Plugins::StateContents state_contents = {false, true};

      /** The contact patch is a sphere's contact solved against each
       * state's surface: a tip that moves nodes has no such contact to
       * render. */
      static void
      check_scene(const Scene &scene)
      {
        if (!ProbeTip::create(scene)->is_sphere())
          throw scene.error(
            "State space/Interpolation",
            "contact patch solves the contact of a sphere against "
            "each state's surface, but Boundary conditions / "
            "Active node / Tip is not sphere",
            "set Tip = sphere with a Tip radius, or Interpolation "
            "= tricubic Hermite.",
            {"Boundary conditions/Active node/Tip"});
      }

      static std::unique_ptr<Interpolation>
      create(const dealii::ParameterHandler &,
             const Scene &,
             const Mesh       &mesh,
             const StateGrid  &grid,
             const StateCache &cache)
      {
        // Work space for the largest patch there can be (every surface
        // node), so that the haptic thread never allocates.
        return std::make_unique<ContactPatchInterpolation>(grid,
                                                           cache,
                                                           mesh.n_vertices());
      }

      /** The force linear on the HIP's tetrahedron
       * (interpolate_on_tetrahedron()), then, where its corners' patches
       * are there, the sphere's contact against them. */
      ForceSample
      force(const Utilities::Point3 &x) noexcept override
      {
        ForceSample sample = interpolate_on_tetrahedron(grid, cache, x);
        if (sample.complete)
          render(x, sample);
        return sample;
      }

      /**
       * While data are missing: the force at @p x from the last complete
       * cell's patches, the sphere's contact against the surface and
       * compliance last known there (weights of the position clamped to
       * that cell, so that the force is continuous as the HIP leaves it).
       * False, and the section ended, if there are none or the parameters
       * changed since.
       */
      bool
      force_while_missing(const Utilities::Point3 &x,
                          Utilities::Point3       &force,
                          std::array<double, 9>   &stiffness) noexcept override
      {
        if (last_valid && cache.generation() != last_generation)
          {
            cache.end_patch_reads();
            section_open = false;
            last_valid   = false;
          }
        if (!last_valid)
          return false;
        std::array<double, 3> local;
        for (unsigned int d = 0; d < 3; ++d)
          local[d] =
            std::clamp((x[d] - last_origin[d]) / grid.spacing(), 0.0, 1.0);
        // The tetrahedron of the clamped position, less a corner whose
        // patch was not there (the last cell was complete for another
        // tetrahedron).
        auto   weights = simplex_weights(local);
        double total   = 0;
        for (unsigned int c = 0; c < 8; ++c)
          total += last_patches[c] ? weights[c] : (weights[c] = 0);
        if (!(total > 0))
          return false;
        for (double &w : weights)
          w /= total;
        contact.blend(last_patches, weights, x, force, &stiffness);
        return true;
      }

      /** Forget the patches read: a new contact starts. */
      void
      reset() noexcept override
      {
        if (section_open)
          cache.end_patch_reads();
        section_open = false;
        last_valid   = false;
      }

    private:
      /**
       * The force of the complete @p sample at @p x from its corners'
       * contact patches, solved for the sphere there, in place of the force
       * linear on the HIP's tetrahedron. A corner of that tetrahedron
       * without a patch (dropped for the memory budget) leaves the
       * sample's linear force.
       */
      void
      render(const Utilities::Point3 &x, ForceSample &sample) noexcept
      {
        const std::uint64_t                 generation = cache.generation();
        std::array<const ContactPatch *, 8> patches;
        // The section of the last complete cell ends here: its patches are
        // not read again.
        if (section_open)
          cache.end_patch_reads();
        cache.begin_patch_reads();
        section_open = true;
        // The cell's patches that are there (those of the other tetrahedra
        // keep answering for missing data beyond this one's face); those
        // of the HIP's tetrahedron are needed.
        for (unsigned int c = 0; c < 8; ++c)
          patches[c] = cache.read_patch(sample.corners[c], generation);
        bool all = true;
        for (const unsigned int c : simplex_corners(sample.local))
          all = all && patches[c];
        last_valid = all;
        if (all)
          {
            contact.blend(patches,
                          simplex_weights(sample.local),
                          x,
                          sample.force,
                          &sample.stiffness);
            last_patches    = patches;
            last_origin     = grid.position(sample.corners[0]);
            last_generation = generation;
          }
      }

      PatchContact                        contact;
      bool                                section_open    = false;
      bool                                last_valid      = false;
      std::array<const ContactPatch *, 8> last_patches    = {};
      Utilities::Point3                   last_origin     = {{0, 0, 0}};
      std::uint64_t                       last_generation = 0;
    };
  } // namespace

  PALPATE_REGISTER_INTERPOLATION(
    ContactPatchInterpolation,
    "contact patch",
    "for Tip = sphere, each state also keeps the compliance of the surface "
    "nodes the sphere can touch from the cells around it (one solve per "
    "node with the state's factorisation), and the haptic loop solves the "
    "sphere's contact against the corners' patches at every tick, for the "
    "sphere where the hand is: zero force off the surface, the tissue's "
    "onset between the states (doc/formulation.md)")
} // namespace palpate
