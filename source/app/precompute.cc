// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

#include <palpate/app/application.h>
#include <palpate/app/precompute.h>
#include <palpate/app/scene_report.h>
#include <palpate/base/exceptions.h>
#include <palpate/haptics/interaction.h>
#include <palpate/scene/scene.h>
#include <palpate/state_space/state_cache.h>
#include <palpate/state_space/state_grid.h>
#include <palpate/state_space/state_store.h>

#include <atomic>
#include <chrono>
#include <cmath>
#include <csignal>
#include <filesystem>
#include <iomanip>
#include <thread>

namespace palpate
{
  namespace
  {
    std::atomic<bool> interrupted{false};

    extern "C" void
    on_interrupt(int)
    {
      interrupted.store(true);
    }
  } // namespace



  int
  run_precompute(std::ostream &out, Scene scene, const double radius)
  {
    using Clock = std::chrono::steady_clock;
    auto &p     = scene.parameters;
    if (p.state_space.store.empty())
      throw scene.error("State space/Store",
                        "palpate precompute writes the states into the "
                        "scene's store, and the scene names none",
                        "set State space / Store = FILE.h5 in the scene.");
    if (radius > 0)
      {
        if (radius > p.state_space.extent)
          throw InputError("command line",
                           0,
                           "--radius " + Utilities::to_string(radius),
                           "the radius is beyond the state space's extent (" +
                             Utilities::to_string(p.state_space.extent) +
                             " m): no grid point is there",
                           "give a radius of at most State space / Extent, "
                           "or enlarge the extent.");
        // The cache must hold the whole region (the states are written
        // from it): make room for it.
        p.engine.memory_budget =
          std::max(p.engine.memory_budget,
                   p.engine.memory_budget *
                     std::pow(radius / p.scheduler.cloud_radius, 3));
        p.scheduler.cloud_radius = radius;
      }
    StoreFingerprint fingerprint;
    bool             stopped = false;
    {
      Interaction interaction(scene);
      fingerprint              = StoreFingerprint::of(interaction.scene(),
                                         interaction.mesh(),
                                         interaction.nodes());
      const auto        total  = interaction.initial_cloud_size();
      const auto        start  = Clock::now();
      const auto        before = interaction.cache().counts();
      const std::string loaded = interaction.store_report();
      out << "Precompute: every state within "
          << 1000 * p.scheduler.cloud_radius << " mm of rest (" << total
          << " grid points), into " << p.state_space.store << "\n"
          << "  store:         " << loaded.substr(0, loaded.find("; appended"))
          << "\n"
          << std::flush;

      interrupted.store(false);
      auto *const previous_int  = std::signal(SIGINT, on_interrupt);
      auto *const previous_term = std::signal(SIGTERM, on_interrupt);
      interaction.attach();
      unsigned int shown = ~0u;
      while (!interaction.initial_cloud_complete() && !interrupted.load())
        {
          std::this_thread::sleep_for(std::chrono::milliseconds(250));
          const auto   c    = interaction.cache().counts();
          const auto   done = std::min(total, c.first + c.second);
          const double t =
            std::chrono::duration<double>(Clock::now() - start).count();
          const auto new_done =
            done - std::min(done, before.first + before.second);
          const auto   left = total - done;
          const double eta  = new_done > 0 ? t / new_done * left : 0;
          if (done != shown)
            {
              const unsigned int width = 30;
              const unsigned int bar   = total > 0 ? width * done / total : 0;
              out << "\r  [" << std::string(bar, '#')
                  << std::string(width - bar, '.') << "] " << done << "/"
                  << total << " states, " << std::fixed << std::setprecision(0)
                  << t << " s"
                  << (new_done > 0 ?
                        ", about " + std::to_string(int(eta)) + " s left" :
                        std::string())
                  << "    " << std::defaultfloat << std::flush;
              shown = done;
            }
        }
      // States held elsewhere (MPI servers) reach the store when it asks
      // for them, while the engine runs: wait until every finished state is
      // stored (at most 60 s).
      for (const auto wait = Clock::now();
           !interrupted.load() &&
           std::chrono::duration<double>(Clock::now() - wait).count() < 60;)
        {
          const auto c = interaction.cache().counts();
          if (interaction.stored_points() >= c.first + c.second)
            break;
          std::this_thread::sleep_for(std::chrono::milliseconds(100));
        }
      interaction.detach(); // appends what was finished last
      std::signal(SIGINT, previous_int);
      std::signal(SIGTERM, previous_term);
      const auto   c = interaction.cache().counts();
      const double t =
        std::chrono::duration<double>(Clock::now() - start).count();
      out << "\n  " << (interrupted.load() ? "interrupted" : "done")
          << " after " << Utilities::to_string(t, 3) << " s: " << c.first
          << " states and " << c.second << " failure points in the cache; "
          << interaction.store_report() << "\n";
      stopped = interrupted.load();
    }
    // The state space for ParaView, from the store (the interaction has
    // closed it).
    const std::string vtk =
      std::filesystem::path(p.state_space.store).replace_extension().string() +
      "-space.vtk";
    {
      const StateStore store(p.state_space.store, fingerprint);
      store.export_vtk(StateGrid(p.state_space.grid_spacing,
                                 p.state_space.extent),
                       vtk);
    }
    out << "  for ParaView:  " << vtk
        << " (force, its magnitude, stiffness and status per grid point; "
           "status -1 not computed, 0 an equilibrium, >= 2 a failure "
           "point)\n";
    if (stopped)
      out << "  run the same command again to go on: the states stored are "
             "not computed again.\n";
    else
      out << "  use it:        palpate " << scene.file()
          << " (with the same State space / Store) starts without waiting "
             "for these states.\n";
    return stopped ? ExitStatus::interrupted : ExitStatus::success;
  }
} // namespace palpate
