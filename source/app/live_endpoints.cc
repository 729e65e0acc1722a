// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

// The live view's endpoints: the steps of LiveServer's constructor that
// set up its HTTP server (who may ask, what the page may read and change,
// how long a connection may take, where it listens).

#include <palpate/app/http_guard.h>
#include <palpate/app/live_server_impl.h>
#include <palpate/base/exceptions.h>
#include <palpate/hyperelastic/material.h>
#include <palpate/mesh/mesh.h>
#include <palpate/mesh/node_selection.h>
#include <palpate/scene/scene.h>
#include <palpate/state_space/state_grid.h>

#include <httplib.h>
#include <netdb.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <iomanip>
#include <limits>
#include <sstream>
#include <stdexcept>

namespace palpate
{
  namespace
  {
    /**
     * Why @p host : @p port cannot be listened on, blaming the right one:
     * a name that does not resolve or an address this machine does not
     * have is --host's fault, a port in use or reserved is --port's (the
     * server library only says "no").
     */
    InputError
    cannot_listen(const std::string &host, const int port)
    {
      const std::string where = host + ":" + std::to_string(port);
      addrinfo          hints{};
      hints.ai_family   = AF_UNSPEC;
      hints.ai_socktype = SOCK_STREAM;
      hints.ai_flags    = AI_PASSIVE;
      addrinfo *found   = nullptr;
      if (::getaddrinfo(
            host.c_str(), std::to_string(port).c_str(), &hints, &found) != 0 ||
          found == nullptr)
        return InputError("command line",
                          0,
                          "--host " + host,
                          "'" + host +
                            "' is not an address or a name this machine can "
                            "resolve",
                          "give one of this machine's addresses: 127.0.0.1 "
                          "(the default: this machine only), 0.0.0.0 (every "
                          "interface), or an interface's address (ip addr).");
      int error = 0;
      for (addrinfo *a = found; a != nullptr && error == 0; a = a->ai_next)
        {
          const int fd = ::socket(a->ai_family, a->ai_socktype, 0);
          if (fd < 0)
            continue;
          const int yes = 1;
          ::setsockopt(fd, SOL_SOCKET, SO_REUSEADDR, &yes, sizeof(yes));
          if (::bind(fd, a->ai_addr, a->ai_addrlen) != 0)
            error = errno;
          ::close(fd);
        }
      ::freeaddrinfo(found);
      if (error == EADDRNOTAVAIL)
        return InputError("command line",
                          0,
                          "--host " + host,
                          "'" + host + "' is not an address of this machine",
                          "give one of this machine's addresses: 127.0.0.1 "
                          "(the default), 0.0.0.0 (every interface), or an "
                          "interface's address (ip addr).");
      if (error == EACCES)
        return InputError("command line",
                          0,
                          "--port " + std::to_string(port),
                          "cannot listen on " + where +
                            ": ports below 1024 need privileges",
                          "choose a port from 1024 up, e.g. --port 8081.");
      return InputError("command line",
                        0,
                        "--port " + std::to_string(port),
                        "cannot listen on " + where +
                          (error == EADDRINUSE ?
                             ": another program uses the port" :
                             " (" + std::string(std::strerror(error)) + ")"),
                        "choose another port, e.g. --port " +
                          std::to_string(port == 65535 ? 8081 : port + 1) +
                          ".");
    }


    /** @p value as the change lines print numbers (6 digits), or as it is
     * if it is not one. */
    std::string
    number_text(const std::string &value)
    {
      try
        {
          std::size_t  used = 0;
          const double x    = std::stod(value, &used);
          if (used == value.size())
            {
              std::ostringstream s;
              s << std::setprecision(10) << x;
              return s.str();
            }
        }
      catch (const std::exception &)
        {}
      return value;
    }



    /** Whether @p value is a number as a whole that is not finite or is
     * subnormal (1e-320): deal.II's pattern takes it, but it cannot be
     * computed with. */
    bool
    beyond_normal_range(const std::string &value)
    {
      char        *end = nullptr;
      const double x   = std::strtod(value.c_str(), &end);
      return !value.empty() && end == value.c_str() + value.size() &&
             (!std::isfinite(x) ||
              (x != 0 && std::abs(x) < std::numeric_limits<double>::min()));
    }
  } // namespace



  /** Who may ask, checked before any handler; the answers' own headers. */
  void
  LiveServer::Impl::guard_requests()
  {
    Impl &s      = *this;
    auto &server = s.server;
    // Before any handler, and before a POST's body is read: who may ask
    // (http_guard::refusal()). A refused client's connection is closed (the
    // body it sent, unread, is not taken for another request).
    server.set_pre_routing_handler(
      [&s](const httplib::Request &req, httplib::Response &res) {
        std::string       kind;
        const std::string reason =
          http_guard::refusal(req, s.token, s.bound, s.hosts, s.address, kind);
        if (reason.empty())
          return httplib::Server::HandlerResponse::Unhandled;
        s.refuse(req, kind, reason);
        res.status = kind == "malformed" ? 400 : 403;
        res.set_header("Connection", "close");
        res.set_content("refused: " + reason + "\n", "text/plain");
        return httplib::Server::HandlerResponse::Handled;
      });
    // On every answer: never read by a page of another site as a script or
    // an image (no-cors), nor guessed as another type than it says.
    server.set_default_headers({{"Cross-Origin-Resource-Policy", "same-origin"},
                                {"X-Content-Type-Options", "nosniff"}});
  }



  /** The page, three.js, the model (/mesh, /material) and its frames. */
  void
  LiveServer::Impl::add_reads()
  {
    Impl &s      = *this;
    auto &server = s.server;
    server.Get("/", [&s](const httplib::Request &, httplib::Response &res) {
      // The page holds the run's token: not kept by the browser's cache
      // (a page from an earlier run would send a stale one), and never
      // shown in a frame of another site's page (a click there would be a
      // click on the view: clickjacking).
      res.set_header("Cache-Control", "no-store");
      res.set_header("X-Frame-Options", "DENY");
      res.set_header("Content-Security-Policy", "frame-ancestors 'none'");
      res.set_content(s.page, "text/html");
    });
    server.Get("/favicon.ico",
               [](const httplib::Request &, httplib::Response &res) {
                 res.status = 204;
               });
    // three.js's modules: the page imports three.module.js, which imports
    // ./three.core.js, and OrbitControls.js, which imports 'three' (the
    // page's import map: /three.module.js, the same module).
    for (const auto &[path, module] :
         {std::make_pair("/three.module.js", live_view_assets::three_module()),
          std::make_pair("/three.core.js", live_view_assets::three_core()),
          std::make_pair("/OrbitControls.js",
                         live_view_assets::orbit_controls())})
      server.Get(
        path,
        [module = module](const httplib::Request &, httplib::Response &res) {
          res.set_content(module.data(), module.size(), "text/javascript");
        });
    server.Get("/mesh", [&s](const httplib::Request &, httplib::Response &res) {
      std::lock_guard<std::mutex> lock(s.mutex);
      res.set_content(s.mesh_json + "," + s.active_json + "}",
                      "application/json");
    });
    server.Get("/material",
               [&s](const httplib::Request &, httplib::Response &res) {
                 res.set_content(s.material_json(), "application/json");
               });
    server.Get("/frame",
               [&s](const httplib::Request &, httplib::Response &res) {
                 res.set_content(s.frame(), "application/json");
               });
  }



  /** The probe's target, attach, detach and back to rest. */
  void
  LiveServer::Impl::add_device_requests()
  {
    Impl &s      = *this;
    auto &server = s.server;
    server.Post(
      "/hip", [&s](const httplib::Request &req, httplib::Response &res) {
        // "x,y,z": the target displacement from rest (m). Anything else, or
        // a target beyond twice the state space, is refused: the device
        // keeps its target.
        try
          {
            const auto   x     = Utilities::parse_point(req.body);
            const double limit = 2 * s.interaction.grid().spacing() *
                                 s.interaction.grid().half_width();
            for (const double c : x)
              if (!std::isfinite(c) || std::abs(c) > limit)
                throw std::invalid_argument("out of range");
            s.device.set_target(x);
            res.set_content("ok", "text/plain");
          }
        catch (const std::exception &)
          {
            res.status = 400;
            res.set_content("expected x,y,z in metres (the HIP's displacement "
                            "from rest, within twice the state space)",
                            "text/plain");
          }
      });
    // Attach and detach are recorded when they change something (a
    // second d changes nothing).
    server.Post("/attach",
                [&s](const httplib::Request &, httplib::Response &res) {
                  std::lock_guard<std::mutex> lock(s.control_mutex);
                  if (!s.interaction.attached())
                    {
                      s.interaction.attach();
                      s.record("attached");
                    }
                  res.set_content("ok", "text/plain");
                });
    server.Post("/detach",
                [&s](const httplib::Request &, httplib::Response &res) {
                  std::lock_guard<std::mutex> lock(s.control_mutex);
                  if (s.interaction.attached())
                    {
                      s.interaction.detach();
                      s.record("detached (the force fades to zero)");
                    }
                  res.set_content("ok", "text/plain");
                });
    server.Post("/reset",
                [&s](const httplib::Request &, httplib::Response &res) {
                  s.device.set_target({{0, 0, 0}});
                  s.record("the probe sent back to rest");
                  res.set_content("ok", "text/plain");
                });
  }



  /** A material constant of the scene's model, "ENTRY=VALUE". */
  void
  LiveServer::Impl::add_material_change()
  {
    Impl &s      = *this;
    auto &server = s.server;
    server.Post(
      "/material", [&s](const httplib::Request &req, httplib::Response &res) {
        const auto eq = req.body.find('=');
        if (eq == std::string::npos)
          {
            res.status = 400;
            res.set_content("expected ENTRY=VALUE, e.g. Young's "
                            "modulus=20000",
                            "text/plain");
            return;
          }
        const std::string entry = Utilities::trim(req.body.substr(0, eq));
        const std::string value = Utilities::trim(req.body.substr(eq + 1));
        // A number deal.II's pattern takes but cannot convert (1e-320, a
        // subnormal) or that is not finite: refused here, in words (the
        // scene file's reader does the same).
        if (beyond_normal_range(value))
          {
            res.status = 400;
            res.set_content("refused: " + entry + " = " + value +
                              " is not a number palpate can compute with "
                              "(beyond a double's normal range)",
                            "text/plain");
            return;
          }
        // The value in force sent again: nothing changes, and the cached
        // states are kept (it dropped them and was counted as a change).
        {
          std::lock_guard<std::mutex> control(s.control_mutex);
          const auto                 &material =
            s.interaction.scene().parameters.material_model;
          try
            {
              const std::string now = material.get(material.model_name, entry);
              char             *end_now = nullptr, *end_new = nullptr;
              const double      a = std::strtod(now.c_str(), &end_now);
              const double      b = std::strtod(value.c_str(), &end_new);
              if (!now.empty() && !value.empty() &&
                  end_now == now.c_str() + now.size() &&
                  end_new == value.c_str() + value.size() && a == b)
                {
                  res.set_content(entry + " = " + value +
                                    ": unchanged (the value in force); the "
                                    "cached states are kept",
                                  "text/plain");
                  return;
                }
            }
          catch (const std::exception &)
            {
              // An entry the model does not have: change() says so.
            }
        }
        std::string refused, before;
        try
          {
            refused = s.change(
              [&](Parameters::AllParameters &p) {
                auto &material = p.material_model;
                try
                  {
                    before = material.get(material.model_name, entry);
                  }
                catch (const std::exception &)
                  {
                    // An entry the model does not have: set() says so.
                  }
                material.set(material.model_name, entry, value);
              },
              false,
              [&] {
                // "Young's modulus 15465 -> 20000 Pa": the value in force
                // now, as the model read it; pascals for its moduli.
                const auto &material =
                  s.interaction.scene().parameters.material_model;
                std::string unit;
                for (const auto &modulus : Material::create(material)->moduli())
                  if (modulus.first == entry)
                    unit = " Pa";
                return entry + " " + number_text(before) + " -> " +
                       number_text(material.get(material.model_name, entry)) +
                       unit;
              });
          }
        catch (const std::exception &e)
          {
            refused = e.what();
          }
        res.status = refused.empty() ? 200 : 400;
        res.set_content(refused.empty() ?
                          entry + " = " + value +
                            ": changed; the cached states were dropped and "
                            "are computed again" :
                          "refused: " + refused,
                        "text/plain");
      });
  }



  /** Another active node: "node N" or the point "x,y,z". */
  void
  LiveServer::Impl::add_active_node_change()
  {
    Impl &s      = *this;
    auto &server = s.server;
    server.Post(
      "/active", [&s](const httplib::Request &req, httplib::Response &res) {
        std::string refused;
        // "active node: node 87 at (...) mm -> node 45 at (...) mm": the
        // active node before (read by the edit, under change()'s lock)
        // and after.
        std::string before;
        const auto  describe = [&] {
          return "active node: " + before + " -> " + s.active_description();
        };
        try
          {
            const std::string body = Utilities::trim(req.body);
            if (body.rfind("node", 0) == 0)
              {
                // The whole rest must be the number: "node 3x" is refused,
                // not read as node 3.
                const std::string number = Utilities::trim(body.substr(4));
                long              id     = 0;
                if (!Utilities::parse_whole_number(number, id))
                  throw std::invalid_argument("'" + number +
                                              "' is not a node number");
                refused = s.change(
                  [&](Parameters::AllParameters &p) {
                    before = s.active_description();
                    p.boundary_conditions.active_node.selection = "node id";
                    p.boundary_conditions.active_node.node_id   = id;
                  },
                  true,
                  describe);
              }
            else
              {
                const auto point = Utilities::parse_point(body);
                // A point on the organ: within its bounding box, enlarged by a
                // tenth of its diameter (a huge or NaN point would select no
                // node).
                const auto [low, high] = s.interaction.mesh().bounding_box();
                const double margin    = 0.1 * s.interaction.mesh().diameter();
                for (unsigned int k = 0; k < 3; ++k)
                  if (!(point[k] >= low[k] - margin &&
                        point[k] <= high[k] + margin))
                    throw std::invalid_argument(
                      "the point (" + Utilities::to_string(point, 6) +
                      ") m is not on the organ (its bounding box is (" +
                      Utilities::to_string(low, 6) + ") to (" +
                      Utilities::to_string(high, 6) + ") m)");
                refused = s.change(
                  [&](Parameters::AllParameters &p) {
                    before = s.active_description();
                    p.boundary_conditions.active_node.selection =
                      "nearest surface node";
                    p.boundary_conditions.active_node.point = point;
                  },
                  true,
                  describe);
              }
          }
        catch (const std::invalid_argument &e)
          {
            refused = std::string(e.what()) +
                      "; send 'node N' (N as the mesh file numbers the "
                      "node) or a point 'x,y,z' (m) on the organ";
          }
        catch (const std::exception &e)
          {
            refused = e.what();
          }
        if (refused.empty())
          {
            std::lock_guard<std::mutex> lock(s.mutex);
            const auto                 &m = s.interaction.mesh();
            const auto                  v = s.interaction.nodes().active_vertex;
            Utilities::Point3           x;
            for (unsigned int k = 0; k < 3; ++k)
              x[k] = 1000 * m.vertices()[v][k];
            res.set_content(m.node_name(v) + " at (" +
                              Utilities::to_string(x, 4) +
                              ") mm; the cached states were dropped and are "
                              "computed again",
                            "text/plain");
            return;
          }
        res.status = 400;
        res.set_content("refused: " + refused, "text/plain");
      });
  }



  /** What a request may be, and how long a connection may take. */
  void
  LiveServer::Impl::limit_connections()
  {
    Impl &s      = *this;
    auto &server = s.server;
    server.set_payload_max_length(4096);
    // Slow or idle clients cannot keep the page waiting. Each connection
    // has a thread of its own (ConnectionThreads: a browser keeps several
    // open, and with a fixed pool nine clients that sent a header line
    // every 3 s held every thread); one that sends nothing for 1 s
    // before a request, or pauses 2 s within one (the page's requests
    // come whole; cpp-httplib's default would wait 5 s), or does not take
    // an answer for 5 s, is closed; so is one whose request has not come
    // whole 3 s after it connected or got its last answer (GuardedServer:
    // a header line every second held a thread for ever), and with every
    // thread taken, the one that has waited longest for its request is
    // closed to make room. A kept-alive connection serves up to
    // 100 requests (the page asks 30 times a second; the default, 5, made
    // it connect again six times a second).
    server.new_task_queue = [&s] {
      return new ConnectionThreads(8, 256, [&s] {
        return s.server.evict_slowest();
      });
    };
    server.set_keep_alive_timeout(1);
    server.set_keep_alive_max_count(100);
    server.set_read_timeout(2, 0);
    server.set_write_timeout(5, 0);
    // Without connections, the threads that ended are joined once a
    // second (ConnectionThreads::on_idle()).
    server.set_idle_interval(1, 0);
    // The reply's header and body go in two writes: with Nagle's algorithm
    // the second waits for the browser's delayed ACK of the first, 40 ms,
    // and the page's frames came at 20 Hz instead of 30 (measured in
    // headless Chromium: 44 ms per /frame, 2 ms with curl).
    server.set_tcp_nodelay(true);
    // cpp-httplib's default also sets SO_REUSEPORT, with which a second
    // palpate serve on the same port binds too and the kernel shares the
    // connections between the two: only SO_REUSEADDR (a restart can bind
    // at once), so a port in use is an error that says so.
    server.set_socket_options([&s](const socket_t sock) {
      const int yes = 1;
      setsockopt(sock, SOL_SOCKET, SO_REUSEADDR, &yes, sizeof yes);
      s.listening = sock;
    });
  }



  /** Bind (a port in use is an error that says so), listen with a long
   * queue, and the names and address requests may use. */
  void
  LiveServer::Impl::listen(const std::string &host, const int port)
  {
    Impl &s      = *this;
    auto &server = s.server;
    s.bound      = port == 0 ? server.bind_to_any_port(host) :
                               (server.bind_to_port(host, port) ? port : -1);
    // cpp-httplib listens with a backlog of 5 connections: the kernel drops
    // the next ones that arrive before they are accepted, and their
    // clients try again after 1 s (then 3 s, 7 s). A burst of connections
    // (a page's first requests, or clients that mean harm) made the others
    // wait. Listening again on the same socket sets a longer queue.
    if (s.bound > 0 && s.listening >= 0)
      ::listen(s.listening, SOMAXCONN);
    if (s.bound <= 0)
      throw cannot_listen(host, port);
    // The names a request may address it by (http_guard::refusal()): the host
    // it was given; on the loopback interface, or on every interface,
    // also the loopback's names; on every interface, this machine's name
    // and addresses (as they are now).
    s.hosts.insert(http_guard::as_url_host(host));
    if (http_guard::loopback(host) || http_guard::every_interface(host))
      s.hosts.insert({"127.0.0.1", "localhost", "[::1]"});
    if (http_guard::every_interface(host))
      for (const auto &name : http_guard::machine_names())
        s.hosts.insert(name);
    std::string here = http_guard::as_url_host(host);
    if (http_guard::every_interface(host))
      {
        char name[256] = {};
        here = gethostname(name, sizeof name - 1) == 0 && name[0] != 0 ?
                 http_guard::lower_case(name) :
                 "127.0.0.1";
      }
    s.address = "http://" + here + ":" + std::to_string(s.bound) + "/";
  }
} // namespace palpate
