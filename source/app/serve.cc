// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

#include <palpate/app/application.h>
#include <palpate/app/serve.h>
#include <palpate/base/exceptions.h>
#include <palpate/engine/engine.h>
#include <palpate/haptics/interaction.h>
#include <palpate/haptics/shape_interpolator.h>
#include <palpate/hyperelastic/hyperelastic_system.h>
#include <palpate/mesh/mesh.h>
#include <palpate/mesh/node_selection.h>
#include <palpate/scene/scene.h>
#include <palpate/state_space/state_cache.h>
#include <palpate/state_space/state_grid.h>

#include <httplib.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <csignal>
#include <functional>
#include <map>
#include <mutex>
#include <sstream>
#include <string_view>
#include <thread>
#include <utility>

namespace palpate
{
  /** The page (serve_page.cc): three.js draws the surface, the HIP and the
   * force; a drag on the organ moves the HIP in the view plane (with Alt,
   * in depth), other drags and the wheel turn, pan and zoom the view. */
  extern const char *const live_view_page;

  /** three.js, compiled in (live_view_assets.cc). */
  namespace live_view_assets
  {
    std::string_view
    three_core();
    std::string_view
    three_module();
    std::string_view
    orbit_controls();
  } // namespace live_view_assets

  namespace
  {
    using Clock = std::chrono::steady_clock;

    std::string
    json_array(const std::vector<double> &v, const unsigned int digits = 6)
    {
      std::ostringstream s;
      s.precision(digits);
      s << '[';
      for (std::size_t i = 0; i < v.size(); ++i)
        s << (i ? "," : "") << (std::isfinite(v[i]) ? v[i] : 0.0);
      s << ']';
      return s.str();
    }

    /** @p text as a JSON string (quotes, backslashes and control
     * characters escaped). */
    std::string
    json_string(const std::string &text)
    {
      std::ostringstream s;
      s << '"';
      for (const char c : text)
        if (c == '"' || c == '\\')
          s << '\\' << c;
        else if (static_cast<unsigned char>(c) < 0x20)
          s << ' ';
        else
          s << c;
      s << '"';
      return s.str();
    }

    std::string
    json_number(const double x)
    {
      std::ostringstream s;
      s.precision(4);
      s << (std::isfinite(x) ? x : 0.0);
      return s.str();
    }

    std::string
    json_point(const Utilities::Point3 &p)
    {
      return json_array({p[0], p[1], p[2]}, 17);
    }

    const char *
    cause_name(const MissingCause c)
    {
      switch (c)
        {
          case MissingCause::none:
            return "none";
          case MissingCause::not_computed:
            return "not computed yet";
          case MissingCause::failure_region:
            return "failure region";
          default:
            return "outside the state space";
        }
    }

    /** The outward unit normal of the surface at vertex @p v: the
     * area-weighted mean of the normals of the surface triangles around
     * it (Mesh orients them outward), or 0 if it is on none. */
    Utilities::Point3
    outward_normal(const Mesh &mesh, const unsigned int v)
    {
      const auto       &x = mesh.vertices();
      Utilities::Point3 n{{0, 0, 0}};
      for (const auto &face : mesh.surface_faces())
        {
          const auto &t = face.vertices;
          if (t[0] != v && t[1] != v && t[2] != v)
            continue;
          // Twice the area times the unit normal.
          const auto c = Utilities::cross(Utilities::minus(x[t[1]], x[t[0]]),
                                          Utilities::minus(x[t[2]], x[t[0]]));
          for (unsigned int k = 0; k < 3; ++k)
            n[k] += c[k];
        }
      const double length = Utilities::norm(n);
      return length > 0 ? Utilities::scaled(n, 1 / length) : n;
    }
  } // namespace



  struct LiveServer::Impl
  {
    Impl(const Scene &scene, const double max_speed)
      : interaction(scene)
      , max_speed(max_speed)
      , rate(scene.parameters.haptics.loop_rate)
    {
      for (auto &a : {&target, &hip, &force})
        for (auto &x : *a)
          x.store(0);
      // The surface: its vertices (rest positions), triangles, and the
      // DoFs of each vertex's displacement.
      const Mesh              &mesh = interaction.mesh();
      const HyperelasticSystem system(mesh,
                                      interaction.nodes(),
                                      interaction.scene().parameters);
      const ShapeFrames        frames(mesh, interaction.nodes(), system);
      std::map<unsigned int, unsigned int> &compact = surface_index;
      for (const auto &face : mesh.surface_faces())
        {
          std::array<unsigned int, 3> t;
          for (unsigned int k = 0; k < 3; ++k)
            {
              const unsigned int v  = face.vertices[k];
              const auto         it = compact.find(v);
              if (it == compact.end())
                {
                  t[k] = compact[v] = surface.size();
                  surface.push_back(v);
                }
              else
                t[k] = it->second;
            }
          triangles.push_back(t);
        }
      for (const unsigned int v : surface)
        dofs.push_back(frames.dofs_of_vertices()[v]);

      std::vector<double> xyz, tri, fixed;
      for (const unsigned int v : surface)
        for (const double x : mesh.vertices()[v])
          xyz.push_back(x);
      for (const auto &t : triangles)
        for (const unsigned int v : t)
          tri.push_back(v);
      for (const unsigned int v : interaction.nodes().fixed_vertices)
        if (compact.count(v) > 0)
          fixed.push_back(compact[v]);
      // The surface vertices' numbers as the mesh file gives them: the
      // page names nodes by these, as the scene report and the scene's
      // Active node / Node id do, never by its own (surface) or deal.II's
      // (vertex) indices.
      std::vector<double> ids;
      for (const unsigned int v : surface)
        ids.push_back(mesh.node_id(v));
      const auto        &grid = interaction.grid();
      std::ostringstream m;
      m << "{\"vertices\":" << json_array(xyz, 9)
        << ",\"triangles\":" << json_array(tri, 9)
        << ",\"nodes\":" << json_array(ids, 17)
        << ",\"fixed\":" << json_array(fixed, 9)
        << ",\"spacing\":" << grid.spacing()
        << ",\"extent\":" << grid.spacing() * grid.half_width()
        << ",\"diameter\":" << mesh.diameter()
        << ",\"scene\":" << json_string(interaction.scene().file());
      m << ",\"engine\":" << json_string(interaction.summary().engine);
      mesh_json = m.str();
      describe_active();
      displacement.assign(3 * surface.size(), 0.0);

      if (live_view_assets::three_module().empty())
        throw NotAvailableError(
          "the live view's 3-D rendering (three.js)",
          "this palpate was built without it: npm was missing (or failed) "
          "when cmake ran. Install npm (apt-get install npm), then run cmake "
          "and make again: cmake installs three.js from npm into the build "
          "tree and builds it in");
    }

    /** The active node as /mesh and /frame give it (active_json), made
     * again when it changes: its number in the mesh file, the outward
     * normal of the surface there (the page's first camera looks along
     * it, at the probe's side of the organ) and, with a sphere probe, the
     * sphere's centre at HIP = 0 and its radius (m), so that the page
     * draws the indenter where it touches, not a marker at the node.
     * Called with mutex held, or before the server runs. */
    void
    describe_active()
    {
      const Mesh          &mesh  = interaction.mesh();
      const NodeSelection &nodes = interaction.nodes();
      const auto          &tip =
        interaction.scene().parameters.boundary_conditions.active_node;
      const bool sphere = tip.tip == Parameters::ActiveNode::Tip::sphere;
      const bool none   = nodes.active_vertex == NodeSelection::no_active_node;
      std::ostringstream a;
      a << "\"active\":" << (none ? -1L : mesh.node_id(nodes.active_vertex))
        << ",\"normal\":"
        << json_point(sphere ? nodes.active_normal :
                      none   ? Utilities::Point3{{0, 0, 0}} :
                               outward_normal(mesh, nodes.active_vertex));
      if (sphere)
        {
          const auto &c = nodes.sphere_center;
          a << ",\"sphere\":"
            << json_array({c[0], c[1], c[2], tip.tip_radius}, 17);
        }
      active_json = a.str();
    }

    /** The device: at the loop rate, move the HIP toward the target as a
     * hand moves a device, at most at max_speed and speeding up and
     * slowing down at most at max_acceleration (the mouse's jumps
     * smoothed: the velocity the scheduler looks ahead with has no jumps),
     * stopping on the target; and ask the interaction for the force. */
    void
    run_device()
    {
      const auto period = std::chrono::duration_cast<Clock::duration>(
        std::chrono::duration<double>(1.0 / rate));
      const double dt = 1.0 / rate, dv_max = max_acceleration * dt;
      auto         next = Clock::now();
      while (running.load())
        {
          // After a stall (a parameter change holds the device), on from
          // now: no burst of steps that would outrun the speed limit.
          next = std::max(next + period, Clock::now());
          std::this_thread::sleep_until(next);
          // Held while the parameters change (the interaction is detached
          // and its scene replaced then, and another active node starts
          // at rest).
          std::lock_guard<std::mutex> lock(device_mutex);
          auto                       &x = device_position, &v = device_velocity;
          Utilities::Point3           d;
          for (unsigned int k = 0; k < 3; ++k)
            d[k] = target[k].load() - x[k];
          const double n = Utilities::norm(d);
          // Toward the target at the speed from which it can still stop
          // there (at most max_speed); the velocity changes by at most
          // dv_max per tick.
          const double reach =
            std::min(max_speed, std::sqrt(2 * max_acceleration * n));
          Utilities::Point3 dv;
          for (unsigned int k = 0; k < 3; ++k)
            dv[k] = (n > 0 ? reach * d[k] / n : 0.0) - v[k];
          const double change = Utilities::norm(dv);
          for (unsigned int k = 0; k < 3; ++k)
            v[k] += change > dv_max ? dv[k] * dv_max / change : dv[k];
          // Within this tick's step, slow (as the approach leaves it: at
          // most 2 mm/s at 1 kHz) and heading for it: on the target, at
          // rest. Moving away or fast, as when the target came back toward
          // the probe, it brakes at max_acceleration instead.
          const double speed   = Utilities::norm(v);
          double       heading = 0;
          for (unsigned int k = 0; k < 3; ++k)
            heading += v[k] * d[k];
          if (speed * dt >= n && speed <= 2 * dv_max * (1 + 1e-9) &&
              (n == 0 || heading > 0))
            {
              for (unsigned int k = 0; k < 3; ++k)
                {
                  x[k] += d[k];
                  v[k] = 0;
                }
            }
          else
            for (unsigned int k = 0; k < 3; ++k)
              x[k] += v[k] * dt;
          const Utilities::Point3 f = interaction.force(x);
          for (unsigned int k = 0; k < 3; ++k)
            {
              hip[k].store(x[k]);
              force[k].store(f[k]);
            }
          cause.store(static_cast<std::uint8_t>(interaction.missing_cause()));
        }
    }

    std::string
    frame()
    {
      Utilities::Point3 x, f, t;
      for (unsigned int k = 0; k < 3; ++k)
        {
          x[k] = hip[k].load();
          f[k] = force[k].load();
          t[k] = target[k].load();
        }
      // The lock first: the parameters (and the nodes) may be changing.
      std::lock_guard<std::mutex> lock(mutex);
      State                       blend;
      const bool                  complete = blend_shape(interaction, x, blend);
      if (complete)
        for (std::size_t v = 0; v < surface.size(); ++v)
          for (unsigned int k = 0; k < 3; ++k)
            displacement[3 * v + k] = blend.solution[dofs[v][k]];
      const auto counts = interaction.cache().counts();
      // The engine's load: workers solving, tasks waiting, and since the
      // last frame (at least 0.5 s ago) states per second and the fraction
      // of the workers' time spent solving.
      const EngineLoad load = interaction.engine_load();
      const auto       now  = Clock::now();
      const double     dt =
        std::chrono::duration<double>(now - load_sample.time).count();
      if (dt >= 0.5)
        {
          const unsigned int done = load.computed + load.failed;
          states_per_second =
            done >= load_sample.done ? (done - load_sample.done) / dt : 0.0;
          utilisation = std::clamp((load.busy_time - load_sample.busy_time) /
                                     (dt * std::max(1u, load.workers)),
                                   0.0,
                                   1.0);
          load_sample = {now, done, load.busy_time};
        }
      std::vector<std::uint8_t> computing(interaction.grid().size(), 0);
      for (const unsigned int p : load.in_progress)
        computing[p] = 1;
      // The cloud around the HIP, as the paper's Fig. 1 draws it and the
      // scheduler keeps it (at rest): each grid point within the cloud
      // radius of the HIP with its status (0 not computed, 1
      // computed, 2 a failure point, 3 being computed), as i, j, k, status.
      const auto     &grid   = interaction.grid();
      const GridIndex centre = grid.nearest(x);
      const double    radius =
        interaction.scene().parameters.scheduler.cloud_radius;
      const int           reach = std::ceil(radius / grid.spacing()) + 1;
      std::vector<double> cloud;
      for (int i = -reach; i <= reach; ++i)
        for (int j = -reach; j <= reach; ++j)
          for (int k = -reach; k <= reach; ++k)
            {
              const GridIndex g{{centre[0] + i, centre[1] + j, centre[2] + k}};
              if (!grid.contains(g))
                continue;
              const unsigned int p = grid.linear(g);
              if (Utilities::distance(grid.position(p), x) > radius)
                continue;
              const int status =
                static_cast<int>(interaction.cache().status(p));
              cloud.insert(cloud.end(),
                           {double(g[0]),
                            double(g[1]),
                            double(g[2]),
                            double(status == 0 && computing[p] ? 3 : status)});
            }
      std::ostringstream s;
      s << "{\"hip\":" << json_point(x) << ",\"target\":" << json_point(t)
        << ",\"force\":" << json_point(f)
        << ",\"shape\":" << (complete ? "true" : "false") << ",\"missing\":\""
        << cause_name(static_cast<MissingCause>(cause.load()))
        << "\",\"available\":" << counts.first
        << ",\"failed\":" << counts.second << ",\"cloud_complete\":"
        << (interaction.initial_cloud_complete() ? "true" : "false")
        << ",\"attached\":" << (interaction.attached() ? "true" : "false")
        << "," << active_json << ",\"load\":{\"workers\":" << load.workers
        << ",\"busy\":" << load.busy << ",\"queued\":" << load.queued
        << ",\"states_per_second\":" << json_number(states_per_second)
        << ",\"utilisation\":" << json_number(utilisation) << "}"
        << ",\"cloud\":" << json_array(cloud, 6)
        << ",\"displacement\":" << json_array(displacement, 6) << "}";
      return s.str();
    }

    Interaction  interaction;
    const double max_speed, rate;
    /** How fast the device speeds up and slows down (m/s^2): from rest to
     * 5 cm/s in 50 ms, a stop from it within 1.25 mm. */
    static constexpr double                  max_acceleration = 1.0;
    std::vector<unsigned int>                surface;
    std::vector<std::array<unsigned int, 3>> triangles, dofs;
    // /mesh without the active node, and the active node (mutex).
    std::string         mesh_json, active_json;
    std::vector<double> displacement;
    std::atomic<double> target[3], hip[3], force[3];
    // The device's HIP and velocity (device_mutex).
    Utilities::Point3 device_position{{0, 0, 0}}, device_velocity{{0, 0, 0}};
    std::atomic<std::uint8_t> cause{0};
    // The engine's counters at the last load sample (frame()).
    struct
    {
      Clock::time_point time;
      unsigned int      done;
      double            busy_time;
    } load_sample{Clock::now(), 0, 0.0};
    double            states_per_second = 0, utilisation = 0;
    std::atomic<bool> running{true};
    // Locked in this order: control_mutex, device_mutex, mutex.
    std::mutex control_mutex, mutex, device_mutex;
    // Mesh vertex -> its index among the surface's vertices.
    std::map<unsigned int, unsigned int> surface_index;

    /** Change the scene's parameters on the fly: detach, change (the
     * cache is invalidated and the states are computed again), attach.
     * Returns "" or the reason the change was refused. */
    /** The material model and its constants as they are now (the m key's
     * prompt). */
    std::string
    material_json()
    {
      std::lock_guard<std::mutex> lock(mutex);
      const auto &material = interaction.scene().parameters.material_model;
      std::ostringstream m;
      m << "{\"model\":" << json_string(material.model_name)
        << ",\"constants\":{";
      const auto found = material.models.find(material.model_name);
      if (found != material.models.end())
        {
          bool first = true;
          for (const auto &[entry, value] : found->second)
            {
              m << (first ? "" : ",") << json_string(entry) << ":"
                << json_string(value);
              first = false;
            }
        }
      m << "}}";
      return m.str();
    }

    std::string
    change(const std::function<void(Parameters::AllParameters &)> &edit,
           const bool                                              rest = false)
    {
      // One change, attach or detach at a time (the HTTP pool has 8
      // threads); the device runs on while detaching (the force fades).
      std::lock_guard<std::mutex> control(control_mutex);
      Parameters::AllParameters   p = interaction.scene().parameters;
      edit(p);
      interaction.detach();
      std::string refused;
      try
        {
          std::lock_guard<std::mutex> lock(device_mutex), frame_lock(mutex);
          interaction.change_parameters(p);
          describe_active();
          // Another active node: the device at rest on it (a target sent
          // meanwhile was for the old one).
          if (rest)
            {
              for (auto &t : target)
                t.store(0);
              device_position = {{0, 0, 0}};
              device_velocity = {{0, 0, 0}};
            }
        }
      catch (const InputError &e)
        {
          refused = e.problem() + " (" + e.fix() + ")";
        }
      catch (const std::exception &e)
        {
          refused = e.what();
        }
      interaction.attach();
      return refused;
    }

    httplib::Server server;
    std::thread     http, device;
    int             bound = 0;
  };



  LiveServer::LiveServer(const Scene       &scene,
                         const std::string &host,
                         const int          port,
                         const double       max_speed)
    : impl(std::make_unique<Impl>(scene, max_speed))
  {
    Impl &s      = *impl;
    auto &server = s.server;
    server.Get("/", [](const httplib::Request &, httplib::Response &res) {
      res.set_content(live_view_page, "text/html");
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
            for (unsigned int k = 0; k < 3; ++k)
              s.target[k].store(x[k]);
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
    // On-the-fly changes (the paper's): a material constant, as
    // "ENTRY=VALUE" of the scene's model; another active node, as "node N"
    // (N as the mesh file numbers it, as the scene's Active node / Node id
    // and the scene report do) or as the point "x,y,z" (m, mesh
    // coordinates) whose nearest surface node it becomes.
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
        std::string       refused;
        try
          {
            refused = s.change([&](Parameters::AllParameters &p) {
              p.material_model.set(p.material_model.model_name, entry, value);
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
    server.Post(
      "/active", [&s](const httplib::Request &req, httplib::Response &res) {
        std::string refused;
        try
          {
            const std::string body = Utilities::trim(req.body);
            if (body.rfind("node", 0) == 0)
              {
                // The whole rest must be the number: "node 3x" is refused,
                // not read as node 3.
                const std::string number = Utilities::trim(body.substr(4));
                std::size_t       used   = 0;
                long              id     = 0;
                try
                  {
                    id = std::stol(number, &used);
                  }
                catch (const std::exception &)
                  {
                    used = 0;
                  }
                if (used == 0 || used != number.size())
                  throw std::invalid_argument("'" + number +
                                              "' is not a node number");
                refused = s.change(
                  [&](Parameters::AllParameters &p) {
                    p.boundary_conditions.active_node.selection = "node id";
                    p.boundary_conditions.active_node.node_id   = id;
                  },
                  true);
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
                    p.boundary_conditions.active_node.selection =
                      "nearest surface node";
                    p.boundary_conditions.active_node.point = point;
                  },
                  true);
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
            res.set_content("node " + std::to_string(m.node_id(v)) + " at (" +
                              Utilities::to_string(x, 4) +
                              ") mm; the cached states were dropped and are "
                              "computed again",
                            "text/plain");
            return;
          }
        res.status = 400;
        res.set_content("refused: " + refused, "text/plain");
      });
    server.Post("/attach",
                [&s](const httplib::Request &, httplib::Response &res) {
                  std::lock_guard<std::mutex> lock(s.control_mutex);
                  s.interaction.attach();
                  res.set_content("ok", "text/plain");
                });
    server.Post("/detach",
                [&s](const httplib::Request &, httplib::Response &res) {
                  std::lock_guard<std::mutex> lock(s.control_mutex);
                  s.interaction.detach();
                  res.set_content("ok", "text/plain");
                });
    server.Post("/reset",
                [&s](const httplib::Request &, httplib::Response &res) {
                  for (auto &t : s.target)
                    t.store(0);
                  res.set_content("ok", "text/plain");
                });
    server.set_payload_max_length(4096);
    // A browser keeps connections open: with cpp-httplib's default pool
    // (one thread per core less one: one here) a kept-alive connection
    // would hold back every other request for its 5 s timeout.
    server.new_task_queue = [] { return new httplib::ThreadPool(8); };
    server.set_keep_alive_timeout(1);
    // The reply's header and body go in two writes: with Nagle's algorithm
    // the second waits for the browser's delayed ACK of the first, 40 ms,
    // and the page's frames came at 20 Hz instead of 30 (measured in
    // headless Chromium: 44 ms per /frame, 2 ms with curl).
    server.set_tcp_nodelay(true);
    // cpp-httplib's default also sets SO_REUSEPORT, with which a second
    // palpate serve on the same port binds too and the kernel shares the
    // connections between the two: only SO_REUSEADDR (a restart can bind
    // at once), so a port in use is an error that says so.
    server.set_socket_options([](const socket_t sock) {
      const int yes = 1;
      setsockopt(sock, SOL_SOCKET, SO_REUSEADDR, &yes, sizeof yes);
    });
    s.bound = port == 0 ? server.bind_to_any_port(host) :
                          (server.bind_to_port(host, port) ? port : -1);
    if (s.bound <= 0)
      throw InputError("command line",
                       0,
                       "--port " + std::to_string(port),
                       "cannot listen on " + host + ":" + std::to_string(port) +
                         " (in use, or not allowed)",
                       "choose another port, e.g. --port 8081.");
    s.interaction.attach();
    s.device = std::thread([&s] { s.run_device(); });
    s.http   = std::thread([&s] { s.server.listen_after_bind(); });
  }



  LiveServer::~LiveServer()
  {
    stop();
  }



  void
  LiveServer::stop()
  {
    Impl &s = *impl;
    if (!s.running.exchange(false))
      return;
    s.server.stop();
    if (s.http.joinable())
      s.http.join();
    if (s.device.joinable())
      s.device.join();
    s.interaction.detach();
  }



  int
  LiveServer::port() const
  {
    return impl->bound;
  }



  const Interaction &
  LiveServer::interaction() const
  {
    return impl->interaction;
  }



  void
  LiveServer::last(Utilities::Point3 &hip, Utilities::Point3 &force) const
  {
    for (unsigned int k = 0; k < 3; ++k)
      {
        hip[k]   = impl->hip[k].load();
        force[k] = impl->force[k].load();
      }
  }



  namespace
  {
    std::atomic<bool> stop_serving{false};

    extern "C" void
    on_stop(int)
    {
      stop_serving.store(true);
    }
  } // namespace



  int
  run_serve(std::ostream      &out,
            const Scene       &scene,
            const std::string &host,
            const int          port)
  {
    LiveServer server(scene, host, port);
    // Listening on every interface: the address to open is this machine's.
    std::string where = host;
    if (host == "0.0.0.0" || host == "::")
      {
        char name[256] = {};
        where = gethostname(name, sizeof name - 1) == 0 && name[0] != 0 ?
                  std::string(name) :
                  "THIS-MACHINE";
      }
    out << "Live view: open http://" << where << ":" << server.port() << "/"
        << (where != host ? " (listening on every interface)" : "")
        << " in a browser. A drag on the organ moves the probe in the view "
           "plane (with Alt held, in depth); a drag elsewhere or with the "
           "right button turns the view, the middle button (or Shift and "
           "the right) pans it, the wheel zooms; keys: f look at the probe, "
           "v the first view, a attach, d detach, r back to rest, m a "
           "material constant, shift-click another active node. Ctrl-C "
           "ends.\n"
        << std::flush;
    stop_serving.store(false);
    auto *const previous_int  = std::signal(SIGINT, on_stop);
    auto *const previous_term = std::signal(SIGTERM, on_stop);
    while (!stop_serving.load())
      std::this_thread::sleep_for(std::chrono::milliseconds(100));
    std::signal(SIGINT, previous_int);
    std::signal(SIGTERM, previous_term);
    server.stop();
    out << "Live view ended.\n";
    RunSummary summary = server.interaction().summary();
    summary.trajectory = "the browser's mouse (palpate serve)";
    summary.print(out);
    return ExitStatus::success;
  }
} // namespace palpate
