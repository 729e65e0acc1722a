// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

#include <palpate/base/plugins.templates.h>
#include <palpate/mesh/fixed_region.h>
#include <palpate/mesh/mesh.h>
#include <palpate/scene/scene.h>

namespace palpate
{
  bool
  FixedRegion::is_place() const
  {
    return false;
  }



  bool
  FixedRegion::contains(const Utilities::Point3 &) const
  {
    return false;
  }



  FixedRegion::Selected
  FixedRegion::select_contained(const Mesh &mesh, const bool surface_only) const
  {
    const auto &x       = mesh.vertices();
    const auto &surface = mesh.on_surface();
    Selected    selected;
    for (unsigned int v = 0; v < x.size(); ++v)
      if (contains(x[v]))
        {
          ++selected.in_region;
          if (!surface_only || surface[v])
            selected.fixed.insert(v);
        }
    return selected;
  }



  std::unique_ptr<FixedRegion>
  FixedRegion::create(const Scene &scene)
  {
    const auto &f   = scene.parameters.boundary_conditions.fixed_nodes;
    const auto  own = f.own.find(f.selection);
    try
      {
        return FixedRegionRegistry::create(f.selection,
                                           own == f.own.end() ?
                                             Plugins::Entries() :
                                             own->second,
                                           scene);
      }
    catch (const Plugins::EntryError &e)
      {
        // No such plug-in is an error of Selection itself (a scene built
        // in code; a file's Selection pattern refuses the name before).
        const std::string section = "Boundary conditions/Fixed nodes/";
        throw scene.error(section + (e.entry == f.selection ?
                                       "Selection" :
                                       f.selection + "/" + e.entry),
                          e.problem,
                          e.fix);
      }
  }



  template class Plugins::Registry<FixedRegion, Scene>;
} // namespace palpate
