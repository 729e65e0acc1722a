// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

// The checks of a scene's body and its boundary conditions
// (Scene::validate()): the mesh's scale, and through their plug-ins the
// probe tip's entries (its radius), the mesh source's (its file, the
// generated beam's or blob's size) and the fixed-node region's.

#include <palpate/scene/scene_impl.h>

namespace palpate
{
  void
  Scene::check_probe() const
  {
    // The probe's tip checks the entries it reads (mesh/probe_tips/): a
    // radius only where the tip has one, and a probe's size.
    const auto &a = parameters.boundary_conditions.active_node;
    Plugins::check_scene("probe tip", a.tip, *this);
  }



  void
  Scene::check_mesh() const
  {
    const auto &p = parameters;

    // The entries the mesh source reads: its file, or its generator's
    // size (mesh/sources/).
    Plugins::check_scene("mesh source", p.mesh.source, *this);
    if (p.mesh.scale_factor <= 0)
      throw error("Mesh/Scale factor",
                  "the scale factor must be positive",
                  "set it to the number of metres per mesh-file unit, e.g. "
                  "0.001 for a mesh in millimetres.");
    // No file unit is below a nanometre or above a thousand kilometres;
    // past that the coordinates in metres under- or overflow, and the
    // messages that follow would blame the mesh instead of the scale.
    if (p.mesh.scale_factor < 1e-9 || p.mesh.scale_factor > 1e6)
      throw error("Mesh/Scale factor",
                  "a scale factor of " +
                    Utilities::to_string(p.mesh.scale_factor, 3) +
                    " m per mesh-file unit is no unit of length a mesh is "
                    "written in (1e-9, a nanometre, to 1e6)",
                  "set it to the number of metres per mesh-file unit, e.g. "
                  "0.001 for a mesh in millimetres, 1 for metres.");
  }



  void
  Scene::check_fixed_nodes() const
  {
    // The fixed region checks the entries that define it
    // (mesh/fixed_regions/): the region must be well-defined.
    const auto &f = parameters.boundary_conditions.fixed_nodes;
    Plugins::check_scene("fixed region", f.selection, *this);
  }

} // namespace palpate
