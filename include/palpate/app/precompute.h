// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

#ifndef palpate_app_precompute_h
#define palpate_app_precompute_h

#include <ostream>
#include <string>

namespace palpate
{
  class Scene;

  /**
   * `palpate precompute SCENE.prm [--radius R]`: compute every state within
   * @p radius (m; the scene's cloud radius if 0) of the active node's rest
   * position, off-line, into the scene's State space / Store, with a
   * progress bar and the time left. The engine computes as in an
   * interaction (threads, or the MPI servers under mpirun, rank 0 writing);
   * each finished state is appended within a quarter second, so an
   * interrupted run (Ctrl-C, kill) started again resumes where it stopped.
   *
   * It holds the store's StoreLock for the whole run: another process that
   * would write the store is refused. SIGINT, SIGTERM and SIGHUP stop it
   * cleanly (exit status 128 + the signal's number); a write the file
   * system refuses (the disk full) stops the appending (exit status 6).
   * Either way it ends by reading the store back and saying exactly how
   * many states and failure points it keeps. Returns an ExitStatus.
   */
  int
  run_precompute(std::ostream &out, Scene scene, const double radius);
} // namespace palpate

#endif
