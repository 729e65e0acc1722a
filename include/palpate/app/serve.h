// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

#ifndef palpate_app_serve_h
#define palpate_app_serve_h

#include <palpate/app/live_server.h>

#include <ostream>
#include <string>

namespace palpate
{
  class Scene;

  /** `palpate serve SCENE.prm [--port P] [--host H]`: serve until
   * interrupted (Ctrl-C), printing each change made through the view on
   * @p out, then the run summary with the live view's part
   * (LiveServer::print_summary()). Returns an ExitStatus. */
  int
  run_serve(std::ostream      &out,
            const Scene       &scene,
            const std::string &host,
            const int          port);
} // namespace palpate

#endif
