// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

#include <palpate/app/application.h>
#include <palpate/app/precompute.h>
#include <palpate/app/scene_report.h>
#include <palpate/base/exceptions.h>
#include <palpate/base/stop_request.h>
#include <palpate/haptics/interaction.h>
#include <palpate/scene/scene.h>
#include <palpate/state_space/state_cache.h>
#include <palpate/state_space/state_grid.h>
#include <palpate/state_space/state_store.h>

#include <chrono>
#include <cmath>
#include <filesystem>
#include <functional>
#include <iomanip>
#include <thread>

namespace palpate
{
  namespace
  {
    using Clock = std::chrono::steady_clock;

    /** A progress bar until the region is computed, the run is stopped,
     * or every solver server is lost (nothing more will come then). */
    void
    show_progress(std::ostream                               &out,
                  Interaction                                &interaction,
                  const unsigned int                          total,
                  const Clock::time_point                     start,
                  const std::pair<unsigned int, unsigned int> before,
                  const std::function<bool()>                &stopping)
    {
      unsigned int shown = ~0u;
      while (!interaction.initial_cloud_complete() && !stopping() &&
             !interaction.engine_lost())
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
    }



    /** States held elsewhere (MPI servers) reach the store when it asks
     * for them, while the engine runs: wait until every finished state is
     * stored (at most 60 s; the store appends every quarter second, so 2 s
     * without progress means nothing more is coming: states dropped for
     * the memory budget, a lost server). */
    void
    wait_until_stored(Interaction                 &interaction,
                      const std::function<bool()> &stopping)
    {
      auto progress = std::make_pair(interaction.stored_points(), Clock::now());
      for (const auto wait = Clock::now();
           !stopping() &&
           std::chrono::duration<double>(Clock::now() - wait).count() < 60 &&
           Clock::now() - progress.second < std::chrono::seconds(2);)
        {
          const auto c      = interaction.cache().counts();
          const auto stored = interaction.stored_points();
          if (stored >= c.first + c.second)
            break;
          if (stored > progress.first)
            progress = std::make_pair(stored, Clock::now());
          std::this_thread::sleep_for(std::chrono::milliseconds(100));
        }
    }



    /** Points of the region no state reached: every path to them from
     * rest passes a failure point (the engine computes a state only from
     * a converged neighbour), so they are not computed, and said so. */
    void
    say_unreached(std::ostream      &out,
                  const Interaction &interaction,
                  const double       cloud_radius)
    {
      {
        const auto  &grid        = interaction.grid();
        unsigned int unreachable = 0;
        for (unsigned int q = 0; q < grid.size(); ++q)
          if (Utilities::norm(grid.position(q)) <= cloud_radius &&
              interaction.cache().status(q) == PointStatus::missing)
            ++unreachable;
        if (unreachable > 0)
          out << "  not reached:   " << unreachable << " grid points within "
              << 1000 * cloud_radius
              << " mm: every way to them from rest passes a failure point "
                 "(a state is computed only from a converged neighbour); "
                 "status -1 in the ParaView export below\n";
      }
    }



    /** What the store keeps, read back from the file, and the state space
     * for ParaView from it; returns why the export failed, or "". */
    std::string
    report_store_and_export(std::ostream                    &out,
                            const Parameters::AllParameters &p,
                            const StoreFingerprint          &fingerprint,
                            const unsigned int               before_run)
    {
      // What the store keeps, read back from the file (the interaction has
      // closed it; the lock still keeps other writers out): the number a
      // user can rely on, whatever stopped the run.
      const StateStore store(p.state_space.store,
                             fingerprint,
                             StateStore::Access::read);
      const auto       kept = store.contents();
      out << "  store keeps:   " << kept.states << " states and "
          << kept.failures << " failure points in " << p.state_space.store
          << " ("
          << kept.states + kept.failures -
               std::min(before_run, kept.states + kept.failures)
          << " appended by this run"
          << (kept.damaged + kept.incomplete > 0 ?
                ", " + std::to_string(kept.damaged + kept.incomplete) +
                  " records damaged or cut short skipped" :
                std::string())
          << ")\n"
          << std::flush;
      // The state space for ParaView, from the store.
      const std::string vtk = std::filesystem::path(p.state_space.store)
                                .replace_extension()
                                .string() +
                              "-space.vtk";
      std::string export_failure;
      try
        {
          store.export_vtk(StateGrid(p.state_space.grid_spacing,
                                     p.state_space.extent),
                           vtk);
          out << "  for ParaView:  " << vtk
              << " (force, its magnitude, stiffness and status per grid point; "
                 "status -1 not computed, 0 an equilibrium, >= 2 a failure "
                 "point)\n";
        }
      catch (const OutputError &e)
        {
          // Half a file would mislead ParaView: none at all.
          std::error_code error;
          std::filesystem::remove(vtk, error);
          export_failure = e.what();
        }
      return export_failure;
    }
  } // namespace



  namespace
  {
    /**
     * That the scene names a store, and @p radius (unless 0) is within the
     * state space: the scheduler's cloud then reaches it, and the cache
     * holds it all (the states are written from it).
     */
    void
    set_region(Scene &scene, const double radius)
    {
      auto &p = scene.parameters;
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
    }
  } // namespace



  int
  run_precompute(std::ostream &out, Scene scene, const double radius)
  {
    set_region(scene, radius);
    auto &p = scene.parameters;
    // One writer per store: the lock is taken before the interaction
    // opens the store, and held until what the store kept has been counted
    // and exported, so that no other process writes in between (the
    // interaction's own store shares it). A second precompute, or an
    // interaction on the same store, is refused naming this process.
    const StoreLock lock(p.state_space.store);
    // SIGINT, SIGTERM and SIGHUP (the terminal closed) stop it the same
    // way: the states finished are appended, what the store keeps is
    // counted and said, and the exit status is 128 + the signal's number.
    const StopRequest stop;
    const auto        stopping = [&] {
      return stop.requested() || !lock.failure().empty();
    };
    StoreFingerprint         fingerprint;
    unsigned int             before_run = 0; // records the store held before
    std::vector<std::string> lost_servers;   // MPI solver servers lost
    {
      Interaction interaction(scene);
      fingerprint              = StoreFingerprint::of(interaction.scene(),
                                         interaction.mesh(),
                                         interaction.nodes());
      before_run               = interaction.stored_points();
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

      interaction.attach();
      show_progress(out, interaction, total, start, before, stopping);
      wait_until_stored(interaction, stopping);
      interaction.detach(); // appends what was finished last
      lost_servers = interaction.summary().lost_servers;
      for (const std::string &lost : lost_servers)
        out << "\n  LOST:          " << lost;
      const auto   c = interaction.cache().counts();
      const double t =
        std::chrono::duration<double>(Clock::now() - start).count();
      out << "\n  "
          << (stop.requested()          ? "stopped by " + stop.description() :
              !lock.failure().empty()   ? std::string("stopped: the store "
                                                      "could not be written,") :
              interaction.engine_lost() ? std::string(
                                            "stopped: every solver server was "
                                            "lost, none is left to compute a "
                                            "state,") :
                                          std::string("done"))
          << " after " << Utilities::to_string(t, 3) << " s: " << c.first
          << " states and " << c.second << " failure points in the cache; "
          << interaction.store_report() << "\n";
      // Points of the region no state reached: every path to them from
      // rest passes a failure point (the engine computes a state only from
      // a converged neighbour), so they are not computed, and said so.
      if (!stop.requested() && lock.failure().empty() &&
          !interaction.engine_lost())
        say_unreached(out, interaction, p.scheduler.cloud_radius);
    }
    const std::string export_failure =
      report_store_and_export(out, p, fingerprint, before_run);
    // A failed write is an output error (exit status 6), after everything
    // else was said and written; the store's comes first, it is the cause.
    if (const std::string failure = lock.failure(); !failure.empty())
      throw OutputError(failure + (export_failure.empty() ?
                                     std::string() :
                                     "; the ParaView export was not "
                                     "written either (" +
                                       export_failure + ")"));
    if (!export_failure.empty())
      throw OutputError(export_failure);
    if (!lost_servers.empty())
      out << "  " << lost_servers.size()
          << " MPI solver server(s) lost (LOST above): exit status "
          << ExitStatus::server_lost << ".\n";
    if (stop.requested() || !lost_servers.empty())
      out << "  run the same command again to go on: the states stored are "
             "not computed again.\n";
    else
      out << "  use it:        palpate " << scene.file()
          << " (with the same State space / Store) starts without waiting "
             "for these states.\n";
    return stop.requested()     ? stop.exit_status() :
           lost_servers.empty() ? ExitStatus::success :
                                  ExitStatus::server_lost;
  }
} // namespace palpate
