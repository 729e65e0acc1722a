// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

#ifndef palpate_app_interaction_run_h
#define palpate_app_interaction_run_h

#include <palpate/haptics/run_summary.h>

#include <iosfwd>
#include <memory>
#include <string>

namespace palpate
{
  class Scene;

  /**
   * Run a scene's interaction: attach, compute the initial cloud, move the
   * simulated device along the scene's trajectory with the built-in haptic
   * loop, report missing-data events as they happen, detach, and print the
   * run summary (and write it as CSV/JSON, the force log and the shape
   * frames when the scene asks for them). Returns the summary.
   */
  RunSummary
  run_interaction(std::ostream &out, const Scene &scene);

  /**
   * That the scene's Output / Directory exists or can be created, and
   * takes files: an InputError naming the entry if not. Before a run that
   * writes files, so that no work is lost to it at the end.
   */
  void
  check_output_directory(const Scene &scene);

  /**
   * One writer per output: holds DIRECTORY/STEM.lock (an flock, released
   * however the process ends) for as long as the returned handle lives. A
   * second run of the scene writing the same files into the same Output /
   * Directory is refused with an InputError naming the first (two live
   * views overwrote each other's force log and summary).
   */
  std::shared_ptr<void>
  lock_outputs(const Scene &scene, const std::string &stem);
} // namespace palpate

#endif
