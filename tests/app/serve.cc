// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

// palpate serve's server (issue 16), driven over HTTP as the page drives it,
// on the small beam:
// - the page, three.js and the surface are served (three.js's two modules,
//   the core the revision source/app/web/package.json pins); the surface
//   has the
//   mesh's surface vertices, the fixed and active nodes;
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
//   the sphere to draw, and the force shown 2 mm in is the state's.

#include <palpate/app/serve.h>
#include <palpate/haptics/interaction.h>
#include <palpate/state_space/state_cache.h>
#include <palpate/state_space/state_grid.h>

#include <httplib.h>

#include <atomic>
#include <chrono>
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
} // namespace

int
main(int argc, char **argv)
{
  palpate::Environment env(argc, argv);
  initlog();

  const palpate::Scene scene = small_beam_scene();
  palpate::LiveServer  server(scene, "127.0.0.1", 0, 0.05);
  httplib::Client      client("127.0.0.1", server.port());
  client.set_read_timeout(10, 0);

  const auto  page   = client.Get("/");
  const auto  module = client.Get("/three.module.js");
  const auto  core   = client.Get("/three.core.js");
  const auto  mesh   = client.Get("/mesh");
  const auto &body   = server.interaction().mesh();
  // "three": "0.187.0" -> revision '187'.
  const std::string pinned =
    read_file(palpate_source_dir + "/source/app/web/package.json");
  const auto        at = pinned.find("\"three\": \"0.");
  const std::string revision =
    at == std::string::npos ?
      "?" :
      pinned.substr(at + 12, pinned.find('.', at + 12) - (at + 12));
  deallog << "page served: "
          << ok(page && page->status == 200 &&
                page->body.find("from \"/three.module.js\"") !=
                  std::string::npos)
          << ", three.js: "
          << ok(module && module->status == 200 &&
                module->body.find("from './three.core.js'") !=
                  std::string::npos &&
                core && core->status == 200 &&
                core->body.find("const REVISION = '" + revision + "'") !=
                  std::string::npos)
          << ", surface: "
          << ok(mesh && numbers(mesh->body, "vertices").size() ==
                          3 * body.n_surface_vertices())
          << " (" << body.n_surface_vertices() << " vertices)" << std::endl;

  // The initial cloud, then a target on a grid point.
  const auto start = std::chrono::steady_clock::now();
  while (!server.interaction().initial_cloud_complete() &&
         std::chrono::steady_clock::now() - start < std::chrono::seconds(120))
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  const auto                &grid   = server.interaction().grid();
  const auto                 point  = grid.linear({{0, 0, -1}});
  const auto                 target = grid.position(point);
  palpate::Utilities::Point3 hip, force;
  server.last(hip, force);
  const auto from    = hip;
  const auto sent_at = std::chrono::steady_clock::now();
  const auto sent    = client.Post("/hip",
                                palpate::Utilities::to_string(target, 17),
                                "text/plain");
  // The motion, sampled: smooth (from rest, at most 1 m/s^2: within t of
  // sending, at most a t^2 / 2, with 2 ms for the request and 20 um to
  // spare; without the smoothing 5 cm/s at once) and at most 5 cm/s. Each
  // sample is taken between two clock readings: the bounds use the widest
  // interval it can stand for, so a preempted test thread cannot fail it.
  bool smooth = true, limited = true;
  auto previous = std::make_pair(sent_at, from);
  for (unsigned int k = 0; k < 200; ++k)
    {
      std::this_thread::sleep_for(std::chrono::milliseconds(10));
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
      if (palpate::Utilities::distance(hip, target) < 1e-12 && k > 50)
        break;
    }
  const auto frame = client.Get("/frame");
  const auto shown = numbers(frame->body, "force");
  const auto state = server.interaction().cache().state(point);
  deallog << "target sent: " << ok(sent && sent->status == 200)
          << ", the probe moves smoothly: " << ok(smooth)
          << ", at most 5 cm/s: " << ok(limited) << ", reached: "
          << ok(palpate::Utilities::distance(hip, target) < 1e-12)
          << ", force shown = the state's force (1e-9): "
          << ok(state && shown.size() == 3 &&
                palpate::Utilities::distance({{shown[0], shown[1], shown[2]}},
                                             state->force) <
                  1e-9 * palpate::Utilities::norm(state->force) + 1e-12)
          << ", shape shown: "
          << ok(frame->body.find("\"shape\":true") != std::string::npos)
          << std::endl;

  // Garbage, a flood, a silent client.
  const auto   garbage  = client.Post("/hip", "not a point", "text/plain");
  const auto   nan      = client.Post("/hip", "nan,0,0", "text/plain");
  const auto   far      = client.Post("/hip", "5,0,0", "text/plain");
  unsigned int accepted = 0;
  for (unsigned int k = 0; k < 300; ++k)
    if (const auto r = client.Post("/hip", "0,0,-0.001", "text/plain");
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
  const double before = palpate::Utilities::norm(state->force);
  const auto   changed =
    client.Post("/material", "Young's modulus=2e5", "text/plain");
  const auto refused =
    client.Post("/material", "Young's modulus=-1", "text/plain");
  const auto unknown =
    client.Post("/material", "Youngs modulus=3", "text/plain");
  client.Post("/hip", palpate::Utilities::to_string(target, 17), "text/plain");
  std::shared_ptr<const palpate::State> again;
  for (unsigned int k = 0; k < 1200 && !again; ++k)
    {
      std::this_thread::sleep_for(std::chrono::milliseconds(50));
      again = server.interaction().cache().state(point);
    }
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
  const auto picked = client.Post("/active", "0.1,0.01,0.01", "text/plain");
  const auto last   = client.Get("/frame");
  const auto off    = client.Post("/active", "1e200,0,0", "text/plain");
  deallog << "another active node picked: "
          << ok(picked && picked->status == 200 && last &&
                last->body.find("\"active\":") != std::string::npos)
          << ", a point off the organ refused: "
          << ok(off && off->status == 400 &&
                off->body.find("is not on the organ") != std::string::npos)
          << std::endl;

  // Several clients at once, as a page's keys and clicks can come: d, a,
  // shift-click and m from four threads, three times each.
  std::atomic<unsigned int> changes_made{0}, answered{0};
  {
    std::vector<std::thread> clients;
    for (unsigned int c = 0; c < 4; ++c)
      clients.emplace_back([&, c] {
        httplib::Client each("127.0.0.1", server.port());
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
            const auto r = each.Post(paths[c], body, "text/plain");
            answered += r ? 1 : 0;
            if (r && c >= 2 && r->status == 200)
              ++changes_made;
          }
      });
    for (auto &t : clients)
      t.join();
  }
  client.Post("/attach", "", "text/plain");
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
  to_indenter.set_read_timeout(10, 0);
  const auto  drawn  = numbers(to_indenter.Get("/mesh")->body, "sphere");
  const auto &centre = indenter.interaction().nodes().sphere_center;
  deallog << "sphere: the page gets its centre and radius: "
          << ok(drawn.size() == 4 &&
                palpate::Utilities::distance({{drawn[0], drawn[1], drawn[2]}},
                                             centre) < 1e-9 &&
                drawn[3] == 0.01);
  const auto begin = std::chrono::steady_clock::now();
  while (!indenter.interaction().initial_cloud_complete() &&
         std::chrono::steady_clock::now() - begin < std::chrono::seconds(120))
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  const auto &sphere_grid = indenter.interaction().grid();
  const auto  pressed     = sphere_grid.linear({{0, 0, -1}});
  const auto  into        = sphere_grid.position(pressed);
  to_indenter.Post("/hip",
                   palpate::Utilities::to_string(into, 17),
                   "text/plain");
  for (unsigned int k = 0; k < 300; ++k)
    {
      std::this_thread::sleep_for(std::chrono::milliseconds(10));
      indenter.last(hip, force);
      if (palpate::Utilities::distance(hip, into) < 1e-12)
        break;
    }
  std::this_thread::sleep_for(std::chrono::milliseconds(200)); // settle
  const auto pressed_frame = to_indenter.Get("/frame");
  const auto pressed_shown = numbers(pressed_frame->body, "force");
  const auto pressed_state = indenter.interaction().cache().state(pressed);
  deallog << "; 2 mm in, force shown = the state's (1e-9): "
          << ok(pressed_state && pressed_shown.size() == 3 &&
                palpate::Utilities::distance(
                  {{pressed_shown[0], pressed_shown[1], pressed_shown[2]}},
                  pressed_state->force) <
                  1e-9 * palpate::Utilities::norm(pressed_state->force))
          << ", pushing the probe out: "
          << ok(pressed_shown.size() == 3 && pressed_shown[2] > 0) << std::endl;
  indenter.stop();
}
