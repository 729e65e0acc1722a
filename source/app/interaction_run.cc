// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

#include <palpate/app/interaction_run.h>
#include <palpate/haptics/haptic_loop.h>
#include <palpate/haptics/interaction.h>
#include <palpate/haptics/shape_interpolator.h>
#include <palpate/haptics/trajectory.h>
#include <palpate/scene/scene.h>
#include <palpate/state_space/state_cache.h>
#include <palpate/state_space/state_grid.h>

#include <chrono>
#include <filesystem>
#include <iomanip>
#include <ostream>
#include <thread>

namespace palpate
{
  RunSummary
  run_interaction(std::ostream &out, const Scene &scene)
  {
    using Clock   = std::chrono::steady_clock;
    const auto &p = scene.parameters;

    // How long the initial cloud may take before the motion starts anyway.
    const double wait_limit = 120;

    Interaction     interaction(scene);
    const auto     &grid        = interaction.grid();
    auto            trajectory  = Trajectory::create(scene);
    const double    duration    = trajectory->duration();
    const double    max_seconds = wait_limit + duration + 1;
    SimulatedDevice device(std::move(trajectory),
                           p.effects.force_log ?
                             HapticLoop::max_ticks(p.haptics.loop_rate,
                                                   max_seconds) :
                             0);

    out << "\nInteraction\n"
        << "  state space:   grid spacing " << 1000 * grid.spacing()
        << " mm, extent +-" << 1000 * grid.half_width() * grid.spacing()
        << " mm (" << grid.size() << " points), cloud radius "
        << 1000 * p.scheduler.cloud_radius << " mm, look-ahead "
        << p.scheduler.look_ahead_time << " s\n"
        << "  device:        " << device.description() << "\n"
        << "  haptic loop:   " << p.haptics.loop_rate << " Hz, force limit "
        << p.haptics.force_limit << " N, at most " << p.haptics.max_force_change
        << " N change per tick\n"
        << std::flush;

    const std::string stem =
      scene.file().empty() ?
        "default" :
        std::filesystem::path(scene.file()).stem().string();
    std::unique_ptr<ShapeInterpolator> shape;
    if (p.effects.shape_output)
      shape = std::make_unique<ShapeInterpolator>(interaction,
                                                  p.effects.shape_output_rate,
                                                  p.output.directory,
                                                  stem);

    HapticLoop loop(interaction, device, p.haptics.loop_rate, max_seconds);
    const auto t0 = Clock::now();
    interaction.attach();
    loop.start(duration);
    if (shape)
      shape->start();
    bool         moving         = p.haptics.trajectory.start == "immediately";
    unsigned int cloud_states   = 0;
    bool         cloud_complete = false;
    if (moving)
      loop.start_motion();

    // Watch: report events as they happen, start the motion once the
    // initial cloud is there.
    while (!loop.finished())
      {
        std::this_thread::sleep_for(std::chrono::milliseconds(10));
        interaction.poll_events(out);
        const double t =
          std::chrono::duration<double>(Clock::now() - t0).count();
        if (!moving && (interaction.initial_cloud_complete() || t > wait_limit))
          {
            const auto counts = interaction.cache().counts();
            cloud_states      = counts.first;
            cloud_complete    = t <= wait_limit;
            out << "  initial cloud: " << counts.first << " states computed, "
                << counts.second << " failure points, in "
                << std::setprecision(3) << t << " s"
                << (t > wait_limit ? " (not complete: starting anyway)" : "")
                << "; motion starts\n"
                << std::flush;
            loop.start_motion();
            moving = true;
          }
      }
    loop.join();
    if (shape)
      shape->stop();
    interaction.detach();
    interaction.poll_events(out);

    RunSummary summary = interaction.summary();
    loop.add_to(summary);
    summary.trajectory             = device.description();
    summary.initial_cloud_states   = cloud_states;
    summary.initial_cloud_complete = cloud_complete;
    if (shape)
      summary.shape_frames = shape->frames().first;
    out << "\n";
    summary.print(out);

    // Machine-readable copies and logs, only when asked for.
    const bool files =
      p.effects.force_log || !p.output.summary_formats.empty() || shape;
    if (files)
      std::filesystem::create_directories(p.output.directory);
    for (const auto &format : p.output.summary_formats)
      {
        const std::string file =
          p.output.directory + "/" + stem + "-summary." + format;
        if (format == "csv")
          summary.write_csv(file);
        else
          summary.write_json(file);
        out << "  wrote " << file << "\n";
      }
    if (p.effects.force_log)
      {
        const std::string file =
          p.output.directory + "/" + stem + "-forces.csv";
        device.write_force_log(file);
        out << "  wrote " << file << "\n";
      }
    if (shape)
      out << "  wrote " << p.output.directory << "/" << stem << "-shape.pvd ("
          << shape->frames().first << " frames, " << shape->frames().second
          << " skipped for missing states)\n";
    return summary;
  }
} // namespace palpate
