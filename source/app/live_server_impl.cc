// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

// The live view's state: the surface the page draws, its frames, and the
// changes made through it (LiveServer::Impl). The endpoints that call
// these are in live_endpoints.cc.

#include <palpate/app/http_guard.h>
#include <palpate/app/live_server_impl.h>
#include <palpate/base/exceptions.h>
#include <palpate/engine/engine.h>
#include <palpate/haptics/shape_interpolator.h>
#include <palpate/hyperelastic/hyperelastic_system.h>
#include <palpate/hyperelastic/material.h>
#include <palpate/mesh/mesh.h>
#include <palpate/mesh/node_selection.h>
#include <palpate/scene/scene.h>
#include <palpate/state_space/state_cache.h>
#include <palpate/state_space/state_grid.h>

#include <httplib.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <sstream>
#include <stdexcept>

namespace palpate
{
  namespace
  {
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

    /** Runs @p f; returns "" if it succeeds, else why it was refused, as a
     * live view's change reports it: "problem (fix)" for bad input. */
    std::string
    refusal_of(const std::function<void()> &f)
    {
      try
        {
          f();
        }
      catch (const InputError &e)
        {
          return e.problem() + " (" + e.fix() + ")";
        }
      catch (const std::exception &e)
        {
          return *e.what() != '\0' ? e.what() : "refused (no reason given)";
        }
      return "";
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



  LiveServer::Impl::Impl(const Scene  &scene,
                         const double  max_speed,
                         std::ostream *log)
    : interaction(scene)
    , max_speed(max_speed)
    , rate(scene.parameters.haptics.loop_rate)
    , device(rate, max_speed)
    , token(http_guard::make_token())
    , log(log)
    , scene_material(material_description())
    , scene_active(active_description())
  {
    force_log = scene.parameters.effects.force_log;
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
      << ",\"scene\":" << Utilities::json_string(interaction.scene().file());
    m << ",\"engine\":" << Utilities::json_string(interaction.summary().engine);
    mesh_json = m.str();
    describe_active();
    displacement.assign(3 * surface.size(), 0.0);

    // The page with the run's token in it (its <meta name=
    // "palpate-token">): the page sends it back with every change.
    page                          = live_view_page;
    const std::string placeholder = "{{palpate-token}}";
    const auto        at          = page.find(placeholder);
    if (at == std::string::npos)
      throw std::logic_error("the live view's page has no place for its "
                             "token");
    page.replace(at, placeholder.size(), token);

    if (live_view_assets::three_module().empty())
      throw NotAvailableError(
        "the live view's 3-D rendering (three.js)",
        "this palpate was built without it: npm was missing (or failed) "
        "when cmake ran. Install npm (apt-get install npm), then run cmake "
        "and make again: cmake installs three.js from npm into the build "
        "tree and builds it in");
  }



  void
  LiveServer::Impl::describe_active()
  {
    const Mesh          &mesh  = interaction.mesh();
    const NodeSelection &nodes = interaction.nodes();
    const auto          &tip =
      interaction.scene().parameters.boundary_conditions.active_node;
    const bool sphere = nodes.sphere_tip;
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



  std::string
  LiveServer::Impl::frame()
  {
    const Utilities::Point3 x = device.hip(), f = device.force(),
                            t = device.target();
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
    const double radius = interaction.scene().parameters.scheduler.cloud_radius;
    const int    reach  = std::ceil(radius / grid.spacing()) + 1;
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
            const int status = static_cast<int>(interaction.cache().status(p));
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
      << cause_name(interaction.missing_cause())
      << "\",\"available\":" << counts.first << ",\"failed\":" << counts.second
      << ",\"cloud_complete\":"
      << (interaction.initial_cloud_complete() ? "true" : "false")
      << ",\"attached\":" << (interaction.attached() ? "true" : "false") << ","
      << active_json << ",\"load\":{\"workers\":" << load.workers
      << ",\"busy\":" << load.busy << ",\"queued\":" << load.queued
      << ",\"states_per_second\":" << json_number(states_per_second)
      << ",\"utilisation\":" << json_number(utilisation) << "}"
      << ",\"cloud\":" << json_array(cloud, 6)
      << ",\"displacement\":" << json_array(displacement, 6) << "}";
    return s.str();
  }



  std::string
  LiveServer::Impl::material_description() const
  {
    const auto &material = interaction.scene().parameters.material_model;
    return material.model_name + ", " +
           Material::create(material)->description();
  }



  std::string
  LiveServer::Impl::active_description() const
  {
    const auto &mesh = interaction.mesh();
    const auto  v    = interaction.nodes().active_vertex;
    if (v == NodeSelection::no_active_node)
      return "none";
    return mesh.node_name(v) + " at (" +
           Utilities::to_string(Utilities::scaled(mesh.vertices()[v], 1000),
                                4) +
           ") mm";
  }



  void
  LiveServer::Impl::record(const std::string &what)
  {
    std::lock_guard<std::mutex> lock(record_mutex);
    changes.push_back(
      {std::chrono::duration<double>(Clock::now() - started).count(), what});
    if (log != nullptr)
      *log << "live view: " << what << std::endl;
  }



  void
  LiveServer::Impl::refuse(const httplib::Request &request,
                           const std::string      &kind,
                           const std::string      &reason)
  {
    std::lock_guard<std::mutex> lock(record_mutex);
    if (++refusals[kind] == 1 && log != nullptr)
      *log << "live view: refused " << http_guard::printable(request.method, 10)
           << " " << http_guard::printable(request.path) << ": " << reason
           << " [more of this kind are counted in the summary, not printed]"
           << std::endl;
  }



  std::string
  LiveServer::Impl::material_json()
  {
    std::lock_guard<std::mutex> lock(mutex);
    const auto        &material = interaction.scene().parameters.material_model;
    std::ostringstream m;
    m << "{\"model\":" << Utilities::json_string(material.model_name)
      << ",\"constants\":{";
    const auto found = material.models.find(material.model_name);
    if (found != material.models.end())
      {
        bool first = true;
        for (const auto &[entry, value] : found->second)
          {
            m << (first ? "" : ",") << Utilities::json_string(entry) << ":"
              << Utilities::json_string(value);
            first = false;
          }
      }
    m << "}}";
    return m.str();
  }



  std::string
  LiveServer::Impl::change(
    const std::function<void(Parameters::AllParameters &)> &edit,
    const bool                                              rest,
    const std::function<std::string()>                     &describe)
  {
    // One change, attach or detach at a time (connections are served
    // in parallel); the device runs on while detaching (the force
    // fades).
    std::lock_guard<std::mutex> control(control_mutex);
    Parameters::AllParameters   p = interaction.scene().parameters;
    edit(p);
    // Checked first, attached and outside the lock /frame waits for: a
    // refused sphere tries the radius it offers by static solves, which
    // take seconds on a fine mesh, and under the locks the view would
    // freeze for them.
    const std::string early =
      refusal_of([&] { interaction.check_parameters(p); });
    if (!early.empty())
      return early;
    interaction.detach();
    const std::string refused = refusal_of([&] {
      // The device held (the loop asks the interaction for nothing)
      // while its scene is replaced.
      const HeldDevice            held(*loop);
      std::lock_guard<std::mutex> frame_lock(mutex);
      interaction.change_parameters(p);
      describe_active();
      // Another active node: the device at rest on it (a target sent
      // meanwhile was for the old one).
      if (rest)
        device.reset();
    });
    interaction.attach();
    if (refused.empty())
      record(describe());
    return refused;
  }
} // namespace palpate
