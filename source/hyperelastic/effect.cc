// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

#include <palpate/base/plugins.templates.h>
#include <palpate/hyperelastic/effect.h>

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



  template class Plugins::Registry<Effect>;
} // namespace palpate
