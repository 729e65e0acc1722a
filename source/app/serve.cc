// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

// `palpate serve`: the live view (LiveServer) until a stop signal, then
// the run summary and the outputs, as after an interaction.

#include <palpate/app/application.h>
#include <palpate/app/http_guard.h>
#include <palpate/app/interaction_run.h>
#include <palpate/app/serve.h>
#include <palpate/base/exceptions.h>
#include <palpate/base/stop_request.h>
#include <palpate/haptics/interaction.h>
#include <palpate/haptics/run_summary.h>
#include <palpate/scene/scene.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <memory>
#include <thread>
#include <vector>

namespace palpate
{
  namespace
  {
    /** What to open and how to use the view, on @p out. */
    void
    print_how_to_use(std::ostream      &out,
                     const Scene       &scene,
                     const std::string &host,
                     const LiveServer  &server)
    {
      const auto &p = scene.parameters;
      // Listening on every interface: the address to open is this machine's
      // (LiveServer::address()); the others it answers to are listed, since
      // a request that names it otherwise is refused.
      out << "Live view: open " << server.address();
      if (http_guard::every_interface(host))
        {
          out << " (listening on every interface; it answers requests "
                 "addressed to";
          for (const auto &name : server.accepted_hosts())
            out << " " << name;
          out << ", port " << server.port() << ")";
        }
      out << " in a browser. A drag on the organ moves the probe in the view "
             "plane (with Alt held, in depth); a drag elsewhere or with the "
             "right button turns the view, the middle button (or Shift and "
             "the right) pans it, the wheel zooms; keys: f look at the probe, "
             "v the first view, a attach, d detach, r back to rest, m a "
             "material constant, shift-click another active node. Ctrl-C "
             "ends.\n"
          << std::flush;
      if (p.effects.shape_output)
        out << "Effects / Shape output: not written by palpate serve (the "
               "browser shows the shape; an interaction run, palpate "
            << (scene.file().empty() ? "SCENE.prm" : scene.file())
            << ", records its frames for ParaView).\n";
    }



    /** Write the machine-readable summaries (Output / Summary formats) of
     * the view's run; throws an OutputError listing these and the earlier
     * @p earlier_failures if any output could not be written. */
    void
    write_summaries(std::ostream                   &out,
                    const Scene                    &scene,
                    const std::string              &stem,
                    const RunSummary               &summary,
                    const std::vector<std::string> &earlier_failures)
    {
      const auto              &p        = scene.parameters;
      std::vector<std::string> failures = earlier_failures;
      // The machine-readable summaries, as after an interaction.
      for (const auto &format : p.output.summary_formats)
        {
          const std::string file =
            p.output.directory + "/" + stem + "-serve-summary." + format;
          try
            {
              std::filesystem::create_directories(p.output.directory);
              if (format == "csv")
                summary.write_csv(file);
              else
                summary.write_json(file);
              out << "  wrote " << file << "\n";
            }
          catch (const std::exception &e)
            {
              failures.push_back(file + ": " + e.what());
            }
        }
      if (!failures.empty())
        {
          std::string what;
          for (const auto &f : failures)
            what += "\n  " + f;
          throw OutputError("the live view ended (its summary is above), but " +
                            std::to_string(failures.size()) +
                            " output(s) could not be written:" + what);
        }
    }
  } // namespace



  int
  run_serve(std::ostream      &out,
            const Scene       &scene,
            const std::string &host,
            const int          port)
  {
    const auto       &p = scene.parameters;
    const std::string stem =
      scene.file().empty() ?
        "default" :
        std::filesystem::path(scene.file()).stem().string();
    // One live view of a scene per output directory: two would overwrite
    // each other's force log and summary.
    std::shared_ptr<void> output_lock;
    if (p.effects.force_log || !p.output.summary_formats.empty())
      {
        check_output_directory(scene);
        output_lock = lock_outputs(scene, stem + "-serve");
      }
    LiveServer server(scene, host, port, 0.05, &out);
    print_how_to_use(out, scene, host, server);
    // The force log is written as the view runs, a few times a second
    // (the haptic loop only fills a ring): a run that ends however it
    // ends keeps it.
    const std::string log_file =
      p.output.directory + "/" + stem + "-serve-forces.csv";
    std::ofstream            log;
    std::size_t              log_rows = 0;
    std::vector<std::string> failures;
    if (p.effects.force_log)
      {
        log.open(log_file);
        log << "t_s,x_m,y_m,z_m,fx_N,fy_N,fz_N\n" << std::setprecision(9);
        out << "Force log: " << log_file
            << " (t in s since the view started)\n";
      }
    out << std::flush;
    // The view runs until a stop signal (Ctrl-C, SIGTERM, SIGHUP: its
    // normal end, status 0), until nobody can read what it prints, or
    // until every MPI solver server is lost (nothing could compute a state
    // any more; status 5, as for an interaction).
    std::string stopped_by;
    int         stop_signal = 0;
    {
      const StopRequest stop;
      while (!stop.requested() && out && !server.interaction().engine_lost())
        {
          std::this_thread::sleep_for(std::chrono::milliseconds(100));
          if (log.is_open() && log)
            log_rows += server.write_force_log(log);
        }
      stopped_by =
        stop.requested() ?
          "by " + stop.description() + " (the live view's end)" :
        !out ? std::string("because standard output could not be written") :
               std::string("because every solver server was lost (the LOST "
                           "lines): none was left to compute a state");
      stop_signal = stop.signal_number();
    }
    server.stop();
    if (log.is_open())
      {
        log_rows += server.write_force_log(log);
        log.close();
      }
    out << "Live view ended.\n";
    RunSummary summary = server.interaction().summary();
    server.add_to(summary);
    summary.stopped_by  = stopped_by;
    summary.stop_signal = stop_signal;
    summary.print(out);
    server.print_summary(out);
    if (const std::string store = server.interaction().store_report();
        !store.empty())
      {
        out << "  state store:       " << store << "\n";
        if (server.interaction().store_write_failed())
          failures.push_back("the state store " + p.state_space.store +
                             " stopped taking states: " + store);
      }
    if (p.effects.force_log)
      {
        if (log)
          out << "  wrote " << log_file << " (" << log_rows << " rows"
              << (server.force_log_dropped() > 0 ?
                    ", " + std::to_string(server.force_log_dropped()) +
                      " ticks not logged: the writer fell behind" :
                    std::string())
              << ")\n";
        else
          failures.push_back(log_file + ": could not be written whole (is "
                                        "the disk full?)");
      }
    write_summaries(out, scene, stem, summary, failures);
    return summary.lost_servers.empty() ? ExitStatus::success :
                                          ExitStatus::server_lost;
  }
} // namespace palpate
