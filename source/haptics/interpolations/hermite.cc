// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

// State space / Interpolation = tricubic Hermite: the force and its
// derivative continuous across cell faces (C1), from the corners' forces
// and stiffnesses and the neighbours' stiffnesses (interpolate_hermite()).

#include <palpate/haptics/interpolation.h>

#include <deal.II/base/parameter_handler.h>

namespace palpate
{
  namespace
  {
    /** The tricubic Hermite force of the HIP's cell. */
    class TricubicHermite : public Interpolation
    {
    public:
      using Interpolation::Interpolation;

      /** No entries of its own. */
      static void
      declare_parameters(dealii::ParameterHandler &)
      {}

      /** The first derivatives at each corner are minus its active-node
       * stiffness, and the cross derivatives come from the neighbours'
       * (StateCache::read_cross_derivatives()): every state keeps it. */
      static constexpr Plugins::StateContents state_contents = {true, false};

      static std::unique_ptr<Interpolation>
      create(const dealii::ParameterHandler &,
             const Scene &,
             const Mesh &,
             const StateGrid  &grid,
             const StateCache &cache)
      {
        return std::make_unique<TricubicHermite>(grid, cache);
      }

      ForceSample
      force(const Utilities::Point3 &x) noexcept override
      {
        return interpolate_hermite(grid, cache, x);
      }
    };
  } // namespace

  PALPATE_REGISTER_INTERPOLATION(
    TricubicHermite,
    "tricubic Hermite",
    "from the corners' forces and active-node stiffnesses (three extra "
    "solves per state with the kept factorisation) and the neighbours' "
    "stiffnesses; the force and the stiffness are continuous, so a coarser "
    "grid gives the same accuracy (doc/accuracy-vs-time.md)")
} // namespace palpate
