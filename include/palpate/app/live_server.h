// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

#ifndef palpate_app_live_server_h
#define palpate_app_live_server_h

#include <palpate/base/utilities.h>

#include <cstddef>
#include <cstdint>
#include <map>
#include <memory>
#include <ostream>
#include <string>
#include <vector>

namespace palpate
{
  class Interaction;
  struct RunSummary;
  class Scene;

  /**
   * The live view (`palpate serve`): the scene's interaction runs as usual,
   * and a small HTTP server (cpp-httplib) serves a page that draws the
   * organ deforming, the HIP and the force (three.js), and takes the
   * mouse as a 3-DOF device. The page polls the state at about 30 Hz; its
   * mouse positions are targets: a TargetFollower device, run by the
   * common HapticLoop at the scene's loop rate, moves the HIP toward the
   * target as a hand moves a device, at most at @p max_speed and with at
   * most 1 m/s^2 of acceleration (smooth: the mouse's jumps become bounded
   * accelerations), and the loop calls Interaction::force() as for every
   * device.
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
   *
   * Only its user gets in (doc/serve.md). Every request must name the
   * server by an address it listens on in its Host header (127.0.0.1:PORT,
   * localhost:PORT, [::1]:PORT, the --host given, and listening on every
   * interface this machine's name and addresses): a page of another site
   * whose name was made to point here (DNS rebinding) is refused. Every
   * POST must carry the run's secret token(), which only the page served
   * in this run holds, in the header token_header, with the content type
   * command_type, and no Origin but the server's own: a page of another
   * site, or a form on it, can neither send the token (it cannot read the
   * page) nor these headers (they need a CORS preflight, which is always
   * refused). Refusals are 403 with the reason as plain text; the first of
   * each kind is printed. Connections are read with timeouts, each on its
   * own thread (up to 256 at once), so that slow or idle clients cannot
   * keep the page waiting.
   *
   * Every change made through the view (a material constant, the active
   * node, attach, detach, back to rest) is printed on the log as it is
   * made, kept (changes()), and listed by print_summary() with the
   * constants in force at the end.
   */
  class LiveServer
  {
  public:
    /** The header every POST carries the run's token() in. */
    static constexpr const char *token_header = "X-Palpate-Token";

    /** The content type of every POST (its body is the plain-text command
     * described above). None of the types a form or a script of another
     * site may send without a CORS preflight (text/plain,
     * application/x-www-form-urlencoded, multipart/form-data). */
    static constexpr const char *command_type = "application/x-palpate";

    /** One change made through the view. */
    struct Change
    {
      /** When, in seconds since the server started. */
      double time;
      /** What, e.g. "Young's modulus 15465 -> 20000 Pa". */
      std::string what;
    };

    /** Set up the interaction and listen on @p host:@p port (0: any free
     * port). Each change made through the view is printed on @p log as it
     * is made ("live view: ...", one line; none if null), and so is the
     * first refused request of each kind. Throws InputError if the port
     * cannot be bound. */
    LiveServer(const Scene       &scene,
               const std::string &host,
               const int          port,
               const double       max_speed = 0.05,
               std::ostream      *log       = nullptr);
    ~LiveServer();

    /** The port it listens on. */
    int
    port() const;

    /** The run's secret: 32 hexadecimal digits (128 random bits from
     * /dev/urandom), made anew by each server and written into the page
     * it serves. Every POST must carry it in token_header. */
    const std::string &
    token() const;

    /** The address to open in a browser, "http://127.0.0.1:8080/"
     * (listening on every interface, with this machine's name). */
    const std::string &
    address() const;

    /** The host names (lower case, IPv6 addresses in brackets) a request's
     * Host header may give, with the port(). */
    std::vector<std::string>
    accepted_hosts() const;

    /** The changes made through the view so far, in order. */
    std::vector<Change>
    changes() const;

    /** The requests refused so far (403), by kind: "Host" (not an address
     * it listens on), "Origin" (another site, or null), "preflight" (a
     * CORS preflight), "content type", "token" (missing or wrong). */
    std::map<std::string, unsigned int>
    refused() const;

    /** The live view's part of the run summary: the material and the
     * active node in force now (and the scene's, if they differ), the
     * changes made through the view, and the requests refused. */
    void
    print_summary(std::ostream &out) const;

    /** The interaction (for tests: its cache and grid). */
    const Interaction &
    interaction() const;

    /** The force the haptic loop rendered last (N) and its HIP (m). */
    void
    last(Utilities::Point3 &hip, Utilities::Point3 &force) const;

    /** Add the haptic loop's statistics (the browser's mouse runs in the
     * common HapticLoop) and the device to @p summary; after stop(). */
    void
    add_to(RunSummary &summary) const;

    /** Stop serving and the haptic loop; detach. */
    void
    stop();

    /**
     * With Effects / Force log: write the rows the haptic loop logged
     * since the last call to @p csv (t in s since the view started, the
     * HIP in m, the force in N, as an interaction's force log), and return
     * how many. The loop puts its rows in a ring of 4 s of ticks
     * and never waits: call this from one thread, a few times a second;
     * rows that found the ring full are counted (force_log_dropped()).
     */
    std::size_t
    write_force_log(std::ostream &csv);

    /** Force-log rows lost because write_force_log() fell behind. */
    std::uint64_t
    force_log_dropped() const;

  private:
    struct Impl;
    std::unique_ptr<Impl> impl;
  };
} // namespace palpate

#endif
