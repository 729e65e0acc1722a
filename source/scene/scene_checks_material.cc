// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

// The checks of a scene's material and plug-ins (Scene::validate()): the
// material plug-in's constants and their bounds (the moduli, Poisson's
// ratio, the first Lame constant they make), the degree its element pair
// fixes, the enabled effects' entries and the own entries of the chosen
// device, trajectory and linear solver; and Scene::displacement_degree(),
// the degree of the displacements that the element pair fixes.

#include <palpate/hyperelastic/effect.h>
#include <palpate/hyperelastic/material.h>
#include <palpate/scene/scene_impl.h>

#include <cmath>
#include <memory>

namespace palpate
{
  unsigned int
  Scene::displacement_degree() const
  {
    return Material::create(parameters.material_model)
      ->formulation()
      .degree(parameters.discretization.polynomial_degree);
  }



  namespace
  {
    // Scene::check_material(), a step: each of the plug-in's moduli, and the
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



    // Scene::check_material(), a step: the first Lame constant that the
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
  Scene::check_material() const
  {
    using namespace Limits;
    const auto &p = parameters;

    // Material: the plug-in checks that its constants describe a solid.
    const auto               &m = p.material_model;
    std::unique_ptr<Material> material;
    try
      {
        material = Material::create(m);
      }
    catch (const Plugins::EntryError &e)
      {
        throw error("Material model/" + m.model_name + "/" + e.entry,
                    e.problem,
                    e.fix);
      }

    check_moduli(*this, *material);
    check_first_lame_constant(*this, *material);

    // An element pair (Taylor-Hood, P1-P1) fixes the displacement degree.
    if (const Formulation f = material->formulation();
        f.displacement_degree > 0 && sets("Discretization/Polynomial degree") &&
        p.discretization.polynomial_degree != f.displacement_degree)
      throw error("Discretization/Polynomial degree",
                  m.model_name + "'s element pair " + f.element +
                    " has displacements of degree " +
                    std::to_string(f.displacement_degree),
                  "remove this entry (Material model / " + m.model_name +
                    " / Element chooses the degree), or choose the "
                    "element pair with the degree you want.");
  }



  void
  Scene::check_effects() const
  {
    using namespace Limits;
    const auto &p = parameters;

    // Effects: each plug-in checks its entries.
    try
      {
        Effect::create_enabled(p.effects);
      }
    catch (const Plugins::EntryError &e)
      {
        throw error("Effects/" + e.entry, e.problem, e.fix);
      }
  }



  void
  Scene::check_plugin_entries() const
  {
    const auto &p     = parameters;
    const auto  check = [&](const std::string &kind,
                           const std::string &section,
                           const std::string &name,
                           const std::map<std::string, Plugins::Entries> &own) {
      const auto entries = own.find(name);
      try
        {
          Plugins::check_entries(kind,
                                 name,
                                 entries == own.end() ? Plugins::Entries() :
                                                         entries->second);
        }
      catch (const Plugins::EntryError &e)
        {
          throw error(section + "/" + name + "/" + e.entry, e.problem, e.fix);
        }
    };
    check("mesh source", "Mesh", p.mesh.source, p.mesh.own);
    check("fixed region",
          "Boundary conditions/Fixed nodes",
          p.boundary_conditions.fixed_nodes.selection,
          p.boundary_conditions.fixed_nodes.own);
    check("device", "Haptics", p.haptics.device, p.haptics.own);
    check("trajectory",
          "Haptics/Trajectory",
          p.haptics.trajectory.type,
          p.haptics.trajectory.own);
    if (p.linear_solver.solver != "by size")
      check("linear solver",
            "Linear solver",
            p.linear_solver.solver,
            p.linear_solver.own);
  }

} // namespace palpate
