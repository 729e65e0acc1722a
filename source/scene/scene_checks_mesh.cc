// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

// The checks of a scene's body and its boundary conditions
// (Scene::validate()): the probe's tip and its radius, the mesh's scale, and
// through their plug-ins the mesh source's entries (its file, the generated
// beam's or blob's size) and the fixed-node region's.

#include <palpate/scene/scene_impl.h>

#include <algorithm>
#include <cmath>

namespace palpate
{
  void
  Scene::check_probe() const
  {
    using namespace Limits;
    const auto &p = parameters;

    // The probe's tip: a radius means something only for a glued tip or a
    // sphere (before Tip existed, Tip radius > 0 meant glued nodes).
    {
      using Tip     = Parameters::ActiveNode::Tip;
      const auto &a = p.boundary_conditions.active_node;
      if (a.tip == Tip::point && a.tip_radius > 0)
        throw error("Boundary conditions/Active node/Tip radius",
                    "Tip radius = " + Utilities::to_string(a.tip_radius, 4) +
                      " m, but Tip = point has no radius",
                    "set Tip = sphere (a rigid sphere in contact with the "
                    "surface: a force that converges with the mesh) or Tip "
                    "= glued nodes (the surface nodes within the radius "
                    "follow the probe), or remove Tip radius.");
      if (a.tip != Tip::point && !(a.tip_radius > 0))
        throw error("Boundary conditions/Active node/Tip radius",
                    "Tip = " +
                      std::string(a.tip == Tip::sphere ? "sphere" :
                                                         "glued nodes") +
                      " needs a positive Tip radius",
                    "set Tip radius in metres, e.g. 0.01 for a probe of "
                    "1 cm radius.");
      if (a.tip != Tip::point && a.tip_radius > max_sphere_radius)
        throw error(
          "Boundary conditions/Active node/Tip radius",
          std::string(a.tip == Tip::sphere ? "a sphere" : "a glued tip") +
            " of " +
            Utilities::to_string_apart(a.tip_radius, max_sphere_radius) +
            " m radius is no probe (at most " +
            Utilities::to_string(max_sphere_radius, 3) + " m)",
          "give the radius in metres (a 1 cm probe: 0.01).");
    }
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
