// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

// Effects / Gravity: the body carries its weight.

#include <palpate/base/utilities.h>
#include <palpate/hyperelastic/effect.h>
#include <palpate/hyperelastic/hyperelastic_system.h>

#include <deal.II/base/parameter_handler.h>

namespace palpate
{
  namespace
  {
    /**
     * The body force rho g per unit reference volume (N/m^3), a dead load
     * (it does not follow the deformation), with rho from Material model /
     * Density. The reactions of the fixed nodes and the probe sum to the
     * weight rho g V (test hyperelastic/reactions).
     */
    class Gravity : public Effect
    {
    public:
      explicit Gravity(const Utilities::Point3 &g)
        : g(g)
      {}

      static void
      declare_parameters(dealii::ParameterHandler &prm)
      {
        prm.declare_entry(
          "Gravitational acceleration",
          "0, 0, -9.81",
          // 100 g at most in each direction: beyond, no tissue holds its
          // own weight, and a failure would seem to be the material's.
          dealii::Patterns::List(
            dealii::Patterns::Double(-1000, 1000), 3, 3, ","),
          "Gravitational acceleration vector g (m/s^2), each component "
          "between -1000 and 1000 (100 g; Earth's is 9.81).");
      }

      static std::unique_ptr<Effect>
      create(const dealii::ParameterHandler &prm)
      {
        return std::make_unique<Gravity>(
          Utilities::parse_point(prm.get("Gravitational acceleration")));
      }

      std::string
      description(const Mesh &,
                  const Parameters::AllParameters &p) const override
      {
        return "gravity (rho g = " +
               Utilities::to_string(Utilities::scaled(g,
                                                      p.material_model.density),
                                    5) +
               " N/m^3)";
      }

      void
      apply(HyperelasticSystem              &system,
            const Parameters::AllParameters &p) const override
      {
        system.add_body_force(Utilities::scaled(g, p.material_model.density));
      }

    private:
      const Utilities::Point3 g;
    };
  } // namespace

  PALPATE_REGISTER_EFFECT(Gravity,
                          "Gravity",
                          "gravity: the body carries its weight, the body "
                          "force rho g (rho from Material model / Density)")
} // namespace palpate
