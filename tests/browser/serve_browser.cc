// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

// palpate serve's page in a real browser (issue 16): Debian's headless
// Chromium, driven by puppeteer-core (drive.js), loads the page served for
// the small beam and is used as a person would use it. Checked here, against
// the API:
// - the first view looks at the probe against the outward normal at the
//   active node (0.01 degree), the probe in the middle of the screen
//   (0.001 of its half-width) and the whole surface in the picture; the
//   active node the page names (from /mesh, the frames and its text) is
//   the one the scene report names, in the mesh's numbering;
// - the camera turns through real mouse events (three.js's OrbitControls):
//   a left drag of 120 pixels off the organ turns it by 120 / 640 of a
//   turn, 67.5 degrees, and a right drag of 60 pixels up that starts on
//   the probe by 33.75 (0.1 degree each), neither moving the probe; the
//   wheel (twice 200) zooms in to 0.95^4 of the distance, a middle drag
//   pans the point it turns about by what the pixels span at its depth
//   (1e-6 each, the direction kept); f centres the view on the probe
//   (0.001 of the screen's half-width, from 0.1 or more off), keeping
//   direction and distance;
// - the drag on the probe in the view turned moves the target down the
//   screen (the camera's -up) by what the pixels span at the probe (1e-6);
// - frames reach the page at 10 Hz or more while the mouse drags the probe,
//   and the server answers a /frame in less than 40 ms;
// - once the probe rests, the force the page holds is the force
//   Interaction::force() returned at that HIP (the device thread's last
//   call, 1e-9 relative) and the trilinear blend of the 8 corner states
//   computed here (1e-9 relative), the force the page prints is it to its
//   3 decimals, and the HIP is the target the drag sent;
// - the cloud around the probe is computed (it followed the probe), and the
//   engine's load is shown;
// - the m key's prompt changes Young's modulus on the fly to twice its
//   value: the force at the same HIP doubles (St.Venant-Kirchhoff, 1e-6);
// - d and a detach and attach; a drag with Alt held, or with the page's
//   depth button on, moves the probe in depth (along the camera's axis,
//   1e-6); shift-click picks another active node: the node, as the mesh
//   numbers it, of the vertex clicked, which the page names and the server
//   then has; v brings back the first view;
// - a reloaded page (a client that leaves and comes back) is served;
// - a page of another site (a second HTTP server on another port, under
//   the name evil.test, which the browser resolves to this machine) cannot
//   change the model nor read it: its POST of text/plain (as a script may
//   send it without asking) and its no-cors POST reach the server and are
//   refused (counted by the server), the answers hidden from it (CORS;
//   for no-cors, Cross-Origin-Resource-Policy); its POST with the
//   live view's headers is never sent (the CORS preflight is refused); its
//   read of /frame is blocked (no CORS header); the view does not show in
//   its frame; its form's POST is answered with the refusal. Through DNS
//   rebinding (evil.test on the live view's port) the page, /frame and a
//   POST are refused (403). Young's modulus is still the page's 2e5, and
//   the changes the server recorded are the page's four, in order;
// - the view is drawn (more than 5 % of its pixels are not background) and
//   a screenshot is kept: PALPATE_ARTEFACT_DIR/live-view.png.

#include <palpate/app/scene_report.h>
#include <palpate/app/serve.h>
#include <palpate/haptics/interaction.h>
#include <palpate/mesh/mesh.h>
#include <palpate/state_space/state_cache.h>
#include <palpate/state_space/state_grid.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include "../tests.h"

namespace
{
  /** The numbers in @p text (commas, parentheses, "=" and words skipped). */
  std::vector<double>
  numbers_in(std::string text)
  {
    for (char &c : text)
      if (c == ',' || c == '(' || c == ')' || c == '=' || c == '|')
        c = ' ';
    std::istringstream  s(text);
    std::vector<double> v;
    std::string         word;
    while (s >> word)
      try
        {
          std::size_t  used = 0;
          const double x    = std::stod(word, &used);
          if (used == word.size())
            v.push_back(x);
        }
      catch (const std::exception &)
        {}
    return v;
  }

  palpate::Utilities::Point3
  point(const std::vector<double> &v, const std::size_t first = 0)
  {
    return {{v.at(first), v.at(first + 1), v.at(first + 2)}};
  }

  /** The force at @p x blended from the states at the 8 corners of its
   * grid cell, with trilinear weights computed here (not by palpate's
   * interpolation): false if a corner is not computed. */
  bool
  blend_corners(const palpate::Interaction       &interaction,
                const palpate::Utilities::Point3 &x,
                palpate::Utilities::Point3       &f)
  {
    const auto        &grid = interaction.grid();
    const double       h    = grid.spacing();
    palpate::GridIndex lower;
    double             t[3];
    for (unsigned int k = 0; k < 3; ++k)
      {
        lower[k] = static_cast<int>(std::floor(x[k] / h));
        t[k]     = x[k] / h - lower[k];
      }
    f = {{0, 0, 0}};
    for (unsigned int c = 0; c < 8; ++c)
      {
        palpate::GridIndex g = lower;
        double             w = 1;
        for (unsigned int k = 0; k < 3; ++k)
          {
            const bool up = (c >> k) & 1;
            g[k] += up;
            w *= up ? t[k] : 1 - t[k];
          }
        if (!grid.contains(g))
          return false;
        const auto state = interaction.cache().state(grid.linear(g));
        if (!state || !state->converged)
          return false;
        for (unsigned int k = 0; k < 3; ++k)
          f[k] += w * state->force[k];
      }
    return true;
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

  /** Whether @p v has an entry @p i, and it is @p expected within @p
   * tolerance. */
  bool
  near(const std::vector<double> &v,
       const std::size_t          i,
       const double               expected,
       const double               tolerance)
  {
    return v.size() > i && std::abs(v[i] - expected) <= tolerance;
  }
} // namespace

int
main(int argc, char **argv)
{
  palpate::Environment env(argc, argv);
  initlog();

  const palpate::Scene scene = small_beam_scene();
  palpate::LiveServer  server(scene, "127.0.0.1", 0, 0.05);
  // The active node as the scene report names it (`palpate SCENE.prm`).
  const long reported = reported_active_node(server.interaction());

  const std::filesystem::path artefacts(PALPATE_ARTEFACT_DIR);
  std::filesystem::create_directories(artefacts);
  const std::filesystem::path screenshot = artefacts / "live-view.png";
  std::filesystem::remove(screenshot);
  const std::string command =
    "NODE_PATH='" PALPATE_NODE_MODULES "' '" PALPATE_NODE
    "' '" PALPATE_SOURCE_DIR "/tests/browser/drive.js' '" PALPATE_CHROMIUM
    "' " +
    std::to_string(server.port()) + " '" + screenshot.string() + "' 2>&1";
  FILE *browser = popen(command.c_str(), "r");
  AssertThrow(browser != nullptr, dealii::ExcMessage("cannot run " + command));

  // The browser's lines as they come: KEY value...; the check of the force
  // against the API is made as soon as the page reports it, while the
  // probe rests there.
  std::map<std::string, std::string> seen;
  std::string                        log;
  palpate::Utilities::Point3         api_hip{{0, 0, 0}}, api_force{{0, 0, 0}};
  palpate::Utilities::Point3         blended{{0, 0, 0}};
  bool                               have_blend = false;
  char                               buffer[4096];
  while (std::fgets(buffer, sizeof buffer, browser) != nullptr)
    {
      std::string line(buffer);
      log += line;
      if (!line.empty() && line.back() == '\n')
        line.pop_back();
      const auto space = line.find(' ');
      const auto key   = line.substr(0, space);
      seen[key] = space == std::string::npos ? "" : line.substr(space + 1);
      if (key == "TARGET")
        {
          server.last(api_hip, api_force);
          have_blend = blend_corners(server.interaction(), api_hip, blended);
        }
    }
  const int status = pclose(browser);

  const auto value = [&](const std::string &key) {
    const auto it = seen.find(key);
    return it == seen.end() ? std::string() : it->second;
  };
  const bool complete = status == 0 && seen.count("PAGE_ERRORS") > 0;
  deallog << "the browser drove the page to the end: " << ok(complete)
          << std::endl;
  // What the browser saw, for the log (not compared: it varies).
  std::cout << "drive.js said:\n" << log << std::endl;

  const auto first = numbers_in(value("FIRST_VIEW"));
  const auto named = numbers_in(value("ACTIVE_NODE"));
  deallog << "the first view looks at the probe against the outward normal "
             "at the active node: "
          << ok(near(first, 0, 0, 0.01))
          << ", the probe in the middle: " << ok(near(first, 1, 0, 0.001))
          << ", the whole organ in the view: "
          << ok(value("FIRST_VIEW").find(" yes") != std::string::npos)
          << std::endl;
  deallog << "the active node the page names (/mesh, frame, text) is the "
             "scene report's: "
          << ok(named.size() == 3 && reported >= 0 && named[0] == reported &&
                named[1] == reported && named[2] == reported)
          << " (node " << reported << ")" << std::endl;
  // 120 and 60 pixels of a 640-pixel-high view: 120 / 640 and 60 / 640 of
  // a turn (OrbitControls' rotateSpeed 1).
  const auto orbit = numbers_in(value("ORBIT"));
  const auto zoom  = numbers_in(value("ZOOM"));
  const auto pan   = numbers_in(value("PAN"));
  const auto look  = numbers_in(value("LOOK_AT_PROBE"));
  deallog << "a left drag off the organ turns the view by 67.5 degrees: "
          << ok(near(orbit, 0, 67.5, 0.1) &&
                value("ORBIT").find("from_background") != std::string::npos)
          << ", a right drag on the probe by 33.75: "
          << ok(near(orbit, 1, 33.75, 0.1))
          << ", neither moves the probe: " << ok(near(orbit, 2, 0, 0))
          << std::endl;
  deallog << "the wheel zooms to 0.95^4 of the distance: "
          << ok(near(zoom, 0, std::pow(0.95, 4), 1e-6) &&
                near(zoom, 1, 0, 1e-4))
          << ", a middle drag pans by what its pixels span: "
          << ok(near(pan, 0, 1, 1e-6) && near(pan, 1, 0, 1e-4)) << std::endl;
  deallog << "f centres the view on the probe: "
          << ok(look.size() == 4 && look[0] > 0.1 && look[1] < 0.001)
          << ", from the same direction and distance: "
          << ok(near(look, 2, 0, 1e-4) && near(look, 3, 1, 1e-9)) << std::endl;
  const auto dragged = numbers_in(value("DRAG"));
  deallog << "the drag on the probe in the turned view moves it down the "
             "screen: "
          << ok(near(dragged, 0, 1, 1e-6))
          << ", by what the pixels span at the probe: "
          << ok(near(dragged, 1, 1, 1e-6)) << std::endl;

  // The page asks every 33 ms; what it gets depends on the machine's load
  // (its software renderer and the solvers share two cores: it fell below
  // 20 Hz in a CI run beside other tests). Frames keep coming while the mouse
  // drags (10 Hz or more), and the server answers a /frame in less than
  // Nagle's 40 ms stall (the median of 21).
  const auto rate = numbers_in(value("RATE"));
  const auto trip = numbers_in(value("FRAME_TRIP"));
  deallog << "frames at 10 Hz or more during the drag: "
          << ok(!rate.empty() && rate[0] >= 10)
          << ", each /frame answered in less than 40 ms: "
          << ok(!trip.empty() && trip[0] < 40) << std::endl;

  const auto hip    = numbers_in(value("HIP"));
  const auto target = numbers_in(value("TARGET"));
  const auto force  = numbers_in(value("FORCE"));
  const auto text   = numbers_in(value("FORCE_TEXT"));
  const bool have = hip.size() == 3 && target.size() == 3 && force.size() == 3;
  if (have)
    {
      const double f = palpate::Utilities::norm(api_force);
      deallog
        << "the probe rests at the dragged target: "
        << ok(palpate::Utilities::distance(point(hip), point(target)) < 1e-9 &&
              palpate::Utilities::norm(point(target)) > 1e-4)
        << ", the HIP is the API's: "
        << ok(palpate::Utilities::distance(point(hip), api_hip) < 1e-12)
        << ", the force the page holds is the API's there (1e-9): "
        << ok(f > 1e-3 &&
              palpate::Utilities::distance(point(force), api_force) < 1e-9 * f)
        << ", and the blend of its cell's corner states (1e-9): "
        << ok(have_blend &&
              palpate::Utilities::distance(point(force), blended) < 1e-9 * f)
        << std::endl;
      bool printed = text.size() == 4;
      for (unsigned int k = 0; printed && k < 3; ++k)
        printed = std::abs(text[k] - api_force[k]) <= 0.0005 + 1e-12;
      deallog << "the force printed is the API's to 3 decimals: " << ok(printed)
              << ", and its magnitude: "
              << ok(text.size() == 4 && std::abs(text[3] - f) <= 0.0005 + 1e-12)
              << std::endl;
    }
  else
    deallog << "the page reported its HIP and force: NO" << std::endl;

  // Status counts: not computed, computed, failed, being computed.
  const auto cloud = numbers_in(value("CLOUD"));
  const auto load  = numbers_in(value("LOAD"));
  deallog << "the cloud around the probe is computed: "
          << ok(cloud.size() == 4 && cloud[1] > 10 && cloud[0] == 0 &&
                cloud[3] == 0)
          << ", the engine's load shown: "
          << ok(load.size() == 3 && load[0] == 2 &&
                value("ENGINE_TEXT").find("workers solving") !=
                  std::string::npos)
          << std::endl;

  const auto after = numbers_in(value("FORCE_AFTER_MATERIAL"));
  deallog << "m's prompt names the model and its constants: "
          << ok(value("PROMPT").find("St.Venant-Kirchhoff") !=
                  std::string::npos &&
                value("PROMPT").find("Young's modulus=") != std::string::npos)
          << std::endl;
  deallog << "m changed Young's modulus: "
          << ok(value("MATERIAL_TEXT").find("Young's modulus") !=
                  std::string::npos &&
                value("MATERIAL_TEXT").rfind("refused", 0) != 0)
          << ", the force at the same HIP doubled (1e-6): "
          << ok(have && after.size() == 3 &&
                std::abs(palpate::Utilities::norm(point(after)) /
                           palpate::Utilities::norm(point(force)) -
                         2) < 1e-6)
          << std::endl;

  // Old, new (the frame's), the node of the vertex clicked, the page's
  // text, and the reply "node N at (...) mm".
  const auto active = numbers_in(value("ACTIVE"));
  const auto depth  = numbers_in(value("DEPTH"));
  const auto button = numbers_in(value("DEPTH_BUTTON"));
  const auto again  = numbers_in(value("FIRST_VIEW_AGAIN"));
  deallog
    << "d and a detached and attached: " << ok(value("DETACH_ATTACH") == "yes")
    << ", a drag with Alt moved the probe in depth: "
    << ok(near(depth, 0, 1, 1e-6) && depth.size() > 1 && depth[1] > 0.2)
    << ", and with the depth button: "
    << ok(near(button, 0, 1, 1e-6) && button.size() > 1 && button[1] > 0.2 &&
          value("DEPTH_BUTTON").find("drag in depth: off") != std::string::npos)
    << std::endl;
  deallog << "shift-click picked the node of the vertex clicked: "
          << ok(active.size() >= 5 && active[0] != active[1] &&
                active[1] == active[2] && active[3] == active[1] &&
                value("ACTIVE").find("active node: node " +
                                     std::to_string(long(active[2])) +
                                     " at (") != std::string::npos)
          << ", the server's active node: "
          << ok(active.size() >= 2 &&
                reported_active_node(server.interaction()) == active[1])
          << ", v brings back the first view: "
          << ok(near(again, 0, 0, 1e-9) && near(again, 1, 0, 1e-9))
          << ", a reloaded page is served: "
          << ok(value("RECONNECTED") == "yes") << std::endl;

  // The other site's attempts, as it saw them, and as the server counted
  // them.
  std::vector<std::string> attempts;
  {
    std::istringstream words(value("OTHER_SITE"));
    std::string        word;
    while (words >> word)
      attempts.push_back(word);
  }
  const auto refused = server.refused();
  const auto count   = [&](const std::string &kind) {
    const auto it = refused.find(kind);
    return it == refused.end() ? 0u : it->second;
  };
  deallog << "a page of another site: its POSTs refused (a script's and a "
             "no-cors one, their answers hidden from it): "
          << ok(attempts.size() == 5 && attempts[0] == "blocked" &&
                attempts[1] == "blocked" && count("Origin") >= 3)
          << ", its POST with the live view's headers never sent (the "
             "preflight refused): "
          << ok(attempts.size() == 5 && attempts[2] == "blocked" &&
                count("preflight") >= 1)
          << ", its read of /frame blocked: "
          << ok(attempts.size() == 5 && attempts[3] == "blocked")
          << ", the view not shown in its frame: "
          << ok(attempts.size() == 5 && attempts[4] == "not_shown")
          << std::endl;
  deallog << "its form's POST answered with the refusal: "
          << ok(value("OTHER_SITE_FORM")
                  .rfind("refused: a change sent by a page of another site "
                         "(Origin: http://evil.test:",
                         0) == 0)
          << "; by DNS rebinding the page, /frame and a change refused (403): "
          << ok(value("REBINDING") == "status_403 status_403 status_403" &&
                count("Host") >= 3)
          << std::endl;
  const auto  made     = server.changes();
  const auto &material = server.interaction().scene().parameters.material_model;
  deallog << "Young's modulus still the page's 2e5: "
          << ok(value("YOUNGS_MODULUS") == "2e5 2e5" &&
                material.get_double(material.model_name, "Young's modulus") ==
                  2e5)
          << ", the changes the server recorded are the page's four, in "
             "order: "
          << ok(made.size() == 4 &&
                made[0].what == "Young's modulus 100000 -> 200000 Pa" &&
                made[1].what == "detached (the force fades to zero)" &&
                made[2].what == "attached" &&
                made[3].what.rfind("active node: node " +
                                     std::to_string(reported) + " at (",
                                   0) == 0)
          << std::endl;

  const auto drawn = numbers_in(value("DRAWN"));
  deallog << "the view is drawn: " << ok(!drawn.empty() && drawn[0] > 0.05)
          << ", the screenshot is kept: "
          << ok(std::filesystem::exists(screenshot) &&
                std::filesystem::file_size(screenshot) > 10000)
          << ", page errors: " << value("PAGE_ERRORS") << std::endl;
  server.stop();
}
