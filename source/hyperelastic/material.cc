// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

#include <palpate/base/exceptions.h>
#include <palpate/base/utilities.h>
#include <palpate/hyperelastic/material.h>

#include <cmath>

namespace palpate
{
  bool
  Material::admissible(const Tensor<2, 3> &F) const
  {
    return std::isfinite(dealii::determinant(F));
  }



  std::unique_ptr<Material>
  Material::create(const Parameters::MaterialModel &p)
  {
    if (p.model_name == "St.Venant-Kirchhoff")
      return std::make_unique<StVenantKirchhoff>(p.stvk_youngs_modulus,
                                                 p.stvk_poissons_ratio);
    if (p.model_name == "Neo-Hookean")
      return std::make_unique<NeoHookean>(p.nh_youngs_modulus,
                                          p.nh_poissons_ratio);
    throw NotAvailableError("The " + p.model_name + " material",
                            "Use St.Venant-Kirchhoff or Neo-Hookean in "
                            "Material model / Model name; Mooney-Rivlin "
                            "with its pressure field comes with the "
                            "incompressible mixed elements.");
  }



  namespace
  {
    double
    lame_lambda(const double E, const double nu)
    {
      return E * nu / ((1 + nu) * (1 - 2 * nu));
    }

    double
    lame_mu(const double E, const double nu)
    {
      return E / (2 * (1 + nu));
    }
  } // namespace



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
    return "St.Venant-Kirchhoff, E = " + Utilities::to_string(E) +
           " Pa, nu = " + Utilities::to_string(nu);
  }



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
    return "compressible neo-Hookean, E = " + Utilities::to_string(E) +
           " Pa, nu = " + Utilities::to_string(nu);
  }
} // namespace palpate
