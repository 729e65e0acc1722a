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
    if (p.model_name == "Mooney-Rivlin")
      return std::make_unique<MooneyRivlin>(p.mr_c10, p.mr_c01);
    throw std::invalid_argument("unknown material " + p.model_name);
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


  void
  volume_derivatives(const Tensor<2, 3> &F,
                     double             &J,
                     Tensor<2, 3>       &dJ,
                     Tensor<4, 3>       *d2J)
  {
    J                       = dealii::determinant(F);
    const Tensor<2, 3> Finv = dealii::invert(F);
    dJ                      = J * dealii::transpose(Finv);
    if (d2J != nullptr)
      for (unsigned int i = 0; i < 3; ++i)
        for (unsigned int A = 0; A < 3; ++A)
          for (unsigned int k = 0; k < 3; ++k)
            for (unsigned int B = 0; B < 3; ++B)
              (*d2J)[i][A][k][B] =
                J * (Finv[A][i] * Finv[B][k] - Finv[A][k] * Finv[B][i]);
  }



  namespace
  {
    /**
     * For f = phi(J) I, with phi = J^e, given I, dI/dF and d2I/dF2 and
     * the derivatives of J: f, df/dF and d2f/dF2 by the product rule.
     */
    double
    scaled_invariant(const double        e,
                     const double        J,
                     const Tensor<2, 3> &dJ,
                     const Tensor<4, 3> &d2J,
                     const double        I,
                     const Tensor<2, 3> &dI,
                     const Tensor<4, 3> &d2I,
                     Tensor<2, 3>       &df,
                     Tensor<4, 3>       *d2f)
    {
      const double phi   = std::pow(J, e);
      const double dphi  = e * phi / J;
      const double d2phi = e * (e - 1) * phi / (J * J);
      df                 = dphi * I * dJ + phi * dI;
      if (d2f != nullptr)
        for (unsigned int i = 0; i < 3; ++i)
          for (unsigned int A = 0; A < 3; ++A)
            for (unsigned int k = 0; k < 3; ++k)
              for (unsigned int B = 0; B < 3; ++B)
                (*d2f)[i][A][k][B] =
                  d2phi * I * dJ[i][A] * dJ[k][B] + dphi * I * d2J[i][A][k][B] +
                  dphi * (dJ[i][A] * dI[k][B] + dI[i][A] * dJ[k][B]) +
                  phi * d2I[i][A][k][B];
      return phi * I;
    }
  } // namespace



  MooneyRivlin::MooneyRivlin(const double c10, const double c01)
    : c10(c10)
    , c01(c01)
  {}



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
    double       J;
    Tensor<2, 3> dJ;
    Tensor<4, 3> d2J;
    volume_derivatives(F, J, dJ, tangent ? &d2J : nullptr);

    // I1 = F:F, dI1 = 2F, d2I1 = 2 d_ik d_AB.
    const double I1  = dealii::scalar_product(F, F);
    Tensor<2, 3> dI1 = 2.0 * F;
    // I2 = (I1^2 - C:C)/2, dI2 = 2 (I1 F - F C),
    // d2I2 = 2 (2 F_iA F_kB + I1 d_ik d_AB - d_ik C_AB - F_iB F_kA - b_ik
    // d_AB).
    const Tensor<2, 3> C   = dealii::transpose(F) * F;
    const Tensor<2, 3> b   = F * dealii::transpose(F);
    const double       I2  = 0.5 * (I1 * I1 - dealii::scalar_product(C, C));
    const Tensor<2, 3> dI2 = 2.0 * (I1 * F - F * C);
    Tensor<4, 3>       d2I1, d2I2;
    if (tangent != nullptr)
      for (unsigned int i = 0; i < 3; ++i)
        for (unsigned int A = 0; A < 3; ++A)
          for (unsigned int k = 0; k < 3; ++k)
            for (unsigned int B = 0; B < 3; ++B)
              {
                const double dik = (i == k), dAB = (A == B);
                d2I1[i][A][k][B] = 2.0 * dik * dAB;
                d2I2[i][A][k][B] =
                  2.0 * (2.0 * F[i][A] * F[k][B] + I1 * dik * dAB -
                         dik * C[A][B] - F[i][B] * F[k][A] - b[i][k] * dAB);
              }

    Tensor<2, 3> dI1bar, dI2bar;
    Tensor<4, 3> d2I1bar, d2I2bar;
    const double I1bar = scaled_invariant(-2.0 / 3.0,
                                          J,
                                          dJ,
                                          d2J,
                                          I1,
                                          dI1,
                                          d2I1,
                                          dI1bar,
                                          tangent ? &d2I1bar : nullptr);
    const double I2bar = scaled_invariant(-4.0 / 3.0,
                                          J,
                                          dJ,
                                          d2J,
                                          I2,
                                          dI2,
                                          d2I2,
                                          dI2bar,
                                          tangent ? &d2I2bar : nullptr);

    P = c10 * dI1bar + c01 * dI2bar;
    if (tangent != nullptr)
      *tangent = c10 * d2I1bar + c01 * d2I2bar;
    return c10 * (I1bar - 3.0) + c01 * (I2bar - 3.0);
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
    return "Mooney-Rivlin (isochoric), C10 = " + Utilities::to_string(c10) +
           " Pa, C01 = " + Utilities::to_string(c01) + " Pa";
  }
} // namespace palpate
