// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

// benchmarks/run serve [--quick|--smoke]
//
// The live view (palpate serve, issue 16) in Debian's headless Chromium with
// its software WebGL (SwiftShader: this machine has no GPU), per scene:
// - the page's frame rate (frames received per second; it asks for 30) while
//   the engine computes the initial cloud on both cores ("solving") and
//   after ("idle");
// - the server's /frame: milliseconds per request (p50, max over 200, one
//   kept-alive connection) and bytes;
// - what the open page costs the engine: the cloud computed again after a
//   material change (the cached states dropped) with the page open, against
//   the same with it closed.
// Needs the browser test's set-up (chromium, node, and puppeteer-core in
// build/browser-test: configure with -DPALPATE_BROWSER_TEST=ON, which
// ./quickstart test does).
//
// --quick: the liver at 960x640 only.
// --smoke (the test suite's): the beam, the page open for 3 s if the
// browser's set-up is there; without it (the test suite runs on machines
// without Chromium) the server's part only: the cloud computed again
// twice with no page and the 200 requests for /frame.

#include <palpate/app/serve.h>
#include <palpate/base/environment.h>
#include <palpate/haptics/interaction.h>
#include <palpate/scene/scene.h>

#include <httplib.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <iomanip>
#include <iostream>
#include <sstream>
#include <stdexcept>
#include <thread>

#include "machine.h"
#include "report_errors.h"

using namespace palpate;

namespace
{
  using Clock = std::chrono::steady_clock;

  using palpate::Utilities::seconds_since;

  struct Result
  {
    double solving_hz = 0, idle_hz = 0, solving_s = 0, idle_s = 0;
    double frame_p50_ms = 0, frame_max_ms = 0;
    // The cloud computed again (a material change) with the page closed
    // and with it open.
    double      cloud_s_closed = 0, cloud_s_open = 0;
    std::size_t frame_bytes = 0;
  };

  /** The cloud computed again after a material change, in seconds:
   * Young's modulus changed by one part in a million, another value each
   * call (the server keeps the cached states when the value in force is
   * sent again). Throws if the server did not take the change: the time
   * would then be that of no work at all. */
  double
  recompute(LiveServer &server, httplib::Client &client, const Scene &scene)
  {
    static unsigned int changes = 0;
    const auto         &m       = scene.parameters.material_model;
    const double        E       = m.get_double(m.model_name, "Young's modulus");
    std::ostringstream  body;
    body << std::setprecision(17)
         << "Young's modulus=" << E * (1 + 1e-6 * ++changes);
    const auto start = Clock::now();
    const auto reply =
      client.Post("/material", body.str(), LiveServer::command_type);
    if (!reply || reply->status != 200 ||
        reply->body.find("unchanged") != std::string::npos)
      throw std::runtime_error(
        "the live view did not take the material change '" + body.str() +
        "': " + (reply ? reply->body : std::string("no reply")));
    while (!server.interaction().initial_cloud_complete())
      std::this_thread::sleep_for(std::chrono::milliseconds(1));
    return seconds_since(start);
  }

  /** The server, its initial cloud; the cloud again without a page; the
   * page open (for @p seconds): 4 s idle, the cloud again, idle; then 200
   * requests for /frame. */
  Result
  with_view(const Scene      &scene,
            const double      seconds,
            const std::string width,
            const std::string height,
            const bool        page = true)
  {
    Result          r;
    LiveServer      server(scene, "127.0.0.1", 0);
    httplib::Client client("127.0.0.1", server.port());
    // Changes carry the run's token, as the page sends it.
    client.set_default_headers({{LiveServer::token_header, server.token()}});
    client.set_read_timeout(600, 0);
    while (!server.interaction().initial_cloud_complete())
      std::this_thread::sleep_for(std::chrono::milliseconds(1));
    r.cloud_s_closed = recompute(server, client, scene);

    const std::string command =
      "NODE_PATH='" PALPATE_BINARY_DIR
      "/browser-test/node_modules' node '" PALPATE_SOURCE_DIR
      "/benchmarks/serve-page.js' \"$(command -v chromium)\" " +
      std::to_string(server.port()) + " " + std::to_string(seconds) + " " +
      width + " " + height + " 2>&1";
    std::thread browser;
    if (page)
      browser = std::thread([&] {
        FILE *p = popen(command.c_str(), "r");
        char  line[512];
        while (p && std::fgets(line, sizeof line, p))
          {
            double a = 0, b = 0, c = 0, d = 0;
            if (std::sscanf(line, "PAGE %lf %lf %lf %lf", &a, &b, &c, &d) == 4)
              {
                r.solving_hz = b > 0 ? a / b : 0;
                r.solving_s  = b;
                r.idle_hz    = d > 0 ? c / d : 0;
                r.idle_s     = d;
              }
            else
              std::cerr << "  browser: " << line;
          }
        if (p)
          pclose(p);
      });
    if (page)
      std::this_thread::sleep_for(std::chrono::seconds(4));
    r.cloud_s_open = recompute(server, client, scene);
    if (browser.joinable())
      browser.join();

    client.set_keep_alive(true);
    std::vector<double> ms;
    for (unsigned int k = 0; k < 200; ++k)
      {
        const auto t     = Clock::now();
        const auto frame = client.Get("/frame");
        ms.push_back(1000 * seconds_since(t));
        if (frame)
          r.frame_bytes = frame->body.size();
      }
    std::sort(ms.begin(), ms.end());
    r.frame_p50_ms = ms[ms.size() / 2];
    r.frame_max_ms = ms.back();
    server.stop();
    return r;
  }
} // namespace

static int
run_benchmark(int argc, char **argv)
{
  Environment env(argc, argv);
  bool        quick = false, smoke = false;
  for (int i = 1; i < argc; ++i)
    if (std::string(argv[i]) == "--quick")
      quick = true;
    else if (std::string(argv[i]) == "--smoke")
      smoke = true;
    else
      {
        std::cerr << "usage: benchmarks/run serve [--quick|--smoke]\n";
        return 2;
      }
  const bool browser =
    std::filesystem::exists(PALPATE_BINARY_DIR
                            "/browser-test/node_modules/puppeteer-core") &&
    std::system("command -v chromium >/dev/null && command -v node "
                ">/dev/null") == 0;
  if (!browser && !smoke)
    {
      std::cerr << "benchmarks/run serve needs headless Chromium, node and "
                   "puppeteer-core in build/browser-test: apt-get install "
                   "chromium nodejs npm, then cmake -S . -B build "
                   "-DPALPATE_BROWSER_TEST=ON (./quickstart test does both)."
                << std::endl;
      return 1;
    }

  std::cout << "palpate serve in headless Chromium (software WebGL), "
            << machine() << (smoke ? " [--smoke]" : "") << "\n";
  if (!browser)
    std::cout << "  no browser (headless Chromium, node, puppeteer-core in "
                 "build/browser-test): the server's part only\n";
  std::cout << "\n";
  struct Config
  {
    std::string scene, width, height;
    double      seconds;
  };
  std::vector<Config> configs = {{"paper-stvk", "960", "640", 16}};
  if (smoke)
    configs = {{"beam", "960", "640", 3}};
  else if (!quick)
    configs = {{"beam", "960", "640", 10},
               {"paper-stvk", "960", "640", 16},
               {"paper-stvk", "1200", "800", 16}};

  std::vector<std::string> results;
  std::cout << std::left << std::setw(12) << "scene" << std::setw(10) << "view"
            << std::right << std::setw(12) << "solving Hz" << std::setw(10)
            << "idle Hz" << std::setw(12) << "frame ms" << std::setw(10)
            << "max ms" << std::setw(10) << "bytes" << std::setw(12)
            << "cloud s" << std::setw(14) << "page closed s" << std::setw(10)
            << "cost %"
            << "\n";
  for (const auto &c : configs)
    {
      const Scene  scene = Scene::read(std::string(PALPATE_SOURCE_DIR) +
                                      "/parameters/" + c.scene + ".prm");
      const Result r = with_view(scene, c.seconds, c.width, c.height, browser);
      const double cost = 100 * (r.cloud_s_open / r.cloud_s_closed - 1);
      std::cout << std::left << std::setw(12) << c.scene << std::setw(10)
                << (c.width + "x" + c.height) << std::right << std::fixed
                << std::setprecision(1) << std::setw(12) << r.solving_hz
                << std::setw(10) << r.idle_hz << std::setprecision(2)
                << std::setw(12) << r.frame_p50_ms << std::setw(10)
                << r.frame_max_ms << std::setw(10) << r.frame_bytes
                << std::setw(12) << r.cloud_s_open << std::setw(14)
                << r.cloud_s_closed << std::setprecision(1) << std::setw(10)
                << cost << "\n"
                << std::defaultfloat;
      std::ostringstream line;
      line << "RESULT serve scene=" << c.scene << " view=" << c.width << "x"
           << c.height << " solving_hz=" << r.solving_hz
           << " solving_s=" << r.solving_s << " idle_hz=" << r.idle_hz
           << " idle_s=" << r.idle_s << " frame_ms_p50=" << r.frame_p50_ms
           << " frame_ms_max=" << r.frame_max_ms
           << " frame_bytes=" << r.frame_bytes
           << " cloud_again_s_page_open=" << r.cloud_s_open
           << " cloud_again_s_page_closed=" << r.cloud_s_closed
           << " view_cost_pct=" << cost
           << " idle_20hz=" << (r.idle_hz >= 20 ? "yes" : "no");
      results.push_back(line.str());
    }
  std::cout << "\n";
  for (const auto &line : results)
    std::cout << line << "\n";
  return 0;
}



int
main(int argc, char **argv)
{
  return report_errors("serve", run_benchmark, argc, argv);
}
