// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

// The compressible neo-Hookean solid: a material plug-in in one file
// (doc/extending.md).

#include <palpate/base/exceptions.h>
#include <palpate/base/utilities.h>
#include <palpate/hyperelastic/material.h>

#include <deal.II/base/parameter_handler.h>

#include <cmath>

namespace palpate
{
  NeoHookean::NeoHookean(const double youngs_modulus,
                         const double poissons_ratio)
    : E(youngs_modulus)
    , nu(poissons_ratio)
    , lambda(lame_lambda(E, nu))
    , mu(lame_mu(E, nu))
  {}



  bool
  NeoHookean::admissible(const Tensor<2, 3> &F) const
  {
    const double J = dealii::determinant(F);
    return std::isfinite(J) && J > 0;
  }



  double
  NeoHookean::evaluate(const Tensor<2, 3> &F,
                       Tensor<2, 3>       &P,
                       Tensor<4, 3>       *tangent) const
  {
    const double       J    = dealii::determinant(F);
    const double       lnJ  = std::log(J);
    const Tensor<2, 3> Finv = dealii::invert(F);
    // P = mu F + (lambda ln J - mu) F^-T
    P = mu * F + (lambda * lnJ - mu) * dealii::transpose(Finv);

    if (tangent != nullptr)
      {
        // A_iJkL = mu delta_ik delta_JL + lambda Finv_Ji Finv_Lk
        //          + (mu - lambda ln J) Finv_Jk Finv_Li
        Tensor<4, 3> &A = *tangent;
        const double  c = mu - lambda * lnJ;
        for (unsigned int i = 0; i < 3; ++i)
          for (unsigned int J2 = 0; J2 < 3; ++J2)
            for (unsigned int k = 0; k < 3; ++k)
              for (unsigned int L = 0; L < 3; ++L)
                A[i][J2][k][L] = (i == k && J2 == L ? mu : 0.0) +
                                 lambda * Finv[J2][i] * Finv[L][k] +
                                 c * Finv[J2][k] * Finv[L][i];
      }
    return 0.5 * mu * (dealii::scalar_product(F, F) - 3.0) - mu * lnJ +
           0.5 * lambda * lnJ * lnJ;
  }



  double
  NeoHookean::shear_modulus() const
  {
    return mu;
  }



  double
  NeoHookean::youngs_modulus() const
  {
    return E;
  }



  std::string
  NeoHookean::description() const
  {
    return "E = " + Utilities::to_string_exact(E) +
           " Pa, nu = " + Utilities::to_string_exact(nu);
  }



  std::vector<std::pair<std::string, double>>
  NeoHookean::moduli() const
  {
    return {{"Young's modulus", E}};
  }



  double
  NeoHookean::poissons_ratio() const
  {
    return nu;
  }



  void
  NeoHookean::declare_parameters(dealii::ParameterHandler &prm)
  {
    prm.declare_entry("Young's modulus",
                      "15465",
                      dealii::Patterns::Double(0.),
                      "Young's modulus E of the small-strain limit (Pa). "
                      "W = mu/2 (tr C - 3) - mu ln J + lambda/2 (ln J)^2 "
                      "with the Lame parameters of E and nu.");
    prm.declare_entry("Poisson's ratio",
                      "0.49",
                      dealii::Patterns::Double(-1., 0.5),
                      "Poisson's ratio nu of the small-strain limit "
                      "(dimensionless), -1 < nu < 0.5.");
  }



  std::unique_ptr<Material>
  NeoHookean::create(const dealii::ParameterHandler &prm)
  {
    const auto [E, nu] = parse_young_poisson(prm);
    // W = mu/2 (I1 - 3) - mu ln J + lambda/2 (ln J)^2: with nu < 0 lambda
    // is negative, and the last term, quadratic in ln J, outgrows the
    // others as an element is crushed (J -> 0): the energy falls without
    // bound and a deep enough push has no equilibrium. On liver-stvk.prm's
    // 3 cm push nu = -0.6 still converges, -0.7 to -0.9 are failure
    // points (St.Venant-Kirchhoff solves at -0.9).
    if (nu < 0)
      throw Plugins::EntryError(
        "Poisson's ratio",
        "nu = " + Utilities::to_string_exact(nu) +
          " < 0 makes lambda negative, and this Neo-Hookean energy (mu/2 "
          "(I1 - 3) - mu ln J + lambda/2 (ln J)^2) then falls without bound "
          "as an element is crushed: pushed deep enough, there is no "
          "equilibrium (on liver-stvk.prm's 3 cm push nu <= -0.7 were "
          "failure points)",
        "use 0 <= nu <= 0.4999 (soft tissue has nu close to 0.5), or "
        "St.Venant-Kirchhoff for an auxetic (nu < 0) material.");
    return std::make_unique<NeoHookean>(E, nu);
  }



  PALPATE_REGISTER_MATERIAL(
    NeoHookean,
    "Neo-Hookean",
    "compressible neo-Hookean, never softens under compression")
} // namespace palpate
