// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

// St.Venant-Kirchhoff, the paper's first model: a material plug-in in one
// file (doc/extending.md).

#include <palpate/base/exceptions.h>
#include <palpate/base/utilities.h>
#include <palpate/hyperelastic/material.h>

#include <deal.II/base/parameter_handler.h>

#include <cmath>

namespace palpate
{
  StVenantKirchhoff::StVenantKirchhoff(const double youngs_modulus,
                                       const double poissons_ratio)
    : E(youngs_modulus)
    , nu(poissons_ratio)
    , lambda(lame_lambda(E, nu))
    , mu(lame_mu(E, nu))
  {}



  double
  StVenantKirchhoff::evaluate(const Tensor<2, 3> &F,
                              Tensor<2, 3>       &P,
                              Tensor<4, 3>       *tangent) const
  {
    // Green strain and second Piola-Kirchhoff stress.
    Tensor<2, 3> E_green = dealii::transpose(F) * F;
    for (unsigned int i = 0; i < 3; ++i)
      E_green[i][i] -= 1.0;
    E_green *= 0.5;
    const double trE = dealii::trace(E_green);
    Tensor<2, 3> S   = 2.0 * mu * E_green;
    for (unsigned int i = 0; i < 3; ++i)
      S[i][i] += lambda * trE;
    P = F * S;

    if (tangent != nullptr)
      {
        // A_iJkL = delta_ik S_JL + F_iI C_IJKL F_kK with
        // C_IJKL = lambda delta_IJ delta_KL + mu (delta_IK delta_JL +
        // delta_IL delta_JK). Written out:
        //   lambda F_iJ F_kL + mu (F_iL F_kJ + delta_JL (F F^T)_ik)
        const Tensor<2, 3> FFt = F * dealii::transpose(F);
        Tensor<4, 3>      &A   = *tangent;
        for (unsigned int i = 0; i < 3; ++i)
          for (unsigned int J = 0; J < 3; ++J)
            for (unsigned int k = 0; k < 3; ++k)
              for (unsigned int L = 0; L < 3; ++L)
                A[i][J][k][L] =
                  (i == k ? S[J][L] : 0.0) + lambda * F[i][J] * F[k][L] +
                  mu * (F[i][L] * F[k][J] + (J == L ? FFt[i][k] : 0.0));
      }
    return 0.5 * lambda * trE * trE +
           mu * dealii::scalar_product(E_green, E_green);
  }



  double
  StVenantKirchhoff::shear_modulus() const
  {
    return mu;
  }



  double
  StVenantKirchhoff::youngs_modulus() const
  {
    return E;
  }



  std::string
  StVenantKirchhoff::description() const
  {
    return "E = " + Utilities::to_string_exact(E) +
           " Pa, nu = " + Utilities::to_string_exact(nu);
  }



  std::vector<std::pair<std::string, double>>
  StVenantKirchhoff::moduli() const
  {
    return {{"Young's modulus", E}};
  }



  double
  StVenantKirchhoff::poissons_ratio() const
  {
    return nu;
  }



  void
  StVenantKirchhoff::declare_parameters(dealii::ParameterHandler &prm)
  {
    prm.declare_entry("Young's modulus",
                      "15465",
                      dealii::Patterns::Double(0.),
                      "Young's modulus E (Pa). The Lame parameters are "
                      "lambda = E nu/((1+nu)(1-2nu)), mu = E/(2(1+nu)).");
    prm.declare_entry("Poisson's ratio",
                      "0.49",
                      dealii::Patterns::Double(-1., 0.5),
                      "Poisson's ratio nu (dimensionless), -1 < nu < "
                      "0.5.");
  }



  std::unique_ptr<Material>
  StVenantKirchhoff::create(const dealii::ParameterHandler &prm)
  {
    const auto [E, nu] = parse_young_poisson(prm);
    return std::make_unique<StVenantKirchhoff>(E, nu);
  }



  PALPATE_REGISTER_MATERIAL(
    StVenantKirchhoff,
    "St.Venant-Kirchhoff",
    "the paper's first model, linear in the Green strain; softens and may "
    "invert under strong compression")
} // namespace palpate
