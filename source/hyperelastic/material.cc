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



  template class Plugins::Registry<Material>;


  PALPATE_REGISTER_MATERIAL(
    StVenantKirchhoff,
    "St.Venant-Kirchhoff",
    "the paper's first model, linear in the Green strain; softens and may "
    "invert under strong compression")
  PALPATE_REGISTER_MATERIAL(
    NeoHookean,
    "Neo-Hookean",
    "compressible neo-Hookean, never softens under compression")
  PALPATE_REGISTER_MATERIAL(
    MooneyRivlin,
    "Mooney-Rivlin",
    "the paper's second model, incompressible, with a pressure multiplier "
    "field")
} // namespace palpate
