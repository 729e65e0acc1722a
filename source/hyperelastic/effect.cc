// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

#include <palpate/base/plugins.templates.h>
#include <palpate/hyperelastic/effect.h>
#include <palpate/mesh/node_selection.h>
#include <palpate/scene/scene.h>

namespace palpate
{
  void
  Effect::check(const Mesh &) const
  {}



  std::vector<std::unique_ptr<Effect>>
  Effect::create_enabled(const Parameters::Effects &p)
  {
    std::vector<std::unique_ptr<Effect>> effects;
    for (const auto &plugin : EffectRegistry::plugins())
      if (p.on(plugin.name))
        {
          const auto entries = p.loads.find(plugin.name);
          effects.push_back(EffectRegistry::create(plugin.name,
                                                   entries == p.loads.end() ?
                                                     Plugins::Entries() :
                                                     entries->second));
        }
    return effects;
  }



  namespace
  {
    /**
     * The enabled effects that depend on the mesh (a traction's faces)
     * check it when the scene's nodes are chosen (NodeSelection::create()),
     * before anything is computed.
     */
    void
    check_effects_on_mesh(const Scene &scene, const Mesh &mesh)
    {
      for (const auto &effect :
           Effect::create_enabled(scene.parameters.effects))
        try
          {
            effect->check(mesh);
          }
        catch (const Plugins::EntryError &e)
          {
            throw scene.error("Effects/" + e.entry, e.problem, e.fix);
          }
    }

    [[maybe_unused]] const bool effects_check_the_mesh =
      add_mesh_check(&check_effects_on_mesh);
  } // namespace



  template class Plugins::Registry<Effect>;
} // namespace palpate
