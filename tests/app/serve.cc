// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

// palpate serve's server (issue 16), driven over HTTP as the page drives it,
// on the small beam:
// - the page, three.js and the surface are served (three.js's two modules,
//   the core the revision source/app/web/package.json pins, and its
//   OrbitControls, which the page's import map points at the same
//   module); the surface has the mesh's surface vertices, the fixed and
//   active nodes;
// - one node numbering everywhere, the mesh file's: the active node /mesh
//   and /frame name is the one the scene report names, each surface
//   vertex comes with its number, "node N" posted to /active makes node N
//   the active node (the reply and the frame name it, at its place), and
//   a number the mesh does not have, or a node inside the body, is
//   refused; on a Gmsh file that numbers its nodes 1000 + 7 (n - 1 - i),
//   neither deal.II's vertex index nor the surface index, too; the first
//   view's normal at the active node is the surface's outward normal
//   there;
// - a target sent with POST /hip is reached by the device thread, smoothly
//   (from rest at most at 1 m/s^2) and at most at 5 cm/s, and the
//   force /frame shows equals the state's force at that grid point (the
//   interpolation's exact value there, 1e-9 relative);
// - the shape /frame shows is that state's displacement;
// - the server survives garbage, a flood of targets and a client that
//   connects and leaves without a word;
// - a material constant changed on the fly (Young's modulus doubled) makes
//   the states be computed again: St.Venant-Kirchhoff's force at a fixed
//   displacement is proportional to E, so it doubles (1e-6); a constant
//   that describes no solid is refused with the reason, the old one kept;
//   an entry the model does not have is refused, naming those it has;
// - another active node can be picked; the frame names it; a point far off
//   the organ is refused;
// - attach, detach and changes sent at once from several clients take
//   turns: every change is made (none refused because another request
//   attached in between), and it still serves;
// - a second server cannot take the same port;
// - with a sphere (Tip = sphere, the beam on its bottom face) the page gets
//   the sphere to draw, and the force shown 2 mm in is the state's; another
//   active node moves the sphere, and the frames say where it went.

#include <palpate/app/scene_report.h>
#include <palpate/app/serve.h>
#include <palpate/haptics/interaction.h>
#include <palpate/haptics/run_summary.h>
#include <palpate/mesh/generators.h>
#include <palpate/mesh/mesh.h>
#include <palpate/mesh/node_selection.h>
#include <palpate/state_space/state_cache.h>
#include <palpate/state_space/state_grid.h>

#include <httplib.h>

#include <atomic>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <map>
#include <sstream>
#include <thread>
#include <vector>

#include "../tests.h"

namespace
{
  /** The numbers of the JSON array after "key": in @p json. */
  std::vector<double>
  numbers(const std::string &json, const std::string &key)
  {
    std::vector<double> v;
    auto                at = json.find("\"" + key + "\":[");
    if (at == std::string::npos)
      return v;
    at += key.size() + 4;
    const auto         end = json.find(']', at);
    std::istringstream s(json.substr(at, end - at));
    std::string        item;
    while (std::getline(s, item, ','))
      v.push_back(std::stod(item));
    return v;
  }

  /** The integer after "key": in @p json, or -2 if there is none. */
  long
  integer(const std::string &json, const std::string &key)
  {
    const auto at = json.find("\"" + key + "\":");
    if (at == std::string::npos)
      return -2;
    try
      {
        return std::stol(json.substr(at + key.size() + 3));
      }
    catch (const std::exception &)
      {
        return -2;
      }
  }

  /** The node number the scene report gives the active node ("active
   * node:   node N at ..."), or -1. */
  long
  reported_active_node(const palpate::Interaction &interaction)
  {
    std::ostringstream report;
    palpate::print_scene_report(report,
                                interaction.scene(),
                                interaction.mesh(),
                                interaction.nodes());
    const std::string text = report.str();
    const auto        at   = text.find("active node:   node ");
    return at == std::string::npos ? -1 : std::stol(text.substr(at + 20));
  }

  /** The numbers of a surface node of @p json's /mesh other than @p
   * active, and of a node inside the body (or -1), for the /active
   * posts. */
  std::pair<long, long>
  other_nodes(const palpate::Mesh &mesh, const long active)
  {
    long surface = -1, inside = -1;
    for (unsigned int v = 0; v < mesh.n_vertices(); ++v)
      if (mesh.on_surface()[v] && mesh.node_id(v) != active && surface < 0 &&
          mesh.vertices()[v][0] > 0.08)
        surface = mesh.node_id(v);
      else if (!mesh.on_surface()[v] && inside < 0)
        inside = mesh.node_id(v);
    return {surface, inside};
  }

  /** Whether the reply to "node N" names node @p id at its place (mm, to
   * the 4 digits the reply gives), and /frame names it too. */
  bool
  picked_node(const httplib::Result &reply,
              httplib::Client       &client,
              const palpate::Mesh   &mesh,
              const long             id)
  {
    const auto v = mesh.vertex_of_node_id(id);
    if (!reply || reply->status != 200 || !v)
      return false;
    palpate::Utilities::Point3 x;
    for (unsigned int k = 0; k < 3; ++k)
      x[k] = 1000 * mesh.vertices()[*v][k];
    const auto frame = client.Get("/frame");
    return reply->body.rfind("node " + std::to_string(id) + " at (" +
                               palpate::Utilities::to_string(x, 4) + ") mm",
                             0) == 0 &&
           frame && integer(frame->body, "active") == id;
  }
} // namespace

int
main(int argc, char **argv)
{
  palpate::Environment env(argc, argv);
  initlog();

  const palpate::Scene scene = small_beam_scene();
  palpate::LiveServer  server(scene, "127.0.0.1", 0, 0.05);
  httplib::Client      client("127.0.0.1", server.port());
  // Every change carries the run's token with the live view's content
  // type, as the page sends them (app/serve_security: what happens to
  // requests without them).
  client.set_default_headers(
    {{palpate::LiveServer::token_header, server.token()}});
  client.set_read_timeout(10, 0);

  const auto  page   = client.Get("/");
  const auto  module = client.Get("/three.module.js");
  const auto  core   = client.Get("/three.core.js");
  const auto  mesh   = client.Get("/mesh");
  const auto  orbit  = client.Get("/OrbitControls.js");
  const auto &body   = server.interaction().mesh();
  // "three": "0.187.0" -> revision '187'.
  const std::string pinned =
    read_file(palpate_source_dir + "/source/app/web/package.json");
  const auto        at = pinned.find("\"three\": \"0.");
  const std::string revision =
    at == std::string::npos ?
      "?" :
      pinned.substr(at + 12, pinned.find('.', at + 12) - (at + 12));
  deallog
    << "page served: "
    << ok(page && page->status == 200 &&
          page->body.find("from \"/three.module.js\"") != std::string::npos)
    << ", three.js: "
    << ok(module && module->status == 200 &&
          module->body.find("from './three.core.js'") != std::string::npos &&
          core && core->status == 200 &&
          core->body.find("const REVISION = '" + revision + "'") !=
            std::string::npos)
    << ", OrbitControls: "
    << ok(page->body.find(R"("imports": { "three": "/three.module.js" })") !=
            std::string::npos &&
          page->body.find("from \"/OrbitControls.js\"") != std::string::npos &&
          orbit && orbit->status == 200 &&
          orbit->body.find("class OrbitControls extends Controls") !=
            std::string::npos &&
          orbit->body.find("from 'three'") != std::string::npos)
    << ", surface: "
    << ok(mesh && numbers(mesh->body, "vertices").size() ==
                    3 * body.n_surface_vertices())
    << " (" << body.n_surface_vertices() << " vertices)" << std::endl;

  // The node numbers: the generator's beam numbers its nodes as deal.II
  // does (the active node is 87, its index among the surface's vertices
  // 68); the file's own numbering is checked on a Gmsh file below.
  const long reported = reported_active_node(server.interaction());
  // Each surface vertex's number is the mesh's node at its place (the
  // places come with 9 digits).
  const auto ids    = numbers(mesh->body, "nodes");
  const auto places = numbers(mesh->body, "vertices");
  bool       numbered =
    ids.size() == body.n_surface_vertices() && places.size() == 3 * ids.size();
  for (std::size_t i = 0; numbered && i < ids.size(); ++i)
    {
      const auto v = body.vertex_of_node_id(std::lround(ids[i]));
      numbered     = v && body.on_surface()[*v] &&
                 palpate::Utilities::distance(body.vertices()[*v],
                                              {{places[3 * i],
                                                places[3 * i + 1],
                                                places[3 * i + 2]}}) < 1e-9;
    }
  const auto normal = numbers(mesh->body, "normal");
  deallog << "the active node /mesh and /frame name is the scene report's: "
          << ok(reported >= 0 && integer(mesh->body, "active") == reported &&
                integer(client.Get("/frame")->body, "active") == reported)
          << " (node " << reported << "), the surface vertices' numbers are "
          << "the mesh's: " << ok(numbered)
          << ", the normal there is the surface's, (1, 0, 1)/sqrt(2) at the "
             "free end's top edge (1e-9): "
          << ok(normal.size() == 3 &&
                palpate::Utilities::distance(
                  {{normal[0], normal[1], normal[2]}},
                  {{std::sqrt(0.5), 0, std::sqrt(0.5)}}) < 1e-9)
          << std::endl;

  // The initial cloud, then a target on a grid point.
  wait_until([&] { return server.interaction().initial_cloud_complete(); },
             120,
             "the initial cloud",
             std::chrono::milliseconds(20));
  const auto                &grid   = server.interaction().grid();
  const auto                 point  = grid.linear({{0, 0, -1}});
  const auto                 target = grid.position(point);
  palpate::Utilities::Point3 hip, force;
  server.last(hip, force);
  const auto from    = hip;
  const auto sent_at = std::chrono::steady_clock::now();
  const auto sent    = client.Post("/hip",
                                palpate::Utilities::to_string(target, 17),
                                palpate::LiveServer::command_type);
  // The motion, sampled: smooth (from rest, at most 1 m/s^2: within t of
  // sending, at most a t^2 / 2, with 2 ms for the request and 20 um to
  // spare; without the smoothing 5 cm/s at once) and at most 5 cm/s. Each
  // sample is taken between two clock readings: the bounds use the widest
  // interval it can stand for, so a preempted test thread cannot fail it.
  // Sampled (at least 50 times) until the probe is at the target and the
  // frame shows the state's force and the shape there: the probe can
  // arrive before the state it lands on has been computed.
  bool                smooth = true, limited = true;
  auto                previous = std::make_pair(sent_at, from);
  unsigned int        samples  = 0;
  std::string         frame;
  std::vector<double> shown;
  std::shared_ptr<const palpate::State> state;
  const auto                            shows_state = [&] {
    return state && shown.size() == 3 &&
           palpate::Utilities::distance({{shown[0], shown[1], shown[2]}},
                                        state->force) <
             1e-9 * palpate::Utilities::norm(state->force) + 1e-12;
  };
  wait_until(
    [&] {
      const auto before = std::chrono::steady_clock::now();
      server.last(hip, force);
      const auto   now = std::chrono::steady_clock::now();
      const double t   = std::chrono::duration<double>(now - sent_at).count();
      const double dt =
        std::chrono::duration<double>(now - previous.first).count();
      if (t < 0.03)
        smooth = smooth && palpate::Utilities::distance(hip, from) <=
                             0.5 * 1.0 * (t + 0.002) * (t + 0.002) + 2e-5;
      limited = limited && palpate::Utilities::distance(hip, previous.second) <=
                             0.05 * (dt + 0.002) + 1e-9;
      previous = {before, hip};
      if (++samples <= 50 || palpate::Utilities::distance(hip, target) >= 1e-12)
        return false;
      const auto f = client.Get("/frame");
      frame        = f ? f->body : "";
      shown        = numbers(frame, "force");
      state        = server.interaction().cache().state(point);
      return shows_state() && frame.find("\"shape\":true") != std::string::npos;
    },
    generous_deadline,
    "the probe at the target, showing the state's force and the shape",
    std::chrono::milliseconds(10));
  deallog << "target sent: " << ok(sent && sent->status == 200)
          << ", the probe moves smoothly: " << ok(smooth)
          << ", at most 5 cm/s: " << ok(limited) << ", reached: "
          << ok(palpate::Utilities::distance(hip, target) < 1e-12)
          << ", force shown = the state's force (1e-9): " << ok(shows_state())
          << ", shape shown: "
          << ok(frame.find("\"shape\":true") != std::string::npos) << std::endl;

  // Garbage, a flood, a silent client.
  const auto garbage =
    client.Post("/hip", "not a point", palpate::LiveServer::command_type);
  const auto nan =
    client.Post("/hip", "nan,0,0", palpate::LiveServer::command_type);
  const auto far =
    client.Post("/hip", "5,0,0", palpate::LiveServer::command_type);
  unsigned int accepted = 0;
  for (unsigned int k = 0; k < 300; ++k)
    if (const auto r =
          client.Post("/hip", "0,0,-0.001", palpate::LiveServer::command_type);
        r && r->status == 200)
      ++accepted;
  {
    httplib::Client silent("127.0.0.1", server.port());
    silent.set_connection_timeout(1, 0);
    silent.Get("/nothing-here");
  }
  const auto after = client.Get("/frame");
  deallog << "garbage refused (400): " << ok(garbage && garbage->status == 400)
          << ", NaN refused: " << ok(nan && nan->status == 400)
          << ", 5 m refused: " << ok(far && far->status == 400)
          << ", a flood of 300 targets accepted: " << ok(accepted == 300)
          << ", still serving: " << ok(after && after->status == 200)
          << std::endl;

  // On the fly: Young's modulus doubled. Back to the same target.
  const double before  = palpate::Utilities::norm(state->force);
  const auto   changed = client.Post("/material",
                                   "Young's modulus=2e5",
                                   palpate::LiveServer::command_type);
  const auto   refused = client.Post("/material",
                                   "Young's modulus=-1",
                                   palpate::LiveServer::command_type);
  const auto   unknown = client.Post("/material",
                                   "Youngs modulus=3",
                                   palpate::LiveServer::command_type);
  client.Post("/hip",
              palpate::Utilities::to_string(target, 17),
              palpate::LiveServer::command_type);
  std::shared_ptr<const palpate::State> again;
  wait_until(
    [&] {
      again = server.interaction().cache().state(point);
      return again != nullptr;
    },
    generous_deadline,
    "the state at the doubled modulus",
    std::chrono::milliseconds(50));
  deallog << "Young's modulus doubled on the fly: "
          << ok(changed && changed->status == 200)
          << ", the force doubles (1e-6): "
          << ok(again &&
                std::abs(palpate::Utilities::norm(again->force) / before - 2) <
                  1e-6)
          << "; a negative modulus refused: "
          << ok(refused && refused->status == 400 &&
                refused->body.rfind("refused", 0) == 0)
          << ", an entry the model does not have refused with its entries: "
          << ok(unknown && unknown->status == 400 &&
                unknown->body.find("its entries are: Poisson's ratio, "
                                   "Young's modulus") != std::string::npos)
          << std::endl;
  // The value in force sent again (as 200000): nothing changes, the state
  // computed at the new modulus stays in the cache.
  {
    const auto changes = server.changes().size();
    const auto same    = client.Post("/material",
                                  "Young's modulus=200000",
                                  palpate::LiveServer::command_type);
    deallog << "the modulus in force sent again: answered "
            << ok(same && same->status == 200 &&
                  same->body.find("unchanged") != std::string::npos)
            << ", not a change: " << ok(server.changes().size() == changes)
            << ", the state kept: "
            << ok(server.interaction().cache().state(point) != nullptr)
            << std::endl;
  }
  const auto picked =
    client.Post("/active", "0.1,0.01,0.01", palpate::LiveServer::command_type);
  const auto last = client.Get("/frame");
  const auto off =
    client.Post("/active", "1e200,0,0", palpate::LiveServer::command_type);
  deallog << "another active node picked: "
          << ok(picked && picked->status == 200 && last &&
                integer(last->body, "active") ==
                  reported_active_node(server.interaction()))
          << ", a point off the organ refused: "
          << ok(off && off->status == 400 &&
                off->body.find("is not on the organ") != std::string::npos)
          << std::endl;
  const auto [other, inside] = other_nodes(body, reported);
  const auto by_number       = client.Post("/active",
                                     "node " + std::to_string(other),
                                     palpate::LiveServer::command_type);
  deallog
    << "\"node N\" picks node N: "
    << ok(picked_node(by_number, client, body, other) &&
          reported_active_node(server.interaction()) == other)
    << ", a node inside refused: "
    << ok(inside >= 0 &&
          client
              .Post("/active",
                    "node " + std::to_string(inside),
                    palpate::LiveServer::command_type)
              ->body.find("is inside the body") != std::string::npos)
    << ", a number the mesh does not have refused: "
    << ok(client
            .Post("/active", "node 100000", palpate::LiveServer::command_type)
            ->body.find("the mesh has no node 100000") != std::string::npos)
    << ", \"node 3x\" refused: "
    << ok(client.Post("/active", "node 3x", palpate::LiveServer::command_type)
            ->status == 400)
    << std::endl;

  // Several clients at once, as a page's keys and clicks can come: d, a,
  // shift-click and m from four threads, three times each.
  std::atomic<unsigned int> changes_made{0}, answered{0};
  {
    std::vector<std::thread> clients;
    for (unsigned int c = 0; c < 4; ++c)
      clients.emplace_back([&, c] {
        httplib::Client each("127.0.0.1", server.port());
        each.set_default_headers(
          {{palpate::LiveServer::token_header, server.token()}});
        each.set_read_timeout(60, 0);
        for (unsigned int round = 0; round < 3; ++round)
          {
            const char *const paths[] = {"/detach",
                                         "/attach",
                                         "/active",
                                         "/material"};
            const std::string body =
              c == 2 ? (round % 2 == 0 ? "0.1,0.01,0.01" : "0.09,0,0.01") :
              c == 3 ? "Young's modulus=" + std::to_string(1 + round) + "e5" :
                       "";
            const auto r =
              each.Post(paths[c], body, palpate::LiveServer::command_type);
            answered += r ? 1 : 0;
            if (r && c >= 2 && r->status == 200)
              ++changes_made;
          }
      });
    for (auto &t : clients)
      t.join();
  }
  client.Post("/attach", "", palpate::LiveServer::command_type);
  const auto still = client.Get("/frame");
  deallog << "requests from 4 clients at once answered: "
          << ok(answered.load() == 12)
          << ", every change made: " << ok(changes_made.load() == 6)
          << ", still serving: "
          << ok(still && still->status == 200 &&
                still->body.find("\"hip\":") != std::string::npos)
          << std::endl;

  // A second server on the same port is an error that says so (cpp-httplib's
  // SO_REUSEPORT would have let it bind and share the connections).
  std::string second;
  try
    {
      palpate::LiveServer other(scene, "127.0.0.1", server.port(), 0.05);
      second = "it bound";
    }
  catch (const palpate::InputError &e)
    {
      second = e.what();
    }
  deallog << "a second server on the port refused: "
          << ok(second.find("cannot listen on 127.0.0.1:") != std::string::npos)
          << std::endl;
  server.stop();
  // Issue 28: the browser's mouse runs in the common haptic loop, and the
  // summary says so: its ticks, priority and periods, and the device. The
  // material and active-node changes above held it (HapticLoop::hold())
  // while the scene changed, and it went on after them.
  {
    palpate::RunSummary summary;
    server.add_to(summary);
    std::ostringstream printed;
    summary.print(printed);
    deallog << "the summary has the haptic loop: "
            << ok(summary.loop_ran && summary.ticks > 100 &&
                  printed.str().find("haptic loop:") != std::string::npos &&
                  printed.str().find("loop period:") != std::string::npos)
            << ", names the device: "
            << ok(summary.trajectory.find("target follower") !=
                  std::string::npos)
            << ", finite periods: "
            << ok(std::isfinite(summary.period_p50_ms) &&
                  summary.period_p50_ms > 0)
            << std::endl;
  }

  // The same beam from a Gmsh file that numbers its nodes 1000 + 7 (n - 1
  // - i): backwards, from 1000, in steps of 7, so that the file's number
  // is neither the vertex index nor the surface index. The active node's
  // number is computed here from the generator's nodes.
  {
    palpate::Scene from_file = small_beam_scene();
    const auto     data = palpate::generate_beam(from_file.parameters.mesh);
    const auto     n    = data.nodes.size();
    const auto     tag  = [&](const std::size_t i) {
      return 1000 + 7 * long(n - 1 - i);
    };
    const auto    file = std::filesystem::absolute("numbered-beam.msh");
    std::ofstream f(file);
    f << std::setprecision(17)
      << "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$Nodes\n"
      << n << "\n";
    for (std::size_t i = 0; i < n; ++i)
      f << tag(i) << " " << data.nodes[i][0] << " " << data.nodes[i][1] << " "
        << data.nodes[i][2] << "\n";
    f << "$EndNodes\n$Elements\n"
      << data.triangles.size() + data.tetrahedra.size() << "\n";
    std::size_t e = 1;
    for (std::size_t t = 0; t < data.triangles.size(); ++t, ++e)
      f << e << " 2 2 " << data.triangle_boundary_ids[t] << " "
        << data.triangle_boundary_ids[t] << " " << tag(data.triangles[t][0])
        << " " << tag(data.triangles[t][1]) << " " << tag(data.triangles[t][2])
        << "\n";
    for (const auto &t : data.tetrahedra)
      f << e++ << " 4 2 7 7 " << tag(t[0]) << " " << tag(t[1]) << " "
        << tag(t[2]) << " " << tag(t[3]) << "\n";
    f << "$EndElements\n";
    f.close();
    from_file.parameters.mesh.source       = "file";
    from_file.parameters.mesh.file_name    = file.string();
    from_file.parameters.mesh.scale_factor = 1;
    long expected                          = -1;
    for (std::size_t i = 0; i < n; ++i)
      if (palpate::Utilities::distance(
            data.nodes[i],
            from_file.parameters.boundary_conditions.active_node.point) < 1e-12)
        expected = tag(i);
    palpate::LiveServer numbered(from_file, "127.0.0.1", 0, 0.05);
    httplib::Client     to_numbered("127.0.0.1", numbered.port());
    to_numbered.set_default_headers(
      {{palpate::LiveServer::token_header, numbered.token()}});
    to_numbered.set_read_timeout(60, 0);
    const auto &m     = numbered.interaction().mesh();
    const long  named = reported_active_node(numbered.interaction());
    // The index the view gave it before: among the surface's vertices in
    // the order the surface triangles first name them.
    const long surface = [&] {
      std::map<unsigned int, long> order;
      for (const auto &face : m.surface_faces())
        for (const unsigned int v : face.vertices)
          order.emplace(v, long(order.size()));
      return order.at(numbered.interaction().nodes().active_vertex);
    }();
    const auto first_mesh  = to_numbered.Get("/mesh");
    const auto first_frame = to_numbered.Get("/frame");
    const auto other_node  = other_nodes(m, named).first;
    const auto pick        = to_numbered.Post("/active",
                                       "node " + std::to_string(other_node),
                                       palpate::LiveServer::command_type);
    deallog << "a Gmsh file's numbers: the scene report names its active "
               "node "
            << ok(named == expected) << " (node " << expected
            << ", not its vertex index "
            << numbered.interaction().nodes().active_vertex
            << " nor its index among the surface's vertices " << surface
            << "), /mesh and /frame name it: "
            << ok(integer(first_mesh->body, "active") == named &&
                  integer(first_frame->body, "active") == named)
            << ", \"node N\" picks file node N: "
            << ok(picked_node(pick, to_numbered, m, other_node) &&
                  reported_active_node(numbered.interaction()) == other_node)
            << std::endl;
    numbered.stop();
    std::filesystem::remove(file);
  }

  // The indenter in the live view: the page gets the sphere (centre at
  // rest and radius) to draw, and the force shown 2 mm into the beam is
  // the state's, pushing the probe out.
  palpate::Scene sphere                           = small_beam_scene();
  sphere.parameters.mesh.beam_subdivisions_length = 20;
  sphere.parameters.mesh.beam_subdivisions_width  = 4;
  sphere.parameters.mesh.beam_subdivisions_height = 4;
  touch_beam_with_sphere(sphere, 0.01);
  palpate::LiveServer indenter(sphere, "127.0.0.1", 0, 0.05);
  httplib::Client     to_indenter("127.0.0.1", indenter.port());
  to_indenter.set_default_headers(
    {{palpate::LiveServer::token_header, indenter.token()}});
  to_indenter.set_read_timeout(10, 0);
  const auto  drawn  = numbers(to_indenter.Get("/mesh")->body, "sphere");
  const auto &centre = indenter.interaction().nodes().sphere_center;
  deallog << "sphere: the page gets its centre and radius: "
          << ok(drawn.size() == 4 &&
                palpate::Utilities::distance({{drawn[0], drawn[1], drawn[2]}},
                                             centre) < 1e-9 &&
                drawn[3] == 0.01);
  wait_until([&] { return indenter.interaction().initial_cloud_complete(); },
             120,
             "the indenter's initial cloud",
             std::chrono::milliseconds(20));
  const auto &sphere_grid = indenter.interaction().grid();
  const auto  pressed     = sphere_grid.linear({{0, 0, -1}});
  const auto  into        = sphere_grid.position(pressed);
  to_indenter.Post("/hip",
                   palpate::Utilities::to_string(into, 17),
                   palpate::LiveServer::command_type);
  // Until the probe is there and the frame shows the state's force (the
  // force settles after the probe arrives, and the state may come later).
  std::vector<double>                   pressed_shown;
  std::shared_ptr<const palpate::State> pressed_state;
  const auto                            shows_pressed = [&] {
    return pressed_state && pressed_shown.size() == 3 &&
           palpate::Utilities::distance(
             {{pressed_shown[0], pressed_shown[1], pressed_shown[2]}},
             pressed_state->force) <
             1e-9 * palpate::Utilities::norm(pressed_state->force);
  };
  wait_until(
    [&] {
      indenter.last(hip, force);
      if (palpate::Utilities::distance(hip, into) >= 1e-12)
        return false;
      const auto f  = to_indenter.Get("/frame");
      pressed_shown = numbers(f ? f->body : "", "force");
      pressed_state = indenter.interaction().cache().state(pressed);
      return shows_pressed();
    },
    generous_deadline,
    "the probe 2 mm in, showing the state's force",
    std::chrono::milliseconds(10));
  deallog << "; 2 mm in, force shown = the state's (1e-9): "
          << ok(shows_pressed()) << ", pushing the probe out: "
          << ok(pressed_shown.size() == 3 && pressed_shown[2] > 0) << std::endl;
  // Another active node moves the sphere: the frames say where it is now
  // (the page draws it there), its centre one radius out along the
  // normal at the node, on the top face (0, 0, 1).
  const auto &body_of_indenter = indenter.interaction().mesh();
  long        top_node         = -1;
  for (unsigned int v = 0; v < body_of_indenter.n_vertices() && top_node < 0;
       ++v)
    {
      const auto &x = body_of_indenter.vertices()[v];
      if (std::abs(x[0] - 0.08) < 1e-9 && std::abs(x[1]) < 1e-9 &&
          std::abs(x[2] - 0.01) < 1e-9)
        top_node = body_of_indenter.node_id(v);
    }
  const auto moved    = to_indenter.Post("/active",
                                      "node " + std::to_string(top_node),
                                      palpate::LiveServer::command_type);
  const auto moved_to = numbers(to_indenter.Get("/frame")->body, "sphere");
  deallog << "another active node moves the sphere, and the frames say where: "
          << ok(moved && moved->status == 200 && moved_to.size() == 4 &&
                palpate::Utilities::distance(
                  {{moved_to[0], moved_to[1], moved_to[2]}},
                  indenter.interaction().nodes().sphere_center) < 1e-12 &&
                palpate::Utilities::distance(
                  {{moved_to[0], moved_to[1], moved_to[2]}},
                  {{0.08, 0, 0.02}}) < 1e-9)
          << std::endl;
  indenter.stop();
}
