// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

#ifndef palpate_app_serve_h
#define palpate_app_serve_h

#include <palpate/base/utilities.h>

#include <memory>
#include <ostream>
#include <string>

namespace palpate
{
  class Interaction;
  class Scene;

  /**
   * The live view (`palpate serve`): the scene's interaction runs as usual,
   * and a small HTTP server (cpp-httplib) serves a page that draws the
   * organ deforming, the HIP and the force (three.js), and takes the
   * mouse as a 3-DOF device. The page polls the state at about 30 Hz; its
   * mouse positions are targets: a device thread at the scene's loop rate
   * moves the HIP toward the target as a hand moves a device, at most at
   * @p max_speed and with at most 1 m/s^2 of acceleration (smooth: the
   * mouse's jumps become bounded accelerations), and calls
   * Interaction::force() like a real device.
   *
   * Endpoints: GET / (the page), GET /three.module.js, /three.core.js and
   * /OrbitControls.js (three.js and its camera controls from npm, built in:
   * live_view_assets.cc),
   * GET /mesh (the surface: rest positions, triangles, each surface
   * vertex's node number, the fixed nodes, the active node with the
   * outward normal there, the state space's extent, the engine), GET
   * /frame (HIP, target, force, the active node, the surface's
   * displacement, the cloud around the HIP with each point's status: not
   * computed, computed, failed, being computed; the engine's load; the
   * missing-data cause),
   * GET /material (the model and its constants now),
   * POST /hip with "x,y,z" (the target displacement from rest, m),
   * POST /material with "ENTRY=VALUE", POST /active with "node N" or
   * "x,y,z" (m: its nearest surface node), POST /attach, /detach, /reset.
   * Nodes are named everywhere as the mesh file numbers them
   * (Mesh::node_id()), as the scene report and Active node / Node id do.
   */
  class LiveServer
  {
  public:
    /** Set up the interaction and listen on @p host:@p port (0: any free
     * port). Throws InputError if the port cannot be bound. */
    LiveServer(const Scene       &scene,
               const std::string &host,
               const int          port,
               const double       max_speed = 0.05);
    ~LiveServer();

    /** The port it listens on. */
    int
    port() const;

    /** The interaction (for tests: its cache and grid). */
    const Interaction &
    interaction() const;

    /** The force the device thread rendered last (N) and its HIP (m). */
    void
    last(Utilities::Point3 &hip, Utilities::Point3 &force) const;

    /** Stop serving and the device thread; detach. */
    void
    stop();

  private:
    struct Impl;
    std::unique_ptr<Impl> impl;
  };

  /** `palpate serve SCENE.prm [--port P] [--host H]`: serve until
   * interrupted (Ctrl-C). Returns an ExitStatus. */
  int
  run_serve(std::ostream      &out,
            const Scene       &scene,
            const std::string &host,
            const int          port);
} // namespace palpate

#endif
