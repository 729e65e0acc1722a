// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

#include <palpate/app/interaction_run.h>
#include <palpate/base/exceptions.h>
#include <palpate/base/stop_request.h>
#include <palpate/haptics/device.h>
#include <palpate/haptics/haptic_loop.h>
#include <palpate/haptics/interaction.h>
#include <palpate/haptics/shape_interpolator.h>
#include <palpate/hyperelastic/hyperelastic_system.h>
#include <palpate/hyperelastic/sphere_trial.h>
#include <palpate/hyperelastic/state.h>
#include <palpate/mesh/mesh.h>
#include <palpate/mesh/node_selection.h>
#include <palpate/scene/scene.h>
#include <palpate/state_space/state_cache.h>
#include <palpate/state_space/state_grid.h>

#include <fcntl.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iomanip>
#include <iostream>
#include <optional>
#include <ostream>
#include <sstream>
#include <thread>

namespace palpate
{
  void
  check_output_directory(const Scene &scene)
  {
    const std::string &directory = scene.parameters.output.directory;
    // A link to nowhere: say what it is, as every other path does
    // (create_directories() would only say "cannot be created: File
    // exists").
    std::string problem = dangling_link(directory);
    if (problem.empty())
      try
        {
          std::filesystem::create_directories(directory);
          const std::string probe = directory + "/.palpate-write-test";
          {
            std::ofstream test(probe);
            test << "test\n";
            test.flush();
            if (!test)
              problem = "files cannot be written in it";
          }
          std::filesystem::remove(probe);
        }
      catch (const std::filesystem::filesystem_error &e)
        {
          // error_code: the path may be one the file system refuses
          // altogether (a loop of links).
          std::error_code error;
          problem = std::string("it cannot be created: ") + e.code().message() +
                    (std::filesystem::exists(directory, error) &&
                         !std::filesystem::is_directory(directory, error) ?
                       " (a file of that name is in the way)" :
                       "");
        }
    if (!problem.empty())
      throw scene.error(
        "Output/Directory",
        "the scene writes files (shape output, VTU export, force log "
        "or summaries) into '" +
          directory + "', but " + problem,
        "name a directory you can write, e.g. 'output', or "
        "turn those outputs off.");
  }



  namespace
  {
    using Clock = std::chrono::steady_clock;

    /**
     * Two interactions of one scene into one Output / Directory would write
     * the same files: two runs started 0.3 s apart would both say "wrote",
     * and one's force log, summary and index would be the other's. The run
     * that writes them holds an flock on DIRECTORY/STEM.lock (the kernel's
     * lock goes with the process, however it ends); a second one is refused
     * before it computes anything, naming the first.
     */
    class OutputLock
    {
    public:
      OutputLock(const Scene &scene, const std::string &stem)
        : file(scene.parameters.output.directory + "/" + stem + ".lock")
      {
        // A few rounds: the holder may remove its lock file just as this
        // run locks it (then the lock is on a file nobody else sees).
        for (unsigned int round = 0; round < 5; ++round)
          {
            fd = ::open(file.c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0644);
            if (fd < 0)
              return; // no lock to be had: check_output_directory() speaks
            if (flock(fd, LOCK_EX | LOCK_NB) != 0)
              {
                char       text[64] = {};
                const auto n        = ::pread(fd, text, sizeof(text) - 1, 0);
                ::close(fd);
                fd = -1;
                throw scene.error(
                  "Output/Directory",
                  "another palpate (process " +
                    std::string(n > 0 ? text : "?") +
                    ") is running this scene with its outputs in '" +
                    scene.parameters.output.directory +
                    "': both would write the same force log, summaries and "
                    "shape frames (its lock file '" +
                    file + "')",
                  "wait until it ends, or give this run a directory of its "
                  "own (--set 'Output/Directory=run2').");
              }
            struct stat locked, named;
            if (fstat(fd, &locked) == 0 && stat(file.c_str(), &named) == 0 &&
                locked.st_ino == named.st_ino && locked.st_dev == named.st_dev)
              {
                const std::string pid = std::to_string(getpid());
                if (ftruncate(fd, 0) != 0 ||
                    ::pwrite(fd, pid.data(), pid.size(), 0) < 0)
                  {
                    // The lock holds without the pid in it.
                  }
                return;
              }
            ::close(fd);
            fd = -1;
          }
      }

      OutputLock(const OutputLock &) = delete;
      OutputLock &
      operator=(const OutputLock &) = delete;

      ~OutputLock()
      {
        if (fd >= 0)
          {
            // Removed while still locked: whoever opens the name next
            // makes a new file, and the check above catches one that
            // locked this one as it went.
            ::unlink(file.c_str());
            ::close(fd);
          }
      }

    private:
      const std::string file;
      int               fd = -1;
    };

    /**
     * One interaction, in the steps run_interaction() takes: set up the
     * device, the haptic loop and the shape output; report; move (attach,
     * wait for the initial cloud, run the motion, watching for events and
     * stop signals); summarise; write the outputs.
     */
    class InteractionRun
    {
    public:
      InteractionRun(std::ostream &out, const Scene &scene)
        : out(out)
        , scene(scene)
        , p(scene.parameters)
        , wait_limit(p.haptics.trajectory.initial_cloud_time_limit)
        , stem(scene.file().empty() ?
                 "default" :
                 std::filesystem::path(scene.file()).stem().string())
      {}

      /** Check the output directory and the trajectory, build the
       * interaction, the device, the haptic loop and the shape output. */
      void
      set_up();

      /** What will run: the state space, the device, the haptic loop. */
      void
      report() const;

      /** The report's warning when the trajectory pushes a sphere deeper
       * than its set-up checks allow. */
      void
      warn_if_sphere_too_small_for_the_motion() const;

      /** Refuses a planned motion longer than the body is across. */
      void
      check_motion_fits_the_body() const;

      /** Attach, start the loop, wait for the initial cloud and run the
       * motion, reporting events as they happen, until its end or a stop
       * signal. */
      void
      move();

      /** Stop the shape output, detach, print the run summary. */
      RunSummary
      summarise();

      /** A stop signal that came after the motion, while the outputs were
       * written: they were written whole (the handler only takes note),
       * and @p summary's exit status still says that the run was stopped. */
      void
      note_late_stop(RunSummary &summary) const
      {
        if (summary.stop_signal == 0 && stop_request &&
            stop_request->requested())
          {
            summary.stop_signal = stop_request->signal_number();
            summary.stopped_by  = "by " + stop_request->description() +
                                 " while the outputs were written (after "
                                 "the motion)";
          }
      }

      /** The CSV/JSON summaries, the store's line, the force log, the VTU
       * export and the shape output's line; an OutputError listing what
       * could not be written, after everything else was. */
      void
      write_outputs(const RunSummary &summary);

    private:
      /** Whether the motion may start: the 27 grid points around rest, or
       * the whole initial cloud (Haptics / Trajectory / Start). */
      bool
      ready_to_move() const;

      /** move(), a step: the initial cloud's line as the motion starts
       * @p t s after attaching (@p neighbourhood: Start = after rest
       * neighbourhood), and what the summary keeps of it. */
      void
      announce_motion_start(double t, bool neighbourhood);

      /** The VTU export of the states the haptic loop used, and its
       * index. */
      void
      write_states();

      std::ostream                    &out;
      const Scene                     &scene;
      const Parameters::AllParameters &p;
      // How long the initial cloud may take before the motion starts
      // anyway.
      const double      wait_limit;
      const std::string stem;

      double                             duration = 0, reach = 0;
      std::unique_ptr<OutputLock>        output_lock;
      std::unique_ptr<Interaction>       interaction;
      std::unique_ptr<Device>            device;
      std::unique_ptr<HapticLoop>        loop;
      std::unique_ptr<ShapeInterpolator> shape;

      // From move(): its stop handler, why it stopped early (empty: it did
      // not), the initial cloud.
      std::optional<StopRequest> stop_request;
      std::string                stopped_by;
      unsigned int               cloud_states   = 0;
      bool                       cloud_complete = false;
      // What could not be written is collected and reported after
      // everything else was written: one lost file does not lose the
      // others.
      std::vector<std::string> output_failures;
    };



    void
    InteractionRun::set_up()
    {
      // The output directory is checked before anything runs, so that no
      // work is lost to an unwritable directory at the end.
      const bool files = p.effects.force_log ||
                         !p.output.summary_formats.empty() ||
                         p.effects.shape_output;
      if (files)
        {
          check_output_directory(scene);
          output_lock = std::make_unique<OutputLock>(scene, stem);
        }

      device   = Device::create(scene);
      duration = std::min(device->max_duration(), Limits::max_motion_duration);
      // How far the device's planned motion takes the probe from rest,
      // along any axis: beyond the grid's extent the force fades to zero.
      reach       = device->planned_reach();
      interaction = std::make_unique<Interaction>(scene);
      check_motion_fits_the_body();
      const double max_seconds = wait_limit + duration + 1;
      loop                     = std::make_unique<HapticLoop>(*interaction,
                                          *device,
                                          p.haptics.loop_rate,
                                          max_seconds,
                                          p.effects.force_log);

      if (p.effects.shape_output)
        shape = std::make_unique<ShapeInterpolator>(
          *interaction,
          p.effects.shape_output_rate,
          p.output.directory,
          stem,
          [this] { return loop->motion_time(); },
          p.effects.shape_output_limit * 1048576.0);
    }



    void
    InteractionRun::report() const
    {
      const auto &grid = interaction->grid();
      out << "\nInteraction\n"
          << "  state space:   grid spacing " << 1000 * grid.spacing()
          << " mm, extent +-" << 1000 * grid.half_width() * grid.spacing()
          << " mm (" << grid.size() << " points), cloud radius "
          << 1000 * p.scheduler.cloud_radius << " mm, look-ahead "
          << p.scheduler.look_ahead_time << " s\n"
          << "  device:        " << device->description() << "\n"
          << "  haptic loop:   " << p.haptics.loop_rate << " Hz, force limit "
          << p.haptics.force_limit << " N, at most "
          << p.haptics.max_force_change << " N change per tick\n";
      if (reach > grid.half_width() * grid.spacing())
        out << "  warning:       the trajectory goes " << 1000 * reach
            << " mm from rest, beyond the state space's extent of +-"
            << 1000 * grid.half_width() * grid.spacing()
            << " mm: there the force fades to zero. Enlarge State space / "
               "Extent to at least "
            << 1000 * reach << " mm.\n";
      warn_if_sphere_too_small_for_the_motion();
      out << std::flush;
    }



    void
    InteractionRun::check_motion_fits_the_body() const
    {
      // A motion farther from rest than the body is across is a unit
      // mistake (a recording in millimetres read as metres), as solve's
      // --to says of such a push; the state space's warning alone would
      // let a replay moving 0.9 m over a 0.36 m liver run.
      const std::string farther =
        interaction->mesh().farther_than_across(device->planned_farthest());
      if (farther.empty())
        return;
      const bool replay = p.haptics.trajectory.type == "replay";
      throw scene.error(
        replay ? "Haptics/Trajectory/File name" : "Haptics/Trajectory/Speed",
        "the trajectory moves the probe from rest by " + farther,
        replay ? "give the recording's positions in metres "
                 "(a recording in millimetres is 1000 times "
                 "too far)." :
                 "shorten the motion (Speed in m/s times Duration in s, "
                 "or Radius) to stay within the body; a hand moves at "
                 "0.01 - 0.1 m/s.");
    }



    void
    InteractionRun::warn_if_sphere_too_small_for_the_motion() const
    {
      // The sphere's set-up checks weighed the scene's Prescribed
      // displacement; the trajectory may push deeper. They are asked
      // again at its farthest point: where they fail, the sphere may go
      // between the surface nodes, those states are failure points and
      // the force is held there (the summary counts it).
      const auto &a = p.boundary_conditions.active_node;
      if (!interaction->nodes().sphere_tip)
        return;
      // Its farthest point drags the sphere farthest along the surface,
      // its deepest presses it deepest (a circle's need not be the same).
      const auto &outward = interaction->nodes().active_normal;
      for (const auto &[point, what] :
           {std::make_pair(device->planned_farthest(), "farthest from rest"),
            std::make_pair(device->planned_deepest(outward),
                           "deepest into the body")})
        {
          if (point == a.prescribed_displacement ||
              !(Utilities::norm(point) > 0))
            continue;
          try
            {
              interaction->nodes().check_sphere_push(scene,
                                                     interaction->mesh(),
                                                     point,
                                                     sphere_sizing(&std::cerr));
            }
          catch (const InputError &e)
            {
              out << "  warning:       the trajectory's point " << what << " ("
                  << Utilities::to_string(1000 * Utilities::norm(point), 3)
                  << " mm from rest, "
                  << Utilities::to_string(-1000 *
                                            Utilities::dot(point, outward),
                                          3)
                  << " mm into the body) fails the set-up checks that "
                     "weighed the Prescribed displacement: the sphere "
                  << e.problem().substr(e.problem().find(" radius ") + 8)
                  << "; the force is held at such states. To avoid it: "
                  << e.fix() << "\n";
              return;
            }
        }
    }



    bool
    InteractionRun::ready_to_move() const
    {
      return p.haptics.trajectory.start == "after rest neighbourhood" ?
               interaction->rest_neighbourhood_missing() == 0 :
               interaction->initial_cloud_complete();
    }



    void
    InteractionRun::announce_motion_start(const double t,
                                          const bool   neighbourhood)
    {
      const auto counts = interaction->cache().counts();
      cloud_states      = counts.first;
      cloud_complete    = t <= wait_limit;
      // The engine is idle with points of the cloud neither computed nor
      // failed: no converged neighbour to start from.
      const unsigned int unreached = cloud_complete && !neighbourhood ?
                                       interaction->initial_cloud_missing() :
                                       0;
      out << "  initial cloud: " << counts.first << " states computed, "
          << counts.second << " failure points, in " << std::setprecision(3)
          << t << " s"
          << (unreached > 0 ?
                " (" + std::to_string(unreached) + " of its " +
                  std::to_string(interaction->initial_cloud_size()) +
                  " points not computed: failure points lie between them "
                  "and rest, and a state starts from a converged "
                  "neighbour)" :
                std::string())
          << (neighbourhood && t <= wait_limit ?
                " (the 27 grid points around rest are there; the rest of "
                "the cloud is computed during the motion)" :
                std::string())
          << (t > wait_limit ?
                " (not complete after Initial cloud time limit = " +
                  Utilities::to_string(wait_limit, 4) + " s: starting anyway)" :
                std::string())
          << "; motion starts\n"
          << std::flush;
    }



    void
    InteractionRun::move()
    {
      // From here on a stop signal ends the run through the path below, and
      // the outputs are still written after it (doc/bad-input.md, "Stops"):
      // it lives as long as this run.
      const StopRequest &stop = stop_request.emplace();

      const auto t0 = Clock::now();
      interaction->attach();
      loop->start(duration);
      if (shape)
        shape->start();
      bool moving = p.haptics.trajectory.start == "immediately";
      // Start = after rest neighbourhood: the motion waits only for the 27
      // grid points around rest, the rest of the cloud comes during it.
      const bool neighbourhood =
        p.haptics.trajectory.start == "after rest neighbourhood";
      if (moving)
        loop->start_motion();
      else
        out << "  initial cloud: " << interaction->initial_cloud_size()
            << " grid points around the rest position; the motion starts when "
            << (neighbourhood ?
                  "the 27 around it are computed (Start = after rest "
                  "neighbourhood; the others during the motion)" :
                  "they are computed")
            << " (at most " << wait_limit
            << " s: Haptics / Trajectory / Initial cloud time "
               "limit)\n"
            << std::flush;
      double next_progress = 10; // s: a word every 10 s while waiting

      // Watch: report events as they happen, start the motion once the
      // initial cloud is there.
      while (!loop->finished())
        {
          std::this_thread::sleep_for(std::chrono::milliseconds(10));
          interaction->poll_events(out);
          const double t =
            std::chrono::duration<double>(Clock::now() - t0).count();
          // A stop signal, or nobody left to read the output (a closed pipe,
          // a full disk: SIGPIPE is ignored, so the write fails instead):
          // end the motion here and write what the run has.
          // Every solver server lost: no state will come any more, so
          // neither waiting for the initial cloud nor moving on can give
          // a force; end here, through the same path.
          if (stop.requested() || !out || interaction->engine_lost())
            {
              const double motion = loop->motion_time();
              stopped_by =
                (stop.requested() ? "by " + stop.description() :
                 !out             ? std::string("because standard output "
                                                "could not be written") :
                                    std::string(
                          "because every solver server was lost "
                                      "(the LOST lines): none was left to compute "
                                      "a state")) +
                (motion >= 0 ?
                   " after " + Utilities::to_string(motion, 3) + " s of the " +
                     Utilities::to_string(duration, 3) + " s motion" :
                   " before the motion started (" + Utilities::to_string(t, 3) +
                     " s into the initial cloud)");
              loop->join();
              break;
            }
          if (!moving && t > next_progress && !ready_to_move())
            {
              const auto counts = interaction->cache().counts();
              out << "  initial cloud: " << counts.first << " of "
                  << interaction->initial_cloud_size() << " states computed ("
                  << counts.second << " failure points) after "
                  << std::setprecision(3) << t << " s\n"
                  << std::flush;
              next_progress += 10;
            }
          if (!moving && (ready_to_move() || t > wait_limit))
            {
              announce_motion_start(t, neighbourhood);
              loop->start_motion();
              moving = true;
            }
        }
      loop->join();
    }



    RunSummary
    InteractionRun::summarise()
    {
      if (shape)
        {
          shape->stop();
          if (!shape->failure().empty())
            output_failures.push_back("the shape output stopped after " +
                                      std::to_string(shape->frames().first) +
                                      " frames: " + shape->failure());
        }
      // Stopped by a signal: the states in flight are not waited for.
      if (stop_request && stop_request->requested())
        interaction->abandon_running();
      interaction->detach();
      interaction->poll_events(out);

      RunSummary summary = interaction->summary();
      loop->add_to(summary);
      summary.trajectory             = device->description();
      summary.stopped_by             = stopped_by;
      summary.stop_signal            = stop_request->signal_number();
      summary.initial_cloud_states   = cloud_states;
      summary.initial_cloud_complete = cloud_complete;
      if (shape)
        summary.shape_frames = shape->frames().first;
      out << "\n";
      summary.print(out);
      out << std::flush; // kept even if a second Ctrl-C ends what follows

      return summary;
    }



    void
    InteractionRun::write_outputs(const RunSummary &summary)
    {
      // Machine-readable copies and logs, only when asked for.
      const auto write = [&](const std::string           &file,
                             const std::function<void()> &how) {
        try
          {
            std::filesystem::create_directories(p.output.directory);
            how();
            out << "  wrote " << file << "\n";
          }
        catch (const std::exception &e)
          {
            output_failures.push_back(file + ": " + e.what());
          }
      };
      for (const auto &format : p.output.summary_formats)
        {
          const std::string file =
            p.output.directory + "/" + stem + "-summary." + format;
          write(file, [&] {
            if (format == "csv")
              summary.write_csv(file);
            else
              summary.write_json(file);
          });
        }
      if (const std::string store = interaction->store_report(); !store.empty())
        {
          out << "  state store:   " << store << "\n";
          if (interaction->store_write_failed())
            output_failures.push_back("the state store " + p.state_space.store +
                                      " stopped taking states: " + store);
        }
      if (p.effects.force_log)
        {
          const std::string file =
            p.output.directory + "/" + stem + "-forces.csv";
          write(file, [&] { loop->write_force_log(file); });
        }
      // The states as VTU come last: they take longest (seconds on a real
      // organ), and a second Ctrl-C while they are written, which ends the
      // process at once, must find the force log and summaries on disk.
      if (p.effects.vtu_export)
        {
          // The states the haptic loop used, for ParaView, and an index.
          const std::string index =
            p.output.directory + "/" + stem + "-states.csv";
          write(index, [&] { write_states(); });
        }
      if (shape)
        out << "  wrote " << p.output.directory << "/" << stem << "-shape.pvd ("
            << shape->frames().first << " frames while the probe moved, "
            << shape->frames().second << " skipped for missing states, "
            << shape->frames_skipped_busy()
            << " skipped while the machine was busy"
            << (shape->frames_decimated() > 0 ?
                  ", " + std::to_string(shape->frames_decimated()) +
                    " thinned out (past half of Shape output limit = " +
                    Utilities::to_string(p.effects.shape_output_limit, 4) +
                    " MiB the rate halves, past 3/4 it halves again, ...)" :
                  std::string())
            << (shape->frames_over_limit() > 0 ?
                  ", " + std::to_string(shape->frames_over_limit()) +
                    " left out beyond Shape output limit = " +
                    Utilities::to_string(p.effects.shape_output_limit, 4) +
                    " MiB" :
                  std::string())
            << ")\n";
      if (!output_failures.empty())
        {
          std::string what;
          for (const auto &f : output_failures)
            what += "\n  " + f;
          throw OutputError(
            "the interaction finished (its summary is above), but " +
            std::to_string(output_failures.size()) +
            " output(s) could not be written:" + what +
            "\n  Check the disk and Output / Directory (" + p.output.directory +
            ").");
        }
    }



    void
    InteractionRun::write_states()
    {
      const std::string index = p.output.directory + "/" + stem + "-states.csv";

      const HyperelasticSystem system(interaction->mesh(),
                                      interaction->nodes(),
                                      p);
      // The index is written after the states, and each state under a
      // temporary name first: a second Ctrl-C meanwhile leaves no
      // truncated file, only whole states and no index.
      std::ostringstream csv;
      csv << "point,i,j,k,x_m,y_m,z_m,fx_N,fy_N,fz_N,file\n"
          << std::setprecision(9);
      unsigned int written = 0, not_held = 0;
      for (const unsigned int point : interaction->used_points())
        {
          const auto state = interaction->cache().state(point);
          if (!state)
            {
              ++not_held; // dropped for the memory budget, or on a server
              continue;
            }
          const GridIndex   g    = interaction->grid().index(point);
          const std::string file = stem + "-state-" + std::to_string(g[0]) +
                                   "_" + std::to_string(g[1]) + "_" +
                                   std::to_string(g[2]) + ".vtu";
          const std::string path = p.output.directory + "/" + file;
          try
            {
              system.write_vtu(*state, path + ".part");
              std::filesystem::rename(path + ".part", path);
            }
          catch (...)
            {
              // A full disk: no partial file left behind either.
              std::error_code ignored;
              std::filesystem::remove(path + ".part", ignored);
              throw;
            }
          csv << point << "," << g[0] << "," << g[1] << "," << g[2] << ","
              << state->active_displacement[0] << ","
              << state->active_displacement[1] << ","
              << state->active_displacement[2] << "," << state->force[0] << ","
              << state->force[1] << "," << state->force[2] << "," << file
              << "\n";
          ++written;
        }
      std::ofstream index_file(index);
      index_file << csv.str();
      index_file.close();
      if (!index_file)
        throw std::runtime_error("cannot write '" + index + "'");
      out << "  wrote " << written << " states the haptic loop used as VTU ("
          << stem << "-state-I_J_K.vtu; warp by 'displacement' in ParaView)"
          << (not_held > 0 ? ", " + std::to_string(not_held) +
                               " not held here (dropped for the memory "
                               "budget, or kept by an MPI server)" :
                             std::string())
          << "\n";
    }
  } // namespace



  RunSummary
  run_interaction(std::ostream &out, const Scene &scene)
  {
    InteractionRun run(out, scene);
    run.set_up();
    run.report();
    run.move();
    RunSummary summary = run.summarise();
    run.write_outputs(summary);
    run.note_late_stop(summary);
    return summary;
  }
  std::shared_ptr<void>
  lock_outputs(const Scene &scene, const std::string &stem)
  {
    return std::make_shared<OutputLock>(scene, stem);
  }
} // namespace palpate
