// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

// check_material_scene(): what a material's constants must satisfy in a
// scene beyond the plug-in's own checks (the moduli within the bounds of a
// solid, the first Lame constant they make, the degree the element pair
// fixes). Every material plug-in declares it as its Declaration's
// check_scene (PALPATE_REGISTER_MATERIAL), so that Scene::validate() runs
// it without the scene including the materials' layer.

#include <palpate/hyperelastic/material.h>
#include <palpate/scene/scene.h>

#include <cmath>
#include <memory>

namespace palpate
{
  namespace
  {
    // check_material_scene(), a step: each of the plug-in's moduli, and the
    // stiffness scale they make, held within the bounds of a solid.
    void
    check_moduli(const Scene &scene, const Material &material)
    {
      using namespace Limits;
      const auto &m = scene.parameters.material_model;
      // Moduli beyond any solid's (diamond: E = 1.2e12 Pa) only overflow the
      // force scale; soft tissue is 1e2 - 1e7 Pa.
      for (const auto &[entry, value] : material.moduli())
        if (std::abs(value) > max_modulus)
          throw scene.error(
            "Material model/" + m.model_name +
              (entry.empty() ? "" : "/" + entry),
            "at most " + Utilities::to_string(max_modulus, 3) +
              " Pa: stiffer than any solid (diamond is 1.2e12 Pa); "
              "such moduli only overflow the solver's force scale",
            "give the modulus in Pa: soft tissue is 1e2 - 1e7 Pa "
            "(liver: E = 15465 Pa).");
      // The lower bound holds for the stiffness scale (Young's modulus of the
      // small-strain limit, 6 (C10 + C01) for Mooney-Rivlin), not for each
      // constant: a tiny C01 beside a liver's C10 is a valid law.
      if (const double E = material.youngs_modulus(); E > 0 && E < min_modulus)
        {
          const auto        moduli = material.moduli();
          const std::string entry =
            moduli.empty() || moduli.front().first.empty() ?
              "" :
              "/" + moduli.front().first;
          throw scene.error(
            "Material model/" + m.model_name + entry,
            "the material's small-strain Young's modulus is " +
              Utilities::to_string(E, 3) + " Pa; at least " +
              Utilities::to_string(min_modulus, 3) +
              " Pa: softer than any tissue (fat is about 1e2 Pa), so "
              "that the forces fall below round-off and Newton "
              "'converges' on any state",
            "give the moduli in Pa: soft tissue is 1e2 - 1e7 Pa "
            "(liver: E = 15465 Pa, or C10 = 2148, C01 = 430).");
        }
    }



    // check_material_scene(), a step: the first Lame constant that the
    // moduli and Poisson's ratio make together, held to the moduli's bound
    // (a step of its own: its message says which of the two to change).
    void
    check_first_lame_constant(const Scene &scene, const Material &material)
    {
      using namespace Limits;
      const auto &m = scene.parameters.material_model;
      // The largest modulus whose lambda fits with @p nu, to 3 digits rounded
      // down: rounded to nearest, the value named can lie above the bound
      // (6.006e10 Pa for nu = 0.499 would read "6.01e+10"), and the modulus
      // the refusal suggests would be refused in turn.
      const auto largest_modulus = [](const double nu) {
        const double E     = max_modulus * (1 + nu) * (1 - 2 * nu) / nu;
        const double digit = std::pow(10., std::floor(std::log10(E)) - 2);
        return std::floor(E / digit) * digit;
      };
      // A Poisson's ratio a hair below 0.5 passes its own check but makes the
      // first Lame constant astronomical: nu = 0.49999999999999994 gives a
      // 1.7e12 N force for a 1 cm push (lambda 4.6e19 Pa). Held against the
      // same bound as the moduli.
      if (const double nu = material.poissons_ratio(); nu < 0.5)
        {
          const double E      = material.youngs_modulus();
          const double lambda = E * nu / ((1 + nu) * (1 - 2 * nu));
          // With nu <= 0.499 it is the modulus that makes lambda too large
          // (E from 6.1e11 Pa with the liver's nu = 0.49): blaming nu would
          // ask for a fix, nu <= 0.499, that it already meets.
          const auto moduli  = material.moduli();
          const bool modulus = nu > 0 && nu <= 0.499 && !moduli.empty() &&
                               !moduli.front().first.empty();
          if (!(std::abs(lambda) <= max_modulus))
            throw scene.error(
              "Material model/" + m.model_name + "/" +
                (modulus ? moduli.front().first : "Poisson's ratio"),
              (modulus ?
                 "E = " + Utilities::to_string_exact(E) + " Pa with nu = " :
                 std::string("nu = ")) +
                Utilities::to_string_exact(nu) +
                " makes the first Lame constant lambda = E nu / ((1 + nu)(1 - "
                "2 nu)) = " +
                Utilities::to_string_apart(lambda, max_modulus) +
                " Pa, more than " + Utilities::to_string(max_modulus, 3) +
                " Pa: stiffer than any solid, it only overflows the solver's "
                "force scale",
              modulus ?
                "give the modulus in Pa, at most " +
                  Utilities::to_string(largest_modulus(nu), 3) +
                  " Pa with this nu: soft tissue is 1e2 - 1e7 Pa (liver: E = "
                  "15465 Pa)." :
                "for a nearly incompressible tissue use nu <= 0.499 (linear "
                "elements lock long before 0.5), or Mooney-Rivlin, whose mixed "
                "formulation keeps the volume without locking.");
        }
    }
  } // namespace



  void
  check_material_scene(const Scene &scene)
  {
    const auto &p = scene.parameters;
    const auto &m = p.material_model;
    // Its own entries were checked before (Plugins::check_entries()).
    const std::unique_ptr<Material> material = Material::create(m);

    check_moduli(scene, *material);
    check_first_lame_constant(scene, *material);

    // An element pair (Taylor-Hood, P1-P1) fixes the displacement degree.
    if (const Formulation f = material->formulation();
        f.displacement_degree > 0 &&
        scene.sets("Discretization/Polynomial degree") &&
        p.discretization.polynomial_degree != f.displacement_degree)
      throw scene.error("Discretization/Polynomial degree",
                        m.model_name + "'s element pair " + f.element +
                          " has displacements of degree " +
                          std::to_string(f.displacement_degree),
                        "remove this entry (Material model / " + m.model_name +
                          " / Element chooses the degree), or choose the "
                          "element pair with the degree you want.");
  }
} // namespace palpate
