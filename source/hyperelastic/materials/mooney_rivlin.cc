// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

// Mooney-Rivlin, the paper's second model, incompressible with a pressure
// field: a material plug-in in one file (doc/extending.md).

#include <palpate/base/exceptions.h>
#include <palpate/base/utilities.h>
#include <palpate/hyperelastic/material.h>

#include <deal.II/base/parameter_handler.h>

#include <cmath>

namespace palpate
{
  MooneyRivlin::MooneyRivlin(const double       c10,
                             const double       c01,
                             const Formulation &formulation)
    : c10(c10)
    , c01(c01)
    , mixed(formulation)
  {
    // The isochoric energy alone is not a solid: without a pressure field
    // it has no volumetric stiffness. Default to the paper's formulation.
    if (mixed.pressure == Formulation::Pressure::none)
      {
        mixed.pressure            = Formulation::Pressure::exact;
        mixed.element             = "P1-P1";
        mixed.displacement_degree = 1;
      }
  }



  Formulation
  MooneyRivlin::formulation() const
  {
    return mixed;
  }



  std::vector<std::pair<std::string, double>>
  MooneyRivlin::moduli() const
  {
    return {{"C10", c10}, {"C01", c01}, {"Bulk modulus", mixed.bulk_modulus}};
  }



  double
  MooneyRivlin::poissons_ratio() const
  {
    return 0.5;
  }



  void
  MooneyRivlin::declare_parameters(dealii::ParameterHandler &prm)
  {
    prm.declare_entry("C10",
                      "2148",
                      dealii::Patterns::Double(0.),
                      "Coefficient of (I1 - 3) in the strain energy "
                      "(Pa). The shear modulus is mu = 2 (C10 + C01); "
                      "the defaults give mu = E/3 for the paper's "
                      "E = 15465 Pa with C01/C10 = 0.2.");
    prm.declare_entry("C01",
                      "429.6",
                      dealii::Patterns::Double(0.),
                      "Coefficient of (I2 - 3) in the strain energy "
                      "(Pa).");
    declare_incompressibility(prm);
  }



  std::unique_ptr<Material>
  MooneyRivlin::create(const dealii::ParameterHandler &prm)
  {
    const double c10 = prm.get_double("C10"), c01 = prm.get_double("C01");
    if (!(c10 + c01 > 0))
      throw Plugins::EntryError(
        "C10",
        "the shear modulus 2 (C10 + C01) must be positive",
        "set C10 (and C01) in Pa; for Young's modulus E of an "
        "incompressible solid, C10 + C01 = E/6.");
    return std::make_unique<MooneyRivlin>(c10,
                                          c01,
                                          parse_incompressibility(prm));
  }



  bool
  MooneyRivlin::admissible(const Tensor<2, 3> &F) const
  {
    const double J = dealii::determinant(F);
    return std::isfinite(J) && J > 0;
  }



  double
  MooneyRivlin::evaluate(const Tensor<2, 3> &F,
                         Tensor<2, 3>       &P,
                         Tensor<4, 3>       *tangent) const
  {
    // The same derivatives as isochoric_invariants() combined with c10
    // and c01 (its comments derive them), but the tangent in one pass over
    // its 81 entries instead of ten passes and six fourth-order
    // temporaries, which made the material a large part of the assembly
    // of a liver's tangent (P1-P1 has one quadrature point per cell;
    // doc/benchmarks/organ-speed.md). tests/hyperelastic/tangent checks it
    // against finite differences of the residual.
    const double       J    = dealii::determinant(F);
    const Tensor<2, 3> Finv = dealii::invert(F);
    const Tensor<2, 3> dJ   = J * dealii::transpose(Finv);
    const double       I1   = dealii::scalar_product(F, F);
    const Tensor<2, 3> C    = dealii::transpose(F) * F;
    const double       I2   = 0.5 * (I1 * I1 - dealii::scalar_product(C, C));
    const Tensor<2, 3> dI1  = 2.0 * F;
    const Tensor<2, 3> dI2  = 2.0 * (I1 * F - F * C);
    // I1bar = phi1 I1, I2bar = phi2 I2 with phi1 = J^(-2/3), phi2 =
    // J^(-4/3) = phi1^2, and their derivatives by J.
    const double cube_root = std::cbrt(J);
    const double phi1 = 1.0 / (cube_root * cube_root), phi2 = phi1 * phi1;
    const double e1 = -2.0 / 3.0, e2 = -4.0 / 3.0;
    const double dphi1 = e1 * phi1 / J, dphi2 = e2 * phi2 / J;
    // W's first derivative: c10 dI1bar + c01 dI2bar.
    const double       a2 = c10 * dphi1 * I1 + c01 * dphi2 * I2;
    const Tensor<2, 3> G  = c10 * dphi1 * dI1 + c01 * dphi2 * dI2;
    P                     = a2 * dJ + c10 * phi1 * dI1 + c01 * phi2 * dI2;
    if (tangent != nullptr)
      {
        const double       d2phi1 = e1 * (e1 - 1) * phi1 / (J * J);
        const double       d2phi2 = e2 * (e2 - 1) * phi2 / (J * J);
        const double       a1     = c10 * d2phi1 * I1 + c01 * d2phi2 * I2;
        const double       s1 = 2.0 * c10 * phi1, s2 = 2.0 * c01 * phi2;
        const Tensor<2, 3> b = F * dealii::transpose(F);
        Tensor<4, 3>      &T = *tangent;
        for (unsigned int i = 0; i < 3; ++i)
          for (unsigned int A = 0; A < 3; ++A)
            for (unsigned int k = 0; k < 3; ++k)
              for (unsigned int B = 0; B < 3; ++B)
                {
                  const double dik = (i == k), dAB = (A == B);
                  // d2J, d2I1 / 2 and d2I2 / 2 (isochoric_invariants()).
                  const double d2J =
                    J * (Finv[A][i] * Finv[B][k] - Finv[A][k] * Finv[B][i]);
                  const double d2I1 = dik * dAB;
                  const double d2I2 = 2.0 * F[i][A] * F[k][B] + I1 * dik * dAB -
                                      dik * C[A][B] - F[i][B] * F[k][A] -
                                      b[i][k] * dAB;
                  T[i][A][k][B] = a1 * dJ[i][A] * dJ[k][B] + a2 * d2J +
                                  dJ[i][A] * G[k][B] + G[i][A] * dJ[k][B] +
                                  s1 * d2I1 + s2 * d2I2;
                }
      }
    return c10 * (phi1 * I1 - 3.0) + c01 * (phi2 * I2 - 3.0);
  }



  double
  MooneyRivlin::shear_modulus() const
  {
    return 2.0 * (c10 + c01);
  }



  double
  MooneyRivlin::youngs_modulus() const
  {
    return 3.0 * shear_modulus();
  }



  std::string
  MooneyRivlin::description() const
  {
    return "C10 = " + Utilities::to_string_exact(c10) +
           " Pa, C01 = " + Utilities::to_string_exact(c01) + " Pa, " +
           (mixed.pressure == Formulation::Pressure::exact ?
              "exactly incompressible, " + mixed.element + " elements" :
              "nearly incompressible, bulk modulus " +
                Utilities::to_string_exact(mixed.bulk_modulus) + " Pa");
  }



  PALPATE_REGISTER_MATERIAL(
    MooneyRivlin,
    "Mooney-Rivlin",
    "the paper's second model, incompressible, with a pressure multiplier "
    "field")
} // namespace palpate
