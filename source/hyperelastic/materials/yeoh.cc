// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

// The Yeoh material, a plug-in in one file: the example of
// doc/extending.md. Nothing else in palpate names it; the registration at
// the end makes `Material model / Model name = Yeoh` and its subsection
// exist, in scenes, in the parameter reference and in error messages.

#include <palpate/base/utilities.h>
#include <palpate/hyperelastic/material.h>

#include <deal.II/base/parameter_handler.h>

namespace palpate
{
  namespace
  {
    /**
     * The incompressible Yeoh solid,
     *   W_iso = C10 (I1bar - 3) + C20 (I1bar - 3)^2 + C30 (I1bar - 3)^3,
     * which stiffens with strain as soft tissue does (Yeoh 1993). The FE
     * module adds the pressure field, as for Mooney-Rivlin. Small-strain
     * shear modulus mu = 2 C10.
     */
    class Yeoh : public Material
    {
    public:
      Yeoh(const double       c10,
           const double       c20,
           const double       c30,
           const Formulation &formulation)
        : c{c10, c20, c30}
        , mixed(formulation)
      {}

      static void
      declare_parameters(dealii::ParameterHandler &prm)
      {
        prm.declare_entry("C10",
                          "2577.5",
                          dealii::Patterns::Double(0.),
                          "Coefficient of (I1 - 3) (Pa); the small-strain "
                          "shear modulus is 2 C10 (the default gives the "
                          "paper's E = 15465 Pa).");
        prm.declare_entry("C20",
                          "1288.75",
                          dealii::Patterns::Double(),
                          "Coefficient of (I1 - 3)^2 (Pa): the stiffening "
                          "at large strain.");
        prm.declare_entry("C30",
                          "0",
                          dealii::Patterns::Double(),
                          "Coefficient of (I1 - 3)^3 (Pa).");
        declare_incompressibility(prm);
      }

      static std::unique_ptr<Material>
      create(const dealii::ParameterHandler &prm)
      {
        const double c10 = prm.get_double("C10");
        check_modulus("C10", c10);
        const double c20 = prm.get_double("C20"), c30 = prm.get_double("C30");
        // The law must stay stable over the strains a probe causes:
        // W'(x) = C10 + 2 C20 x + 3 C30 x^2 > 0 for x = I1bar - 3 in
        // [0, 3] (stretches up to about 2.2). A negative C20 or C30 large
        // against C10 makes the energy fall with strain: every state near
        // rest is a failure point and the run renders no force.
        for (unsigned int k = 0; k <= 30; ++k)
          if (const double x = 0.1 * k;
              !(c10 + 2 * c20 * x + 3 * c30 * x * x > 0))
            throw Plugins::EntryError(
              c20 < 0 ? "C20" : "C30",
              "with C10 = " + Utilities::to_string(c10) +
                ", C20 = " + Utilities::to_string(c20) +
                " and C30 = " + Utilities::to_string(c30) +
                " Pa the law is unstable: its stiffness C10 + 2 C20 x + 3 "
                "C30 x^2 is not positive at I1 - 3 = " +
                Utilities::to_string(x, 2) +
                " (a strain a probe reaches), so no state there exists",
              "make C20 and C30 positive (soft tissue stiffens with strain), "
              "or small against C10.");
        return std::make_unique<Yeoh>(c10,
                                      c20,
                                      c30,
                                      parse_incompressibility(prm));
      }

      double
      evaluate(const Tensor<2, 3> &F,
               Tensor<2, 3>       &P,
               Tensor<4, 3>       *tangent) const override
      {
        IsochoricInvariants inv;
        isochoric_invariants(F, inv, tangent != nullptr);
        // W(x) with x = I1bar - 3: P = W' dI1bar,
        // A = W' d2I1bar + W'' dI1bar (x) dI1bar.
        const double x   = inv.I1bar - 3.0;
        const double W1  = c[0] + 2 * c[1] * x + 3 * c[2] * x * x;
        const double W11 = 2 * c[1] + 6 * c[2] * x;
        P                = W1 * inv.dI1bar;
        if (tangent != nullptr)
          *tangent = W1 * inv.d2I1bar +
                     W11 * dealii::outer_product(inv.dI1bar, inv.dI1bar);
        return c[0] * x + c[1] * x * x + c[2] * x * x * x;
      }

      bool
      admissible(const Tensor<2, 3> &F) const override
      {
        const double J = dealii::determinant(F);
        return std::isfinite(J) && J > 0;
      }

      bool
      isochoric() const override
      {
        return true;
      }

      Formulation
      formulation() const override
      {
        return mixed;
      }

      double
      shear_modulus() const override
      {
        return 2 * c[0];
      }

      double
      youngs_modulus() const override
      {
        return 3 * shear_modulus();
      }

      double
      poissons_ratio() const override
      {
        return 0.5;
      }

      std::vector<std::pair<std::string, double>>
      moduli() const override
      {
        return {{"C10", c[0]}, {"C20", c[1]}, {"C30", c[2]}};
      }

      std::string
      description() const override
      {
        return "C10 = " + Utilities::to_string_exact(c[0]) +
               " Pa, C20 = " + Utilities::to_string_exact(c[1]) +
               " Pa, C30 = " + Utilities::to_string_exact(c[2]) + " Pa, " +
               (mixed.pressure == Formulation::Pressure::exact ?
                  "exactly incompressible, " + mixed.element + " elements" :
                  "nearly incompressible, bulk modulus " +
                    Utilities::to_string_exact(mixed.bulk_modulus) + " Pa");
      }

    private:
      const double      c[3];
      const Formulation mixed;
    };
  } // namespace

  PALPATE_REGISTER_MATERIAL(Yeoh,
                            "Yeoh",
                            "incompressible Yeoh, W = sum Ci0 (I1bar - 3)^i: "
                            "stiffens with strain like soft tissue")
} // namespace palpate
