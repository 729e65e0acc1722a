// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

// A thread that fails reports and shuts down cleanly; it never takes the
// process down (std::terminate) while a device renders forces:
// - the thread engine's scheduler throws at its 3rd plan (an injected
//   fault): the error is counted and named in the statistics, the engine
//   stops and reports idle, stop() returns, and attaching again computes
//   the cloud;
// - the shape output's directory is replaced by a file in mid-run: the
//   shape thread stops with the error, the frames written before it stay
//   listed in the PVD file, and the interaction goes on;
// - the disk fills during the shape output (a file size limit): the thread
//   stops at the first frame that could not be written and removes it;
//   the count, the frame files and the PVD index agree.

#include <palpate/engine/hip_channel.h>
#include <palpate/engine/thread_engine.h>
#include <palpate/haptics/interaction.h>
#include <palpate/haptics/shape_interpolator.h>
#include <palpate/mesh/mesh.h>
#include <palpate/mesh/node_selection.h>
#include <palpate/state_space/state_cache.h>
#include <palpate/state_space/state_grid.h>

#include <sys/resource.h>

#include <chrono>
#include <csignal>
#include <filesystem>
#include <thread>

#include "../tests.h"

namespace
{
  /** What a ThreadEngine works on: a body, a grid, a cache, a HIP. */
  struct Rig
  {
    explicit Rig(const palpate::Scene &scene)
      : body(scene)
      , grid(scene.parameters.state_space.grid_spacing,
             scene.parameters.state_space.extent)
      , cache(grid, 1 << 28)
    {}

    Body                body;
    palpate::StateGrid  grid;
    palpate::StateCache cache;
    palpate::HipChannel hip;
  };
} // namespace

int
main(int argc, char **argv)
{
  palpate::Environment env(argc, argv);
  initlog();

  palpate::Scene scene = small_beam_scene();
  auto          &p     = scene.parameters;

  {
    deallog << "--- the scheduler throws at its 3rd plan" << std::endl;
    Rig                   rig(scene);
    auto                 &cache = rig.cache;
    const auto           &grid  = rig.grid;
    palpate::EngineFaults faults;
    faults.scheduler_throws_at_plan = 3;
    palpate::ThreadEngine engine(
      rig.body.mesh, rig.body.nodes, p, grid, cache, rig.hip, faults);
    engine.start();
    const bool idle =
      wait_until([&] { return engine.idle(); }, 60, "the engine to be idle");
    const auto stats = engine.statistics();
    deallog << "engine idle after the fault: " << (idle ? "yes" : "NO")
            << ", running: " << (engine.running() ? "YES" : "no")
            << ", errors: " << stats.errors << " (" << stats.last_error << ")"
            << std::endl;
    engine.stop();
    deallog << "stop() returned" << std::endl;

    unsigned int cloud = 0; // grid points within the radius of the origin
    for (unsigned int q = 0; q < grid.size(); ++q)
      cloud +=
        palpate::Utilities::norm(grid.position(q)) <= p.scheduler.cloud_radius;
    engine.start();
    const bool computed = wait_until(
      [&] {
        return engine.idle() &&
               cache.counts().first + cache.counts().second >= cloud;
      },
      300,
      "the cloud computed again");
    engine.stop();
    deallog << "attached again: the cloud of " << cloud << " points is "
            << (computed ? "computed" : "NOT computed")
            << ", errors still: " << engine.statistics().errors << std::endl;
  }

  {
    deallog << "--- every worker throws in every task" << std::endl;
    Rig                   rig(scene);
    auto                 &cache = rig.cache;
    const auto           &grid  = rig.grid;
    palpate::EngineFaults faults;
    faults.workers_throw = true;
    palpate::ThreadEngine engine(
      rig.body.mesh, rig.body.nodes, p, grid, cache, rig.hip, faults);
    engine.start();
    const bool idle =
      wait_until([&] { return engine.idle(); }, 60, "the engine to be idle");
    engine.stop();
    const auto stats = engine.statistics();
    deallog << "engine idle: " << (idle ? "yes" : "NO") << "; every task a "
            << "failure point with its error counted: "
            << (stats.errors > 0 && stats.errors == stats.failed &&
                    stats.computed == 0 &&
                    cache.counts().second == stats.failed ?
                  "yes" :
                  "NO")
            << " (" << stats.last_error.substr(0, 30) << "...)" << std::endl;
  }

  {
    deallog << "--- the shape output's directory disappears in mid-run"
            << std::endl;
    std::filesystem::remove_all("shapes");
    palpate::Interaction interaction(scene);
    interaction.attach();
    const bool cloud =
      wait_until([&] { return interaction.initial_cloud_complete(); },
                 300,
                 "the initial cloud");
    palpate::ShapeInterpolator shape(interaction, 50, "shapes", "beam");
    shape.start();
    // Frames are written while the probe moves: move it.
    unsigned int step = 0;
    const auto   move = [&] {
      interaction.force({{1e-5 * (++step % 20), 0, 0}});
    };
    const bool some = wait_until(
      [&] {
        move();
        return shape.frames().first >= 3;
      },
      60,
      "three frames");
    std::filesystem::remove_all("shapes");
    write_file("shapes", "a file where the directory was\n");
    // The probe keeps moving until the thread meets the missing directory
    // (its next frame), and then for 20 more moves, frames that would be
    // written if it went on.
    const bool failed = wait_until(
      [&] {
        move();
        return shape.failed();
      },
      generous_deadline,
      "the shape thread to fail on the missing directory",
      std::chrono::milliseconds(10));
    const unsigned int before = shape.frames().first;
    for (unsigned int k = 0; k < 20; ++k)
      {
        move();
        std::this_thread::sleep_for(std::chrono::milliseconds(10));
      }
    const bool stopped_writing = failed && shape.frames().first == before;
    shape.stop();
    const palpate::Utilities::Point3 f = interaction.force({{0, 0, 0}});
    interaction.detach();
    deallog << "initial cloud: " << (cloud ? "yes" : "NO")
            << ", frames written before: " << (some ? ">= 3" : "FEWER")
            << ", no more frames after: " << (stopped_writing ? "yes" : "NO")
            << std::endl;
    const std::string &failure = shape.failure();
    deallog << "failure reported: "
            << (failure.find("cannot write the file 'shapes/beam-shape-") !=
                    std::string::npos ?
                  "yes, naming the frame's file" :
                  "NO: '" + failure + "'")
            << std::endl;
    deallog << "the interaction still answers: force at rest "
            << (all_finite(f) ? "finite" : "NOT FINITE") << std::endl;
    std::filesystem::remove("shapes");
  }

  {
    // A full disk, as a file size limit (RLIMIT_FSIZE) below a frame's
    // size set in mid-run: writes of frames fail (EFBIG), small files such
    // as the index still fit. Before, the failed write went unnoticed: the
    // count went on, cut and empty frames were left, and the index listed
    // them.
    deallog << "--- the disk fills during the shape output" << std::endl;
    std::filesystem::remove_all("full");
    palpate::Interaction interaction(scene);
    interaction.attach();
    wait_until([&] { return interaction.initial_cloud_complete(); },
               300,
               "the initial cloud");
    palpate::ShapeInterpolator shape(interaction, 50, "full", "beam");
    shape.start();
    unsigned int step = 0;
    const auto   move = [&] {
      interaction.force({{1e-5 * (++step % 20), 0, 0}});
    };
    const bool some = wait_until(
      [&] {
        move();
        return shape.frames().first >= 3;
      },
      60,
      "three frames");
    const auto frame_size =
      std::filesystem::file_size("full/beam-shape-00000.vtu");
    std::signal(SIGXFSZ, SIG_IGN);
    rlimit old_limit{};
    getrlimit(RLIMIT_FSIZE, &old_limit);
    rlimit full   = old_limit;
    full.rlim_cur = frame_size / 2;
    setrlimit(RLIMIT_FSIZE, &full);
    // Moving until a frame could not be written.
    wait_until(
      [&] {
        move();
        return shape.failed();
      },
      generous_deadline,
      "the shape thread to fail on the full disk",
      std::chrono::milliseconds(10));
    shape.stop();
    setrlimit(RLIMIT_FSIZE, &old_limit);
    interaction.detach();

    unsigned int on_disk = 0, whole = 0;
    for (const auto &f : std::filesystem::directory_iterator("full"))
      if (f.path().extension() == ".vtu")
        {
          ++on_disk;
          const std::string text = read_file(f.path().string());
          whole += text.size() == frame_size ||
                   text.find("</VTKFile>") != std::string::npos;
        }
    const std::string  pvd    = read_file("full/beam-shape.pvd");
    unsigned int       listed = 0;
    const unsigned int count  = shape.frames().first;
    for (auto at = pvd.find("<DataSet"); at != std::string::npos;
         at      = pvd.find("<DataSet", at + 1))
      ++listed;
    deallog << "frames before the disk filled: " << (some ? ">= 3" : "FEWER")
            << " (a frame is larger than 8 KiB: " << ok(frame_size > 8192)
            << ")" << std::endl;
    deallog << "frames counted = frame files on disk = frames in the index: "
            << ok(count == on_disk && on_disk == listed && count >= 3)
            << ", every file a whole frame: " << ok(whole == on_disk)
            << ", index closed: "
            << ok(pvd.find("</VTKFile>") != std::string::npos) << std::endl;
    if (count != on_disk || on_disk != listed)
      deallog << "  (" << count << " counted, " << on_disk << " on disk, "
              << listed << " listed)" << std::endl;
    const std::string &failure = shape.failure();
    deallog << "failure names the frame and the cause: "
            << ok(failure.find("cannot write the file 'full/beam-shape-") !=
                    std::string::npos &&
                  failure.find("File too large") != std::string::npos)
            << std::endl;
    if (failure.find("File too large") == std::string::npos)
      deallog << "  ('" << failure << "')" << std::endl;
    std::filesystem::remove_all("full");
  }

  {
    deallog << "--- the shape output reaches its limit (Effects / Shape "
               "output limit)"
            << std::endl;
    std::filesystem::remove_all("limited");
    palpate::Interaction interaction(scene);
    interaction.attach();
    const bool cloud =
      wait_until([&] { return interaction.initial_cloud_complete(); },
                 300,
                 "the initial cloud");
    // One byte: the first frame is written, then none.
    palpate::ShapeInterpolator shape(
      interaction, 50, "limited", "beam", nullptr, 1);
    shape.start();
    unsigned int step     = 0;
    const bool   left_out = wait_until(
      [&] {
        interaction.force({{1e-5 * (++step % 20), 0, 0}});
        return shape.frames_over_limit() >= 3;
      },
      60,
      "three frames over the limit");
    shape.stop();
    interaction.detach();
    deallog << "initial cloud: " << (cloud ? "yes" : "NO")
            << ", frames written: " << shape.frames().first
            << ", later frames left out and counted: "
            << (left_out ? "yes" : "NO") << std::endl;
    const auto frame_bytes =
      std::filesystem::file_size("limited/beam-shape-00000.vtu");
    std::filesystem::remove_all("limited");

    // Decimation: with room for 8 frames, the first 4 are written at the
    // full rate; past half the limit every 2nd, past 3/4 every 4th, past
    // 7/8 every 8th; then none.
    palpate::Interaction decimated(scene);
    decimated.attach();
    wait_until([&] { return decimated.initial_cloud_complete(); },
               300,
               "the initial cloud");
    palpate::ShapeInterpolator thinned(
      decimated, 50, "limited", "beam", nullptr, 8.0 * frame_bytes);
    thinned.start();
    step               = 0;
    const bool reached = wait_until(
      [&] {
        decimated.force({{1e-5 * (++step % 20), 0, 0}});
        return thinned.frames_over_limit() >= 3;
      },
      60,
      "three frames over the limit");
    thinned.stop();
    decimated.detach();
    const unsigned int written = thinned.frames().first;
    deallog << "decimation: limit reached " << (reached ? "yes" : "NO")
            << ", frames written 5-9: "
            << (written >= 5 && written <= 9 ? "yes" : "NO")
            << ", frames thinned out before the limit (about 1 + 3 + 7 when "
               "the frames are equally large; later frames are larger): "
            << (thinned.frames_decimated() >= 2 ? "yes" : "NO") << std::endl;
    if (written < 5 || written > 9 || thinned.frames_decimated() < 2)
      deallog << "  written " << written << ", thinned "
              << thinned.frames_decimated() << ", frame " << frame_bytes
              << " bytes" << std::endl;
    std::filesystem::remove_all("limited");
  }

  {
    // A slow Shape output rate (a frame every 1000 s): stop() wakes the
    // shape thread from its wait at once (it slept until its next frame,
    // and an interaction of 1 s then took 1000 s to end).
    deallog << "--- stop() at a Shape output rate of 1e-3 Hz" << std::endl;
    std::filesystem::remove_all("slow");
    palpate::Interaction       interaction(scene);
    palpate::ShapeInterpolator shape(interaction, 1e-3, "slow", "beam");
    shape.start();
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
    const auto start = std::chrono::steady_clock::now();
    shape.stop();
    const double took =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start)
        .count();
    // The property is that stop() does not wait for the next frame (1000 s
    // away): a bound far below that and far above any load's delay.
    deallog << "stop() returned long before the next frame (within 60 s of "
               "1000 s): "
            << (took < 60 ? "yes" : "NO") << ", PVD written: "
            << (std::filesystem::exists("slow/beam-shape.pvd") ? "yes" : "NO")
            << std::endl;
    std::filesystem::remove_all("slow");
  }
}
