// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

// The checks of a scene's material and plug-ins (Scene::validate()): the
// material plug-in's constants (its own checks, then what they must satisfy
// in the scene: check_material_scene()), the enabled effects' entries and
// the own entries of the chosen probe tip, interpolation, device,
// trajectory and linear solver; and Scene::displacement_degree(), the degree of
// the displacements that the element pair fixes. Each plug-in is reached
// through its Declaration (Plugins::declarations()), not its interface.

#include <palpate/scene/scene_impl.h>

namespace palpate
{
  unsigned int
  Scene::displacement_degree() const
  {
    // The material's element pair fixes it, or the scene's Polynomial
    // degree (the material plug-in says which, from its entries).
    const auto &m        = parameters.material_model;
    const auto *material = Plugins::find_declaration("material", m.model_name);
    const auto  entries  = m.models.find(m.model_name);
    const unsigned int fixed =
      material == nullptr || material->element_degree == nullptr ?
        0 :
        material->element_degree(*Plugins::make_parameter_handler(
          material->declare_parameters,
          entries == m.models.end() ? Plugins::Entries() : entries->second));
    return fixed > 0 ? fixed : parameters.discretization.polynomial_degree;
  }



  void
  Scene::check_material() const
  {
    // The plug-in checks its constants (that they describe a solid), then
    // what they must satisfy in this scene (check_material_scene()).
    const auto &m       = parameters.material_model;
    const auto  entries = m.models.find(m.model_name);
    try
      {
        Plugins::check_entries("material",
                               m.model_name,
                               entries == m.models.end() ? Plugins::Entries() :
                                                           entries->second);
      }
    catch (const Plugins::EntryError &e)
      {
        throw error("Material model/" + m.model_name + "/" + e.entry,
                    e.problem,
                    e.fix);
      }
    Plugins::check_scene("material", m.model_name, *this);
  }



  void
  Scene::check_effects() const
  {
    // Effects: each enabled plug-in checks its entries.
    const auto &e = parameters.effects;
    for (const auto &effect : Plugins::declarations("effect"))
      if (e.on(effect.name))
        try
          {
            const auto entries = e.loads.find(effect.name);
            Plugins::check_entries("effect",
                                   effect.name,
                                   entries == e.loads.end() ?
                                     Plugins::Entries() :
                                     entries->second);
          }
        catch (const Plugins::EntryError &error_in)
          {
            throw error("Effects/" + error_in.entry,
                        error_in.problem,
                        error_in.fix);
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
    check("probe tip",
          "Boundary conditions/Active node",
          p.boundary_conditions.active_node.tip,
          p.boundary_conditions.active_node.own);
    check("interpolation",
          "State space",
          p.state_space.interpolation,
          p.state_space.own);
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
