// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

// State space / Interpolation = trilinear: the paper's interpolation, the
// force trilinear in the 8 corners' forces (interpolate_force()).

#include <palpate/haptics/interpolation.h>

#include <deal.II/base/parameter_handler.h>

namespace palpate
{
  namespace
  {
    /** The trilinear force of the HIP's cell. */
    class Trilinear : public Interpolation
    {
    public:
      using Interpolation::Interpolation;

      /** No entries of its own. */
      static void
      declare_parameters(dealii::ParameterHandler &)
      {}

      /** The corners' forces are all it reads. */
      static constexpr Plugins::StateContents state_contents = {};

      static std::unique_ptr<Interpolation>
      create(const dealii::ParameterHandler &,
             const Scene &,
             const Mesh &,
             const StateGrid  &grid,
             const StateCache &cache)
      {
        return std::make_unique<Trilinear>(grid, cache);
      }

      ForceSample
      force(const Utilities::Point3 &x) noexcept override
      {
        return interpolate_force(grid, cache, x);
      }
    };
  } // namespace

  PALPATE_REGISTER_INTERPOLATION(
    Trilinear,
    "trilinear",
    "the paper's, from the 8 corners' forces; continuous, but the "
    "stiffness the hand feels jumps at every cell face")
} // namespace palpate
