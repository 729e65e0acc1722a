// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

#include <palpate/base/exceptions.h>
#include <palpate/base/plugins.templates.h>
#include <palpate/base/utilities.h>
#include <palpate/hyperelastic/material.h>
#include <palpate/scene/scene.h>

#include <deal.II/base/parameter_handler.h>

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
    const auto entries = p.models.find(p.model_name);
    return MaterialRegistry::create(p.model_name,
                                    entries == p.models.end() ?
                                      Plugins::Entries() :
                                      entries->second);
  }



  void
  check_modulus(const std::string &entry, const double value)
  {
    if (!(value > 0))
      throw Plugins::EntryError(entry,
                                "must be positive",
                                "set it in Pa: soft tissue is 1e2 - 1e7 Pa "
                                "(the scene's default is a liver's).");
  }



  std::vector<std::pair<std::string, double>>
  Material::moduli() const
  {
    return {{"", youngs_modulus()}};
  }



  /** The Poisson's ratios a compressible model takes (check_poissons_ratio
   * says why). */
  constexpr double max_compressible_nu = 0.4999, min_compressible_nu = -0.9;



  void
  check_poissons_ratio(const std::string &entry, const double nu)
  {
    if (nu >= 0.5)
      throw Plugins::EntryError(
        entry,
        "nu = 0.5 makes the Lame parameter lambda infinite",
        "use nu < 0.5 (e.g. 0.49, the paper's value), or the "
        "incompressible Mooney-Rivlin model.");
    if (nu <= -1)
      throw Plugins::EntryError(
        entry,
        "nu = -1 makes the shear modulus E/(2(1+nu)) infinite",
        "use -1 < nu < 0.5; soft tissue has nu close to 0.5.");
    // Linear and quadratic displacement elements lock as nu nears 0.5:
    // on liver-stvk.prm's 3 cm push (solve) 0.49 renders 3.43 N, 0.4999
    // 26.3 N, and 0.4999999 thousands of newtons with exit 0: the force is
    // then the locking's, not the tissue's.
    if (nu > max_compressible_nu)
      throw Plugins::EntryError(
        entry,
        "nu = " + Utilities::to_string_exact(nu) +
          " is too close to 0.5 for a compressible model: its elements "
          "lock, and the force is the locking's, not the tissue's (on "
          "liver-stvk.prm's 3 cm push nu = 0.49 renders 3.4 N, 0.4999 "
          "already 26 N, 0.4999999 thousands)",
        "use nu <= 0.4999 (0.49 is the paper's value), or Mooney-Rivlin, "
        "whose mixed formulation keeps the volume without locking.");
    // Near -1 the shear modulus E/(2(1+nu)) dwarfs the bulk modulus by
    // many orders: with -0.9999999 every state of an interaction fails
    // and the run would render 0 N with exit 0.
    if (nu < min_compressible_nu)
      throw Plugins::EntryError(
        entry,
        "nu = " + Utilities::to_string_exact(nu) +
          " is below -0.9: the shear modulus E/(2(1+nu)) is then more "
          "than five times E and the states fail to converge",
        "use -0.9 <= nu <= 0.4999; soft tissue has nu close to 0.5.");
  }



  /**
   * Young's modulus and Poisson's ratio of a compressible plug-in, checked
   * (St.Venant-Kirchhoff and Neo-Hookean share these entries).
   */
  std::pair<double, double>
  parse_young_poisson(const dealii::ParameterHandler &prm)
  {
    const double E  = prm.get_double("Young's modulus");
    const double nu = prm.get_double("Poisson's ratio");
    check_poissons_ratio("Poisson's ratio", nu);
    check_modulus("Young's modulus", E);
    return {E, nu};
  }



  void
  declare_incompressibility(dealii::ParameterHandler &prm)
  {
    using dealii::Patterns::Double;
    using dealii::Patterns::Selection;
    prm.declare_entry("Incompressibility",
                      "exact",
                      Selection("exact|penalty"),
                      "exact: J = 1 is imposed by a pressure field that "
                      "acts as a Lagrange multiplier (mixed u-p "
                      "elements, as in the paper); penalty: nearly "
                      "incompressible with the bulk modulus below.");
    prm.declare_entry("Bulk modulus",
                      "1e6",
                      Double(0.),
                      "Bulk modulus kappa of the volumetric energy "
                      "kappa/2 (J - 1)^2 for Incompressibility = "
                      "penalty (Pa).");
    prm.declare_entry("Element",
                      "P1-P1",
                      Selection("P1-P1|Taylor-Hood"),
                      "Displacement-pressure element pair for exact "
                      "incompressibility: P1-P1 (the paper's, one "
                      "pressure per node, not inf-sup stable) or "
                      "Taylor-Hood P2-P1 (stable).");
    prm.declare_entry("Stabilization",
                      "Brezzi-Pitkaranta",
                      Selection("none|Brezzi-Pitkaranta"),
                      "Pressure stabilisation for P1-P1: none, or the "
                      "Brezzi-Pitkaranta term -alpha h^2/mu (grad p, "
                      "grad q) that suppresses checkerboard pressure.");
    prm.declare_entry("Stabilization factor",
                      "0.05",
                      Double(0.),
                      "alpha of the Brezzi-Pitkaranta term "
                      "(dimensionless).");
  }



  Formulation
  parse_incompressibility(const dealii::ParameterHandler &prm)
  {
    Formulation f;
    f.pressure     = prm.get("Incompressibility") == "penalty" ?
                       Formulation::Pressure::penalty :
                       Formulation::Pressure::exact;
    f.bulk_modulus = prm.get_double("Bulk modulus");
    if (f.pressure == Formulation::Pressure::penalty)
      {
        if (!(f.bulk_modulus > 0))
          throw Plugins::EntryError(
            "Bulk modulus",
            "the bulk modulus must be positive",
            "set it in Pa, typically 1000 times C10 + C01 for soft tissue.");
      }
    f.element             = prm.get("Element");
    f.displacement_degree = f.element == "Taylor-Hood" ? 2 : 1;
    f.stabilization =
      f.element == "P1-P1" && prm.get("Stabilization") == "Brezzi-Pitkaranta";
    f.stabilization_factor = prm.get_double("Stabilization factor");
    // alpha is of order 0.01-1 (Brezzi-Pitkaranta); beyond 100 the term
    // swamps the equations it stabilises (1e308 made the rest state a
    // failure point).
    if (f.stabilization && !(f.stabilization_factor <= 100))
      throw Plugins::EntryError(
        "Stabilization factor",
        "at most 100: alpha is of order 0.01-1, and a larger term swamps "
        "the incompressibility it stabilises",
        "use 0.05 (the default).");
    return f;
  }



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



  void
  isochoric_invariants(const Tensor<2, 3>  &F,
                       IsochoricInvariants &inv,
                       const bool           second_derivatives)
  {
    double       J;
    Tensor<2, 3> dJ;
    Tensor<4, 3> d2J;
    volume_derivatives(F, J, dJ, second_derivatives ? &d2J : nullptr);

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
    if (second_derivatives)
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

    inv.I1bar = scaled_invariant(-2.0 / 3.0,
                                 J,
                                 dJ,
                                 d2J,
                                 I1,
                                 dI1,
                                 d2I1,
                                 inv.dI1bar,
                                 second_derivatives ? &inv.d2I1bar : nullptr);
    inv.I2bar = scaled_invariant(-4.0 / 3.0,
                                 J,
                                 dJ,
                                 d2J,
                                 I2,
                                 dI2,
                                 d2I2,
                                 inv.dI2bar,
                                 second_derivatives ? &inv.d2I2bar : nullptr);
  }



  template class Plugins::Registry<Material>;
} // namespace palpate
