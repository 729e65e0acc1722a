// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

#ifndef palpate_app_scene_report_h
#define palpate_app_scene_report_h

#include <iosfwd>

namespace palpate
{
  class Scene;
  class Mesh;
  struct NodeSelection;

  /**
   * Print what a scene sets up: the mesh (size, volume, bounding box), the
   * fixed and active nodes, the material, and which effects are on. This is
   * the first thing `palpate scene.prm` prints.
   */
  void
  print_scene_report(std::ostream        &out,
                     const Scene         &scene,
                     const Mesh          &mesh,
                     const NodeSelection &nodes);
} // namespace palpate

#endif
