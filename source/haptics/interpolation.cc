// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

#include <palpate/base/plugins.templates.h>
#include <palpate/haptics/interpolation.h>
#include <palpate/mesh/mesh.h>
#include <palpate/scene/scene.h>
#include <palpate/state_space/state_cache.h>
#include <palpate/state_space/state_grid.h>

namespace palpate
{
  Interpolation::Interpolation(const StateGrid &grid, const StateCache &cache)
    : grid(grid)
    , cache(cache)
  {}



  bool
  Interpolation::force_while_missing(const Utilities::Point3 &,
                                     Utilities::Point3 &,
                                     std::array<double, 9> &) noexcept
  {
    return false;
  }



  void
  Interpolation::reset() noexcept
  {}



  std::unique_ptr<Interpolation>
  Interpolation::create(const Scene      &scene,
                        const Mesh       &mesh,
                        const StateGrid  &grid,
                        const StateCache &cache)
  {
    const auto &s   = scene.parameters.state_space;
    const auto  own = s.own.find(s.interpolation);
    try
      {
        return InterpolationRegistry::create(s.interpolation,
                                             own == s.own.end() ?
                                               Plugins::Entries() :
                                               own->second,
                                             scene,
                                             mesh,
                                             grid,
                                             cache);
      }
    catch (const Plugins::EntryError &e)
      {
        // No such plug-in is an error of Interpolation itself (a scene
        // built in code; a file's Selection pattern refuses the name
        // before).
        throw scene.error("State space/" + (e.entry == s.interpolation ?
                                              "Interpolation" :
                                              s.interpolation + "/" + e.entry),
                          e.problem,
                          e.fix);
      }
  }



  template class Plugins::
    Registry<Interpolation, Scene, Mesh, StateGrid, StateCache>;
} // namespace palpate
