// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

#include <palpate/app/application.h>
#include <palpate/app/application_impl.h>
#include <palpate/app/interaction_run.h>
#include <palpate/app/scene_report.h>
#include <palpate/app/static_solve.h>
#include <palpate/base/exceptions.h>
#include <palpate/base/stop_request.h>
#include <palpate/engine/mpi_engine.h>
#include <palpate/haptics/run_summary.h>
#include <palpate/hyperelastic/sphere_trial.h>
#include <palpate/mesh/mesh.h>
#include <palpate/mesh/node_selection.h>
#include <palpate/scene/scene.h>

#include <iostream>
#include <optional>
#include <string>
#include <vector>

namespace palpate
{
  namespace
  {
    /** Whether the ranks 1..N-1 of an MPI run serve this run as solver
     * servers: an interaction with Engine / Type = mpi under mpirun. */
    bool
    serves(const Scene &scene, const bool solve)
    {
      return !solve && mpi_size() > 1 &&
             scene.parameters.engine.type == "mpi" &&
             scene.parameters.run.mode == "interaction";
    }

    /**
     * A static solve's push longer than the body is across is a typing
     * mistake (mm for m), not a failure point after 1000 increments:
     * refused before anything is set up (the sphere's check would
     * otherwise blame the radius). @p from_command_line: given by --to.
     */
    void
    check_push_length(const Scene             &scene,
                      const Mesh              &mesh,
                      const Utilities::Point3 &push,
                      const bool               from_command_line)
    {
      const std::string farther = mesh.farther_than_across(push);
      if (farther.empty())
        return;
      const std::string what = "the probe would move " + farther;
      if (from_command_line)
        throw InputError("command line",
                         0,
                         "--to " + Utilities::to_string(push, 6),
                         what,
                         "give the displacement in metres, e.g. --to "
                         "0,0,-0.01 for 1 cm down.");
      throw scene.error("Boundary conditions/Active node/Prescribed "
                        "displacement",
                        what,
                        "give the displacement in metres, e.g. 0, 0, "
                        "-0.01 for 1 cm down.");
    }
  } // namespace



  namespace internal
  {
    std::optional<ReleaseServers>
    release_servers_at_end(const Scene &scene)
    {
      // A prvalue: the guard is never copied (nor released early).
      return mpi_size() > 1 && scene.parameters.engine.type == "mpi" ?
               std::optional<ReleaseServers>(std::in_place) :
               std::nullopt;
    }



    int
    run_server_rank(const std::vector<std::string> &args,
                    const std::vector<std::string> &settings,
                    const bool                      dangling_set,
                    std::ostream                   &err)
    {
      // Rank 0 refuses a '--set' without its value before it starts
      // anything: a server waiting for it would wait forever.
      if (dangling_set)
        return ExitStatus::input_error;
      // palpate precompute and palpate serve under mpirun: the servers
      // compute, rank 0 writes the store or serves the page, whatever the
      // scene's Run / Mode.
      const bool subcommand =
        args.size() >= 2 && (args[0] == "precompute" || args[0] == "serve");
      if (!subcommand && (args.size() != 1 || args[0].empty() ||
                          args[0][0] == '-' || args[0] == "solve"))
        return ExitStatus::success;
      try
        {
          const Scene scene =
            Scene::read(subcommand ? args[1] : args[0], settings);
          if (subcommand ?
                !(mpi_size() > 1 && scene.parameters.engine.type == "mpi") :
                !serves(scene, false))
            return ExitStatus::success;
          const Mesh          mesh  = Mesh::create(scene);
          const NodeSelection nodes = NodeSelection::create(scene, mesh);
          // Ctrl-C on mpirun reaches every rank as SIGTERM. A server that
          // died of it would take the client's run down with it before the
          // client wrote its summary and logs; the server rather goes on
          // until the client, stopping through its normal path, releases
          // it (mpirun kills what is left after its own grace period).
          const StopRequest stop;
          switch (run_solver_server(scene, mesh, nodes))
            {
              case 0:
                return ExitStatus::success;
              case 2: // the client was lost (it said so on stderr)
                return ExitStatus::server_lost;
              default:
                return ExitStatus::internal_error;
            }
        }
      catch (const InputError &)
        {
          return ExitStatus::input_error;
        }
      catch (const std::exception &e)
        {
          err << "\npalpate (solver server, MPI rank " << mpi_rank()
              << "): internal error: " << e.what() << "\n";
          return ExitStatus::internal_error;
        }
    }



    int
    run_scene(const std::string               &filename,
              const std::vector<std::string>  &settings,
              std::optional<Utilities::Point3> target,
              const bool                       solve,
              std::ostream                    &out)
    {
      Scene scene = Scene::read(filename, settings);
      // The push as the scene has it (before --to replaces it below).
      const Utilities::Point3 prescribed =
        scene.parameters.boundary_conditions.active_node
          .prescribed_displacement;
      // `solve --to` is the push: the sphere's check (NodeSelection) weighs
      // its depth against the radius, as it does the scene's push.
      if (solve && target)
        scene.parameters.boundary_conditions.active_node
          .prescribed_displacement = *target;
      const Mesh  mesh = Mesh::create(scene);
      const auto &mode = scene.parameters.run.mode;
      if (solve || (mode != "set-up only" && mode != "interaction"))
        check_push_length(scene,
                          mesh,
                          target ? *target : prescribed,
                          target.has_value());
      const NodeSelection nodes = select_nodes(scene, mesh, &std::cerr);
      // Under mpirun the other ranks got this far too; with the MPI
      // engine they now wait as solver servers, and are released whatever
      // happens here (the engine releases them itself when it ends).
      std::optional<ReleaseServers> release;
      if (serves(scene, solve))
        release.emplace();
      print_scene_report(out, scene, mesh, nodes);
      // Out now, into a file or a pipe too: a stop signal before a run's
      // own handler is installed still ends the process at once, and lost
      // the report in the buffer. (Not line buffering: with it a closed
      // pipe went unseen, since a line-buffered fwrite reports success.)
      out << std::flush;
      if (!solve && mode == "set-up only")
        return ExitStatus::success;
      if (!solve && mode == "interaction")
        {
          const RunSummary summary = run_interaction(out, scene);
          if (summary.stop_signal != 0)
            {
              out.flush();
              std::cerr << "\npalpate: the interaction was stopped "
                        << summary.stopped_by
                        << "; its summary and output files were written. "
                           "Exit status "
                        << 128 + summary.stop_signal << ".\n";
              return 128 + summary.stop_signal;
            }
          if (summary.lost_servers.empty())
            return ExitStatus::success;
          // mpirun --enable-recovery (needed to survive a dead server)
          // itself exits 0 whatever the ranks return: say it plainly.
          out.flush();
          std::cerr << "\npalpate: " << summary.lost_servers.size()
                    << " MPI solver server(s) lost during the run (LOST in the "
                       "summary above); "
                    << (summary.stopped_by.find(
                          "every solver server was lost") == std::string::npos ?
                          "the interaction went on with the servers left" :
                        summary.stopped_by.find("before the motion started") !=
                            std::string::npos ?
                          "none was left before the motion started, so the "
                          "run ended there" :
                          "the interaction went on with the servers left, "
                          "and ended when none was left")
                    << ". Exit status " << ExitStatus::server_lost << ".\n";
          return ExitStatus::server_lost;
        }
      if (!target && Utilities::norm(prescribed) > 0)
        target = prescribed;
      if (!target)
        {
          out << "\nThe active node's prescribed displacement is zero: nothing "
                 "to solve.\n";
          return ExitStatus::success;
        }
      out << "\n";
      const int status = run_static_solve(out, scene, mesh, nodes, *target);
      if (status > 128)
        {
          out.flush();
          std::cerr << "\npalpate: the solve was stopped by a signal; what it "
                       "reached was printed and its output files were "
                       "written. Exit status "
                    << status << ".\n";
        }
      return status;
    }



    Scene
    read_and_report(const std::string              &file,
                    const std::vector<std::string> &settings,
                    std::ostream                   &out)
    {
      const Scene         scene = Scene::read(file, settings);
      const Mesh          mesh  = Mesh::create(scene);
      const NodeSelection nodes = select_nodes(scene, mesh, &std::cerr);
      print_scene_report(out, scene, mesh, nodes);
      out << "\n" << std::flush; // as in the interaction's: kept on a stop
      return scene;
    }
  } // namespace internal
} // namespace palpate
