// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

#ifndef palpate_hyperelastic_material_h
#define palpate_hyperelastic_material_h

#include <palpate/base/plugins.h>
#include <palpate/scene/parameters.h>

#include <deal.II/base/tensor.h>

#include <memory>
#include <string>
#include <utility>
#include <vector>

namespace palpate
{
  using dealii::Tensor;

  /**
   * How the FE module discretises a material: a compressible law needs only
   * the displacement; an isochoric one (Mooney-Rivlin) needs a pressure
   * field that imposes J = 1 exactly or penalises J - 1. Materials say what
   * they need; the FE module reads nothing else of theirs.
   */
  struct Formulation
  {
    /** The pressure field: none, exact (a Lagrange multiplier of J = 1)
     * or penalty (kappa/2 (J - 1)^2). */
    enum class Pressure
    {
      none,
      exact,
      penalty
    } pressure = Pressure::none;
    /** kappa for Pressure::penalty (Pa). */
    double bulk_modulus = 0;
    /** The displacement degree the element pair fixes (1 for P1-P1, 2 for
     * Taylor-Hood), or 0: Discretization / Polynomial degree decides. */
    unsigned int displacement_degree = 0;
    /** The displacement field's degree: the element pair's, else the
     * scene's Discretization / Polynomial degree (@p polynomial_degree).
     * The one statement of this rule: the FE system, the sphere's checks
     * and the study's element knob all ask it. */
    unsigned int
    degree(const unsigned int polynomial_degree) const
    {
      return displacement_degree > 0 ? displacement_degree : polynomial_degree;
    }
    /** The element pair's name for reports ("P1-P1", "Taylor-Hood"). */
    std::string element;
    /** The Brezzi-Pitkaranta pressure stabilisation of P1-P1 and its
     * dimensionless factor alpha. */
    bool   stabilization        = false;
    double stabilization_factor = 0;
  };

  /**
   * A hyperelastic material in the total Lagrangian setting: a strain
   * energy density W(F) per unit reference volume (J/m^3 = Pa), its first
   * Piola-Kirchhoff stress P = dW/dF (Pa) and the tangent A = dP/dF (Pa),
   * A[i][J][k][L] = d P[i][J] / d F[k][L].
   *
   * The FE module calls evaluate() at every quadrature point; implementations
   * must be thread-safe (const, no state).
   */
  class Material
  {
  public:
    virtual ~Material() = default;

    /**
     * Energy, stress and (if @p tangent is not null) tangent at the
     * deformation gradient @p F. Returns W(F).
     */
    virtual double
    evaluate(const Tensor<2, 3> &F,
             Tensor<2, 3>       &P,
             Tensor<4, 3>       *tangent) const = 0;

    /**
     * Whether the energy is defined at F: false if det F <= 0 and the law
     * needs J > 0 (neo-Hookean). St.Venant-Kirchhoff is defined for every
     * F, but palpate still treats det F <= 0 as an inverted element.
     */
    virtual bool
    admissible(const Tensor<2, 3> &F) const;

    /**
     * Whether the energy is only the isochoric (volume-preserving) part,
     * so that the FE module must add a pressure field that imposes or
     * penalises J - 1 (Mooney-Rivlin).
     */
    virtual bool
    isochoric() const
    {
      return false;
    }

    /** The shear modulus mu of the small-strain limit (Pa). */
    virtual double
    shear_modulus() const = 0;

    /** Young's modulus of the small-strain limit (Pa): the stiffness scale. */
    virtual double
    youngs_modulus() const = 0;

    /** Poisson's ratio of the small-strain limit: 0.5 for an
     * incompressible law. The scene report warns about volumetric locking
     * of compressible laws near 0.5 on linear elements. */
    virtual double
    poissons_ratio() const = 0;

    /** The moduli (entry name, Pa) that Scene::validate() holds against
     * the largest any solid has: beyond it they only overflow the force
     * scale. By default Young's modulus, unnamed. */
    virtual std::vector<std::pair<std::string, double>>
    moduli() const;

    /** What the FE module must add to the displacement field. */
    virtual Formulation
    formulation() const
    {
      return {};
    }

    /** The constants for the scene report, e.g. "E = 15465 Pa, nu =
     * 0.49" (after the model's name). */
    virtual std::string
    description() const = 0;

    /**
     * The material a scene asks for, built by the plug-in registered under
     * Material model / Model name from its entries. For Mooney-Rivlin this
     * is the isochoric energy only; the FE module adds the pressure field.
     * Throws Plugins::EntryError for constants that describe no solid.
     */
    static std::unique_ptr<Material>
    create(const Parameters::MaterialModel &parameters);
  };

  /**
   * Material plug-ins: each registers itself at the end of its `.cc`,
   *
   *     PALPATE_REGISTER_MATERIAL(Yeoh, "Yeoh", "one line for the reference")
   *
   * with `static void declare_parameters(ParameterHandler &)` (its entries,
   * in subsection Material model / NAME) and `static
   * std::unique_ptr<Material> create(const ParameterHandler &)`.
   */
  using MaterialRegistry = Plugins::Registry<Material>;
  extern template class Plugins::Registry<Material>;

  /** A material plug-in's entries checked by building it (its
   * Declaration's check_parameters: the scene checks them so, without
   * including this header). */
  template <typename Class>
  void
  check_material_entries(const dealii::ParameterHandler &own)
  {
    Class::create(own);
  }

  /** The displacement degree a material plug-in's element pair fixes
   * (its Declaration's element_degree). */
  template <typename Class>
  unsigned int
  material_element_degree(const dealii::ParameterHandler &own)
  {
    return Class::create(own)->formulation().displacement_degree;
  }

  /**
   * What every material's constants must satisfy beyond their own checks,
   * in the scene (its Declaration's check_scene, run by Scene::validate()):
   * each modulus and the stiffness scale they make within the bounds of a
   * solid, the first Lame constant they make with Poisson's ratio too, and
   * Discretization / Polynomial degree agreeing with the element pair's.
   */
  void
  check_material_scene(const Scene &scene);

  /* Registered in MaterialRegistry (the solver builds the material from
   * it) and declared as a "material" (Plugins::declarations(): the scene
   * declares, checks and sizes the material's entries without including
   * this header). */
#define PALPATE_REGISTER_MATERIAL(classname, name, description)           \
  namespace                                                               \
  {                                                                       \
    [[maybe_unused]] const bool palpate_material_registered_##classname = \
      ::palpate::MaterialRegistry::add({name,                             \
                                        description,                      \
                                        &classname::declare_parameters,   \
                                        &classname::create}) &&           \
      ::palpate::Plugins::add_declaration(                                \
        "material",                                                       \
        {name,                                                            \
         description,                                                     \
         &classname::declare_parameters,                                  \
         &::palpate::check_material_entries<classname>,                   \
         &::palpate::check_material_scene,                                \
         &::palpate::material_element_degree<classname>});                \
  }

  /** The Lame parameters lambda and mu of Young's modulus @p E and
   * Poisson's ratio @p nu (the compressible models'). */
  double
  lame_lambda(const double E, const double nu);
  double
  lame_mu(const double E, const double nu);

  /**
   * Helpers for material plug-ins. They throw Plugins::EntryError naming
   * @p entry when a modulus is not positive.
   */
  void
  check_modulus(const std::string &entry, const double value);

  /** The same for Poisson's ratio: -1 < nu < 0.5. */
  void
  check_poissons_ratio(const std::string &entry, const double nu);

  /** The entries "Young's modulus" and "Poisson's ratio" of a compressible
   * plug-in, checked with the two functions above. */
  std::pair<double, double>
  parse_young_poisson(const dealii::ParameterHandler &prm);

  /**
   * Entries and their parsing shared by the isochoric (incompressible)
   * plug-ins: Incompressibility (exact|penalty), Bulk modulus, Element
   * (P1-P1|Taylor-Hood), Stabilization and its factor.
   */
  void
  declare_incompressibility(dealii::ParameterHandler &prm);

  /** The formulation of those entries (throws EntryError). */
  Formulation
  parse_incompressibility(const dealii::ParameterHandler &prm);

  /**
   * The isochoric invariants I1bar = J^(-2/3) tr C, I2bar = J^(-4/3) I2 of
   * F, with their first and (if asked) second derivatives with respect to
   * F. An isochoric material W(I1bar, I2bar) needs nothing else.
   */
  struct IsochoricInvariants
  {
    double       I1bar, I2bar;
    Tensor<2, 3> dI1bar, dI2bar;
    Tensor<4, 3> d2I1bar, d2I2bar;
  };

  void
  isochoric_invariants(const Tensor<2, 3>  &F,
                       IsochoricInvariants &invariants,
                       const bool           second_derivatives);

  /**
   * St.Venant-Kirchhoff: W = lambda/2 (tr E)^2 + mu tr(E^2) with the Green
   * strain E = (F^T F - I)/2; S = lambda tr(E) I + 2 mu E, P = F S. The
   * simplest large-deformation extension of linear elasticity; it softens
   * under strong compression and admits inverted states.
   */
  class StVenantKirchhoff : public Material
  {
  public:
    /** @p youngs_modulus in Pa, @p poissons_ratio dimensionless. */
    StVenantKirchhoff(const double youngs_modulus, const double poissons_ratio);

    double
    evaluate(const Tensor<2, 3> &F,
             Tensor<2, 3>       &P,
             Tensor<4, 3>       *tangent) const override;

    /** The plug-in's entries and factory (the registry's). */
    static void
    declare_parameters(dealii::ParameterHandler &prm);
    static std::unique_ptr<Material>
    create(const dealii::ParameterHandler &prm);

    double
    poissons_ratio() const override;

    std::vector<std::pair<std::string, double>>
    moduli() const override;

    double
    shear_modulus() const override;

    double
    youngs_modulus() const override;

    std::string
    description() const override;

    /** Lame parameters (Pa). */
    const double E, nu, lambda, mu;
  };

  /**
   * Compressible neo-Hookean: W = mu/2 (tr C - 3) - mu ln J + lambda/2
   * (ln J)^2; P = mu (F - F^-T) + lambda ln J F^-T. Reduces to linear
   * elasticity for small strains; W -> infinity as J -> 0, so it never
   * softens under compression.
   */
  class NeoHookean : public Material
  {
  public:
    /** @p youngs_modulus in Pa, @p poissons_ratio dimensionless. */
    NeoHookean(const double youngs_modulus, const double poissons_ratio);

    double
    evaluate(const Tensor<2, 3> &F,
             Tensor<2, 3>       &P,
             Tensor<4, 3>       *tangent) const override;

    bool
    admissible(const Tensor<2, 3> &F) const override;

    /** The plug-in's entries and factory (the registry's). */
    static void
    declare_parameters(dealii::ParameterHandler &prm);
    static std::unique_ptr<Material>
    create(const dealii::ParameterHandler &prm);

    double
    poissons_ratio() const override;

    std::vector<std::pair<std::string, double>>
    moduli() const override;

    double
    shear_modulus() const override;

    double
    youngs_modulus() const override;

    std::string
    description() const override;

    /** Lame parameters (Pa). */
    const double E, nu, lambda, mu;
  };

  /**
   * The isochoric Mooney-Rivlin energy
   *   W_iso = C10 (I1bar - 3) + C01 (I2bar - 3),
   * with the invariants of the isochoric deformation Fbar = J^(-1/3) F:
   * I1bar = J^(-2/3) I1, I2bar = J^(-4/3) I2, I2 = ((tr C)^2 - tr C^2)/2. It
   * carries no volumetric stiffness: the FE module imposes J = 1 with a
   * pressure field p (adding -p (J - 1) to the energy), or penalises it. C01 =
   * 0 is the incompressible neo-Hookean solid. The small-strain shear modulus
   * is mu = 2 (C10 + C01).
   */
  class MooneyRivlin : public Material
  {
  public:
    /** @p c10, @p c01 in Pa; @p formulation: exact incompressibility on
     * P1-P1 by default. */
    MooneyRivlin(const double       c10,
                 const double       c01,
                 const Formulation &formulation = Formulation());

    Formulation
    formulation() const override;

    double
    evaluate(const Tensor<2, 3> &F,
             Tensor<2, 3>       &P,
             Tensor<4, 3>       *tangent) const override;

    bool
    admissible(const Tensor<2, 3> &F) const override;

    bool
    isochoric() const override
    {
      return true;
    }

    /** The plug-in's entries and factory (the registry's). */
    static void
    declare_parameters(dealii::ParameterHandler &prm);
    static std::unique_ptr<Material>
    create(const dealii::ParameterHandler &prm);

    double
    poissons_ratio() const override;

    std::vector<std::pair<std::string, double>>
    moduli() const override;

    double
    shear_modulus() const override;

    /** 3 mu, the Young's modulus of an incompressible solid (Pa). */
    double
    youngs_modulus() const override;

    std::string
    description() const override;

    /** The coefficients (Pa). */
    const double c10, c01;

  private:
    Formulation mixed;
  };

  /**
   * J = det F and its first and second derivatives with respect to F:
   * dJ/dF = J F^-T, d2J/dF2_iJkL = J (Finv_Ji Finv_Lk - Finv_Jk Finv_Li).
   * The pressure terms of the mixed formulation use them.
   */
  void
  volume_derivatives(const Tensor<2, 3> &F,
                     double             &J,
                     Tensor<2, 3>       &dJ,
                     Tensor<4, 3>       *d2J);
} // namespace palpate

#endif
