// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

#ifndef palpate_app_static_solve_h
#define palpate_app_static_solve_h

#include <palpate/base/utilities.h>

#include <iosfwd>

namespace palpate
{
  class Scene;
  class Mesh;
  struct NodeSelection;

  /**
   * Drive the active node from rest to @p target (m) and print what
   * happened: the system's size and solver, the Newton history of every
   * increment, the force on the probe, and where the time went. Writes the
   * state as VTU and the force as CSV when the scene's effects ask for it.
   *
   * A stop signal (SIGINT, SIGTERM, SIGHUP) ends the solve within one
   * Newton iteration: the history, the last equilibrium reached and the
   * files asked for are written all the same.
   *
   * Returns the exit status: ExitStatus::success if the state converged,
   * ExitStatus::solve_failed at a failure point, 128 + the signal's number
   * after a stop.
   */
  int
  run_static_solve(std::ostream            &out,
                   const Scene             &scene,
                   const Mesh              &mesh,
                   const NodeSelection     &nodes,
                   const Utilities::Point3 &target);
} // namespace palpate

#endif
