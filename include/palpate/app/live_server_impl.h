// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

#ifndef palpate_app_live_server_impl_h
#define palpate_app_live_server_impl_h

#include <palpate/app/connection_pool.h>
#include <palpate/app/live_server.h>
#include <palpate/haptics/haptic_loop.h>
#include <palpate/haptics/interaction.h>
#include <palpate/haptics/target_follower.h>
#include <palpate/scene/parameters.h>

#include <array>
#include <atomic>
#include <chrono>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <ostream>
#include <set>
#include <string>
#include <string_view>
#include <thread>
#include <vector>

namespace httplib
{
  struct Request;
}

namespace palpate
{
  /** The page (serve_page.cc): three.js draws the surface, the HIP and the
   * force; a drag on the organ moves the HIP in the view plane (with Alt,
   * in depth), other drags and the wheel turn, pan and zoom the view. Its
   * "{{palpate-token}}" is replaced by the run's token. */
  extern const char *const live_view_page;

  /** three.js, compiled in (live_view_assets.cc); empty if npm was
   * missing when cmake ran. */
  namespace live_view_assets
  {
    /** three.core.js, which three.module.js imports. */
    std::string_view
    three_core();
    /** three.module.js, which the page imports. */
    std::string_view
    three_module();
    /** OrbitControls.js, the page's camera controls. */
    std::string_view
    orbit_controls();
  } // namespace live_view_assets



  /**
   * What the live view holds while it runs: the interaction and the
   * browser's device, the surface the page draws, who may ask (the token,
   * the names it answers to), what happened (changes, refusals), and the
   * HTTP server. Its state and the changes are in live_server_impl.cc; the
   * endpoints the page calls, set up by the constructor's steps, in
   * live_endpoints.cc. Internal to the live view: LiveServer is its
   * interface.
   */
  struct LiveServer::Impl
  {
    /** The clock of the load samples and the change times. */
    using Clock = std::chrono::steady_clock;

    /** The interaction of @p scene, the surface the page draws, and the
     * page with a new token in it; the device follows the page's targets
     * at most at @p max_speed (m/s); changes and refusals are printed on
     * @p log (if not null). The server is not set up yet: the steps
     * below do it. */
    Impl(const Scene &scene, const double max_speed, std::ostream *log);

    /** The active node as /mesh and /frame give it (active_json), made
     * again when it changes: its number in the mesh file, the outward
     * normal of the surface there (the page's first camera looks along
     * it, at the probe's side of the organ) and, with a sphere probe, the
     * sphere's centre at HIP = 0 and its radius (m), so that the page
     * draws the indenter where it touches, not a marker at the node.
     * Called with mutex held, or before the server runs. */
    void
    describe_active();

    /** /frame: the HIP, target and force, the surface's displacement, the
     * cloud around the HIP with each point's status, and the engine's
     * load, as JSON. */
    std::string
    frame();

    /** The material model and its constants now, as the scene report
     * gives them: "St.Venant-Kirchhoff, E = 15465 Pa, nu = 0.49". */
    std::string
    material_description() const;

    /** The active node now: "node 87 at (100, 0, 10) mm". */
    std::string
    active_description() const;

    /** A change made through the view: printed on the log as it is made
     * and kept for the summary. */
    void
    record(const std::string &what);

    /** Count a refused request; print the first of each kind. */
    void
    refuse(const httplib::Request &request,
           const std::string      &kind,
           const std::string      &reason);

    /** The material model and its constants as they are now (the m key's
     * prompt). */
    std::string
    material_json();

    /** Change the scene's parameters on the fly: detach, change (the
     * cache is invalidated and the states are computed again), attach;
     * with @p rest, the device goes back to rest. If it was made, the
     * line @p describe returns is recorded (printed and kept for the
     * summary) in the order the changes were made. Returns "" or the
     * reason the change was refused. */
    std::string
    change(const std::function<void(Parameters::AllParameters &)> &edit,
           const bool                                              rest,
           const std::function<std::string()>                     &describe);

    /** The steps of LiveServer's constructor (live_endpoints.cc): who may
     * ask, checked before any handler, and the answers' own headers. */
    void
    guard_requests();
    /** The page, three.js, the model (/mesh, /material) and its frames. */
    void
    add_reads();
    /** The probe's target, attach, detach and back to rest. */
    void
    add_device_requests();
    /** A material constant of the scene's model, "ENTRY=VALUE". */
    void
    add_material_change();
    /** Another active node: "node N" or the point "x,y,z". */
    void
    add_active_node_change();
    /** What a request may be, and how long a connection may take. */
    void
    limit_connections();
    /** Bind @p host : @p port (a port in use is an error that says so),
     * listen with a long queue, and the names and address requests may
     * use. */
    void
    listen(const std::string &host, const int port);

    /** The scene's interaction, which the view changes on the fly. */
    Interaction interaction;
    /** The device's top speed (m/s) and the haptic loop's rate (Hz). */
    const double max_speed, rate;
    /** The browser's mouse: the HIP follows the target the page sends, in
     * the common haptic loop (started by LiveServer's constructor). */
    TargetFollower device;
    /** The haptic loop that runs the device. */
    std::unique_ptr<HapticLoop> loop;
    /** The mesh vertices on the surface, in the page's order. */
    std::vector<unsigned int> surface;
    /** The surface triangles (page's vertex numbers), and each surface
     * vertex's three displacement DoFs. */
    std::vector<std::array<unsigned int, 3>> triangles, dofs;
    /** /mesh without the active node, and the active node (mutex). */
    std::string mesh_json, active_json;
    /** The surface's displacement last shown (m), 3 per vertex. */
    std::vector<double> displacement;
    /** Effects / Force log: the loop's ring, emptied by
     * write_force_log(). */
    bool force_log = false;
    /** The engine's counters at the last load sample (frame()). */
    struct
    {
      Clock::time_point time;
      unsigned int      done;
      double            busy_time;
    } load_sample{Clock::now(), 0, 0.0};
    /** The engine's states per second and the workers' busy fraction
     * since the load sample before the last. */
    double states_per_second = 0, utilisation = 0;
    /** Until stop(). */
    std::atomic<bool> running{true};
    /** Locked in this order: control_mutex (one change, attach or detach
     * at a time), (the loop held), mutex (the parameters and nodes a
     * frame reads). */
    std::mutex control_mutex, mutex;
    /** Mesh vertex -> its index among the surface's vertices. */
    std::map<unsigned int, unsigned int> surface_index;

    /** Who gets in: the run's secret. */
    const std::string token;
    /** The page, with the token in it. */
    std::string page;
    /** The port it listens on, and the listening socket. */
    int bound = 0, listening = -1;
    /** The host names a request's Host header may give with the port
     * (lower case, IPv6 in brackets). */
    std::set<std::string> hosts;
    /** The address to open in a browser. */
    std::string address;

    /** What happened, for the user: the log (or null). */
    std::ostream *const log;
    /** When the server started. */
    const Clock::time_point started = Clock::now();
    /** Guards changes and refusals. */
    mutable std::mutex record_mutex;
    /** The changes made through the view. */
    std::vector<LiveServer::Change> changes;
    /** The requests refused, by kind. */
    std::map<std::string, unsigned int> refusals;
    /** The material and the active node at the start. */
    const std::string scene_material, scene_active;

    /** A request must come whole within this many seconds of connecting
     * or of the last answer (keep-alive waits 1 s for its first byte). */
    static constexpr double request_limit = 3;
    /** The HTTP server. */
    GuardedServer server{request_limit};
    /** The thread it listens on. */
    std::thread http;
  };
} // namespace palpate

#endif
