// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

#ifndef palpate_haptics_trajectory_checks_h
#define palpate_haptics_trajectory_checks_h

namespace palpate
{
  class Scene;

  /**
   * The checks of the shared entries of `Haptics / Trajectory` (Radius,
   * Direction, Speed, Duration), for the trajectory plug-ins that read them:
   * each plug-in's check_scene() calls those of the entries it reads, so a
   * scene is refused for an entry only by the trajectories that use it. Each
   * throws the scene's InputError (Scene::error()) naming the entry.
   */
  namespace TrajectoryChecks
  {
    /** Radius of at least 0.1 mm, and a motion that reaches @p across
     * radii from rest staying within State space / Extent. */
    void
    check_radius(const Scene &scene, const double across);

    /** Direction is not the zero vector. */
    void
    check_direction(const Scene &scene);

    /** Duration from 0.01 s to an hour, Speed at most a hand's. */
    void
    check_timing(const Scene &scene);

    /** Speed x Duration moves the probe at least 0.1 mm. */
    void
    check_motion_length(const Scene &scene);
  } // namespace TrajectoryChecks
} // namespace palpate

#endif
