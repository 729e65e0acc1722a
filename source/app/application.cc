// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

#include <palpate/app/application.h>
#include <palpate/app/interaction_run.h>
#include <palpate/app/precompute.h>
#include <palpate/app/scene_report.h>
#include <palpate/app/serve.h>
#include <palpate/app/static_solve.h>
#include <palpate/app/study.h>
#include <palpate/base/exceptions.h>
#include <palpate/base/stop_request.h>
#include <palpate/engine/mpi_engine.h>
#include <palpate/haptics/run_summary.h>
#include <palpate/hyperelastic/sphere_trial.h>
#include <palpate/mesh/mesh.h>
#include <palpate/mesh/node_selection.h>
#include <palpate/mesh/volume_mesher.h>
#include <palpate/scene/scene.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <map>
#include <optional>
#include <set>
#include <sstream>
#include <string>
#include <vector>

namespace palpate
{
  namespace
  {
    const char *const usage =
      "palpate: touch a non-linear finite element model through a haptic "
      "device.\n"
      "\n"
      "Usage:\n"
      "  palpate SCENE.prm               set up the scene and run it (Run /\n"
      "                                  Mode: an interaction by default)\n"
      "  palpate solve SCENE.prm [--to X,Y,Z]\n"
      "                                  compute the state with the active node\n"
      "                                  displaced by X,Y,Z metres from rest\n"
      "                                  (default: the scene's Prescribed\n"
      "                                  displacement) and print the force\n"
      "  palpate study SCENE.prm [--quick] [--samples N] [--finer-mesh FILE]\n"
      "                [--csv FILE] [--time-limit S] [--skip KNOB,...]\n"
      "                                  what accuracy costs in time for this\n"
      "                                  scene: grid spacing, interpolation,\n"
      "                                  tolerance, staging, mesh and element\n"
      "                                  against direct solves; recommends a\n"
      "                                  setting (doc/accuracy-vs-time.md)\n"
      "  palpate mesh SURFACE OUT.msh [--nodes N] [--scale S]\n"
      "               [--time-limit T] [--refine X,Y,Z --fine-size H\n"
      "               [--fine-radius R]]\n"
      "                                  make a tetrahedral mesh of an organ's\n"
      "                                  closed surface (.stl, .obj, .ply, .vtk,\n"
      "                                  .vtp; S metres per file unit, 0.001\n"
      "                                  for millimetres; N nodes, 1500 by\n"
      "                                  default): repairs, checks, meshes with\n"
      "                                  Gmsh, reports the quality; --refine\n"
      "                                  grades it to elements of H metres\n"
      "                                  within R metres (default 2 H) of the\n"
      "                                  point X,Y,Z (metres), where the\n"
      "                                  probe works\n"
      "                                  (doc/your-organ.md)\n"
      "  palpate precompute SCENE.prm [--radius R]\n"
      "                                  compute every state within R metres\n"
      "                                  of rest (default: the cloud radius)\n"
      "                                  into the scene's State space / Store\n"
      "                                  (HDF5); interrupted, it resumes\n"
      "  palpate serve SCENE.prm [--port P] [--host H]\n"
      "                                  the interaction with a live view in a\n"
      "                                  browser (http://127.0.0.1:8080/): the\n"
      "                                  mouse is the device\n"
      "  mpirun -np N palpate SCENE.prm  the same with Engine / Type = mpi:\n"
      "                                  rank 0 is the haptic client, ranks\n"
      "                                  1..N-1 are solver servers\n"
      "  palpate --print-parameters [prm|markdown]\n"
      "                                  print every scene parameter with its\n"
      "                                  default and documentation\n"
      "  ... --set ENTRY=VALUE           (repeatable, with any command that\n"
      "                                  reads a scene) a variant of the scene\n"
      "                                  without copying it: ENTRY is the\n"
      "                                  entry's path, e.g. --set 'Material\n"
      "                                  model/Model name=Neo-Hookean'\n"
      "  palpate --help                  this text\n"
      "  palpate --version               the version\n"
      "\n"
      "Scenes are deal.II parameter files; parameters/ holds examples\n"
      "(default.prm, liver-stvk.prm, liver-mooney-rivlin.prm, beam.prm) and\n"
      "doc/parameters.md documents every entry.\n";

    /** Whether the ranks 1..N-1 of an MPI run serve this run as solver
     * servers: an interaction with Engine / Type = mpi under mpirun. */
    bool
    serves(const Scene &scene, const bool solve)
    {
      return !solve && mpi_size() > 1 &&
             scene.parameters.engine.type == "mpi" &&
             scene.parameters.run.mode == "interaction";
    }

    /** Releases the MPI solver servers when it goes out of scope, however
     * rank 0's work ended (an error before the engine started included). */
    struct ReleaseServers
    {
      ReleaseServers()                       = default;
      ReleaseServers(const ReleaseServers &) = delete;
      ~ReleaseServers()
      {
        release_solver_servers();
      }
    };

    /** With the MPI engine under mpirun, a guard that releases the solver
     * servers however the rest ends. */
    std::optional<ReleaseServers>
    release_servers_at_end(const Scene &scene)
    {
      // A prvalue: the guard is never copied (nor released early).
      return mpi_size() > 1 && scene.parameters.engine.type == "mpi" ?
               std::optional<ReleaseServers>(std::in_place) :
               std::nullopt;
    }

    /**
     * A rank other than 0 of an MPI run: a solver server if the command
     * is an interaction with the MPI engine; otherwise nothing (rank 0
     * does the work and reports). Input errors are rank 0's to report.
     */
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



    /**
     * Set up a scene (read it, build the mesh, select the nodes), report
     * it, and do what its Run / Mode says: an interaction, a static solve
     * for the active node's prescribed displacement, or nothing more.
     * `palpate solve` (@p solve) always means a static solve, to @p target
     * if given (--to), else to the prescribed displacement.
     */
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

    /** The error for a command-line argument palpate does not know. */
    InputError
    unexpected(const std::string &argument)
    {
      return InputError("command line",
                        0,
                        argument,
                        "unexpected argument '" + argument + "'",
                        "run 'palpate --help' for the usage.");
    }

    /**
     * Before a command reads its options (from args[@p first] on): each
     * option that takes a value is given at most once, and has its value. @p values
     * maps the options that take a value to an example ("--to 0,0,-0.02").
     * Without this, "--to" at the end was an "unexpected argument" and a
     * second "--port" silently won.
     */
    void
    check_options(const std::vector<std::string>           &args,
                  const unsigned int                        first,
                  const std::map<std::string, std::string> &values)
    {
      std::set<std::string> seen;
      for (unsigned int i = first; i < args.size(); ++i)
        {
          const auto value = values.find(args[i]);
          if (value == values.end())
            continue; // a flag, or what the command refuses itself
          const std::string &option = args[i];
          if (!seen.insert(option).second)
            throw InputError("command line",
                             0,
                             option,
                             "'" + option +
                               "' is given twice: one of the two values "
                               "would be used without a word",
                             "give it once, e.g. " + value->second + ".");
          if (i + 1 == args.size())
            throw InputError("command line",
                             0,
                             option,
                             "'" + option + "' needs a value after it",
                             "e.g. " + value->second + ".");
          ++i;
        }
    }

    /** Read the scene @p file, build its mesh and nodes, and print its
     * report: what precompute, serve and study show first. */
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

    /** A whole number or a positive number from the command line. */
    double
    number_argument(const std::string &option,
                    const std::string &value,
                    const double       lo,
                    const double       hi,
                    const std::string &example)
    {
      std::size_t end = 0;
      double      x   = 0;
      try
        {
          x = std::stod(value, &end);
        }
      catch (const std::exception &)
        {
          end = 0;
        }
      if (end != value.size() || !(x >= lo && x <= hi))
        throw InputError("command line",
                         0,
                         option + " " + value,
                         "expected a number from " + Utilities::to_string(lo) +
                           " to " + Utilities::to_string(hi),
                         "e.g. " + option + " " + example + ".");
      return x;
    }

    /** palpate mesh SURFACE OUT.msh [--nodes N] [--scale S]
     * [--time-limit T]. */
    int
    run_mesh(const std::vector<std::string> &args, std::ostream &out)
    {
      if (args.size() < 3 || args[1][0] == '-' || args[2][0] == '-')
        throw InputError("command line",
                         0,
                         "mesh",
                         "'mesh' needs a surface file and an output file",
                         "run 'palpate mesh SURFACE.stl OUT.msh --scale "
                         "0.001' (for a surface in millimetres).");
      check_options(args,
                    3,
                    {{"--nodes", "--nodes 1500"},
                     {"--scale", "--scale 0.001"},
                     {"--time-limit", "--time-limit 60"},
                     {"--refine", "--refine -0.0936,0.1107,0.0994"},
                     {"--fine-size", "--fine-size 0.003"},
                     {"--fine-radius", "--fine-radius 0.02"}});
      double       scale = 1, time_limit = 60;
      unsigned int nodes = 1500;
      MeshGrading  grading;
      bool         refine = false, radius_given = false;
      for (unsigned int i = 3; i < args.size(); ++i)
        {
          const bool has_value = i + 1 < args.size();
          if (args[i] == "--nodes" && has_value)
            nodes = static_cast<unsigned int>(
              number_argument("--nodes", args[++i], 50, 200000, "1500"));
          else if (args[i] == "--scale" && has_value)
            scale = number_argument("--scale", args[++i], 1e-9, 1e9, "0.001");
          else if (args[i] == "--time-limit" && has_value)
            time_limit =
              number_argument("--time-limit", args[++i], 0.01, 86400, "60");
          else if (args[i] == "--refine" && has_value)
            {
              const std::string value = args[++i];
              try
                {
                  grading.center = Utilities::parse_point(value);
                }
              catch (const std::exception &)
                {
                  throw InputError("command line",
                                   0,
                                   "--refine " + value,
                                   "expected a point x,y,z in metres (after "
                                   "--scale)",
                                   "e.g. --refine -0.0936,0.1107,0.0994.");
                }
              refine = true;
            }
          else if (args[i] == "--fine-size" && has_value)
            grading.fine_size =
              number_argument("--fine-size", args[++i], 1e-5, 1, "0.003");
          else if (args[i] == "--fine-radius" && has_value)
            {
              grading.radius =
                number_argument("--fine-radius", args[++i], 0, 10, "0.02");
              radius_given = true;
            }
          else
            throw unexpected(args[i]);
        }
      if (refine != (grading.fine_size > 0))
        throw InputError("command line",
                         0,
                         refine ? "--refine" : "--fine-size",
                         "--refine and --fine-size go together: where to "
                         "refine and to what element size",
                         "e.g. --refine -0.0936,0.1107,0.0994 --fine-size "
                         "0.003.");
      if (!radius_given)
        grading.radius = 2 * grading.fine_size;
      if (std::filesystem::path(args[2]).extension() != ".msh")
        throw InputError("command line",
                         0,
                         args[2],
                         "the volume mesh is written as Gmsh 2.2, so its "
                         "name must end in .msh",
                         "e.g. 'palpate mesh " + args[1] + " organ.msh'.");
      // A link to nowhere would be replaced by the mesh (its target left
      // empty), and a file of the user's that is no mesh overwritten: both
      // are refused.
      if (const std::string link = dangling_link(args[2]); !link.empty())
        throw InputError("command line",
                         0,
                         args[2],
                         link,
                         "name the mesh by the link's target (in a directory "
                         "that exists), or remove the link first.");
      if (std::filesystem::is_regular_file(args[2]))
        {
          std::ifstream in(args[2], std::ios::binary);
          std::string   head(11, '\0');
          in.read(head.data(), head.size());
          head.resize(in.gcount());
          if (!head.empty() && head != "$MeshFormat")
            throw InputError("command line",
                             0,
                             args[2],
                             "'" + args[2] +
                               "' exists and is not a Gmsh mesh: it would "
                               "be overwritten",
                             "name a new file, or remove this one first if "
                             "it is no longer needed.");
        }
      {
        // Check that the output can be written before any work.
        const auto      dir = std::filesystem::path(args[2]).parent_path();
        std::error_code ec;
        if (!dir.empty())
          std::filesystem::create_directories(dir, ec);
        const bool    existed = std::filesystem::exists(args[2]);
        std::ofstream probe(args[2], std::ios::app);
        if (!probe)
          throw OutputError("cannot write '" + args[2] +
                            "': check that its directory exists and is "
                            "writable");
        probe.close();
        if (!existed)
          std::filesystem::remove(args[2], ec);
      }
      out << "palpate mesh: " << args[1] << " -> " << args[2] << " (about "
          << nodes << " nodes, " << Utilities::to_string(scale, 6)
          << " m per file unit)\n";
      // A stop signal ends the meshing child and removes its files
      // (StoppedError); without it the child outlived palpate.
      const StopRequest       stop;
      const SurfaceMeshReport report = mesh_surface_file(
        args[1], scale, "--scale", nodes, time_limit, args[2], grading);
      for (const auto &line : report.lines())
        out << "  " << line << "\n";
      out << "  use it:        subsection Mesh: set Source = file, set File "
             "name = "
          << args[2] << ", set Scale factor = 1 (the mesh is in metres)\n";
      return ExitStatus::success;
    }

    /** palpate solve SCENE.prm [--to X,Y,Z]: a static solve. */
    int
    run_solve_command(const std::vector<std::string> &args,
                      const std::vector<std::string> &settings,
                      std::ostream                   &out)
    {
      if (args.size() < 2)
        throw InputError("command line",
                         0,
                         "solve",
                         "'solve' needs a scene file",
                         "run 'palpate solve SCENE.prm [--to X,Y,Z]'.");
      check_options(args, 2, {{"--to", "--to 0,0,-0.02"}});
      std::optional<Utilities::Point3> target;
      for (unsigned int i = 2; i < args.size(); ++i)
        if (args[i] == "--to" && i + 1 < args.size())
          {
            try
              {
                target = Utilities::parse_point(args[++i]);
              }
            catch (const std::invalid_argument &e)
              {
                throw InputError("command line",
                                 0,
                                 "--to " + args[i],
                                 e.what(),
                                 "give the displacement in metres as "
                                 "X,Y,Z, e.g. --to 0,0,-0.02.");
              }
          }
        else
          throw unexpected(args[i]);
      return run_scene(args[1], settings, target, true, out);
    }



    /** palpate serve SCENE.prm [--port P] [--host H]: the live view. */
    int
    run_serve_command(const std::vector<std::string> &args,
                      const std::vector<std::string> &settings,
                      std::ostream                   &out)
    {
      if (args.size() < 2 || args[1].empty() || args[1][0] == '-')
        throw InputError("command line",
                         0,
                         "serve",
                         "'serve' needs a scene file",
                         "run 'palpate serve SCENE.prm [--port P]'.");
      // Under mpirun the servers read this scene too and now wait for
      // its engine: released however this ends, a bad option included.
      const auto release =
        release_servers_at_end(Scene::read(args[1], settings));
      check_options(
        args, 2, {{"--port", "--port 8080"}, {"--host", "--host 127.0.0.1"}});
      int         port = 8080;
      std::string host = "127.0.0.1";
      for (unsigned int i = 2; i < args.size(); ++i)
        if (args[i] == "--port" && i + 1 < args.size())
          port = static_cast<int>(
            number_argument("--port", args[++i], 1, 65535, "8080"));
        else if (args[i] == "--host" && i + 1 < args.size())
          {
            host = args[++i];
            // "http://localhost/": a URL, not an address.
            if (host.find("://") != std::string::npos ||
                host.find('/') != std::string::npos)
              throw InputError("command line",
                               0,
                               "--host " + host.substr(0, 80),
                               "a URL, not an address or a host name",
                               "give only the address or name, e.g. --host "
                               "127.0.0.1 (and the port with --port).");
            // "[::1]:8080": an IPv6 address with a port after it.
            if (!host.empty() && host.front() == '[')
              if (const auto close = host.find("]:");
                  close != std::string::npos)
                throw InputError(
                  "command line",
                  0,
                  "--host " + host.substr(0, 80),
                  "the address has a port in it ('" +
                    host.substr(close + 1, 20) + "')",
                  "give the port with --port: --host " +
                    host.substr(0, std::min<std::size_t>(close + 1, 80)) +
                    " --port " + host.substr(close + 2, 20) + ".");
            // "127.0.0.1:80": a port written into the address (an IPv6
            // address has several colons, or brackets).
            if (const auto colon = host.find(':');
                colon != std::string::npos && colon > 0 &&
                host.find(':', colon + 1) == std::string::npos &&
                host.front() != '[')
              throw InputError("command line",
                               0,
                               "--host " + host.substr(0, 80),
                               "the address has a port in it (':" +
                                 host.substr(colon + 1, 20) + "')",
                               "give the port with --port: --host " +
                                 host.substr(0,
                                             std::min<std::size_t>(colon, 80)) +
                                 " --port " + host.substr(colon + 1, 20) + ".");
            // An address or a host name: letters, digits, '.', '-',
            // and ':' '[' ']' for IPv6. An empty one would listen on
            // every interface without saying so.
            const bool valid =
              !host.empty() && host.size() <= 253 &&
              std::all_of(host.begin(), host.end(), [](const char c) {
                return std::isalnum(static_cast<unsigned char>(c)) ||
                       c == '.' || c == '-' || c == ':' || c == '[' || c == ']';
              });
            if (!valid)
              throw InputError(
                "command line",
                0,
                "--host '" + host.substr(0, 80) + "'",
                host.empty() ? "the address to listen on is empty" :
                               "not an address or a host name (letters, "
                               "digits, '.', '-'; IPv6 in brackets)",
                "give 127.0.0.1 (this machine only, the default), "
                "0.0.0.0 (every interface) or one of this machine's "
                "addresses.");
            // An IPv6 address as a URL writes it, [::1]: the address
            // itself is inside the brackets.
            if (host.size() > 2 && host.front() == '[' && host.back() == ']')
              host = host.substr(1, host.size() - 2);
          }
        else
          throw unexpected(args[i]);
      const Scene scene = read_and_report(args[1], settings, out);
      return run_serve(out, scene, host, port);
    }



    /** palpate precompute SCENE.prm [--radius R]: states into the store. */
    int
    run_precompute_command(const std::vector<std::string> &args,
                           const std::vector<std::string> &settings,
                           std::ostream                   &out)
    {
      if (args.size() < 2 || args[1].empty() || args[1][0] == '-')
        throw InputError("command line",
                         0,
                         "precompute",
                         "'precompute' needs a scene file",
                         "run 'palpate precompute SCENE.prm [--radius "
                         "R]'.");
      // Under mpirun the servers read this scene too and now wait for
      // its engine: released however this ends, a bad option included.
      const auto release =
        release_servers_at_end(Scene::read(args[1], settings));
      check_options(args, 2, {{"--radius", "--radius 0.05"}});
      double radius = 0;
      for (unsigned int i = 2; i < args.size(); ++i)
        if (args[i] == "--radius" && i + 1 < args.size())
          radius = number_argument("--radius", args[++i], 1e-4, 10, "0.05");
        else
          throw unexpected(args[i]);
      const Scene scene = read_and_report(args[1], settings, out);
      return run_precompute(out, scene, radius);
    }



    /** palpate study SCENE.prm [options]: what accuracy costs in time. */
    int
    run_study_command(const std::vector<std::string> &args,
                      const std::vector<std::string> &settings,
                      std::ostream                   &out)
    {
      if (args.size() < 2 || args[1].empty() || args[1][0] == '-')
        throw InputError("command line",
                         0,
                         "study",
                         "'study' needs a scene file",
                         "run 'palpate study SCENE.prm [--quick]'.");
      check_options(args,
                    2,
                    {{"--finer-mesh", "--finer-mesh finer.msh"},
                     {"--csv", "--csv study.csv"},
                     {"--time-limit", "--time-limit 600"},
                     {"--skip", "--skip element,mesh"},
                     {"--samples", "--samples 240"}});
      StudyOptions options;
      for (unsigned int i = 2; i < args.size(); ++i)
        {
          const bool has_value = i + 1 < args.size();
          if (args[i] == "--quick")
            options.quick = true;
          else if (args[i] == "--finer-mesh" && has_value)
            options.finer_mesh = args[++i];
          else if (args[i] == "--csv" && has_value)
            {
              options.csv_file  = args[++i];
              options.csv_given = true;
            }
          else if (args[i] == "--time-limit" && has_value)
            options.time_limit =
              number_argument("--time-limit", args[++i], 1, 7 * 86400, "600");
          else if (args[i] == "--skip" && has_value)
            {
              const std::string           knobs = args[++i];
              const std::set<std::string> known = {"grid",
                                                   "tolerance",
                                                   "increment",
                                                   "combined",
                                                   "mesh",
                                                   "element"};
              std::stringstream           list(knobs);
              for (std::string knob; std::getline(list, knob, ',');)
                {
                  if (known.count(knob) == 0)
                    throw InputError(
                      "command line",
                      0,
                      "--skip " + knobs,
                      "'" + knob + "' is not one of the study's knobs",
                      "name some of grid, tolerance, increment, "
                      "combined, mesh, element, separated by commas: "
                      "e.g. --skip element,mesh.");
                  options.skip.push_back(knob);
                }
            }
          else if (args[i] == "--samples" && has_value)
            {
              const std::string v = args[++i];
              long              n = 0;
              if (!Utilities::parse_whole_number(v, n) || n < 8 || n > 5000)
                throw InputError("command line",
                                 0,
                                 "--samples " + v,
                                 "the number of HIP positions must be a "
                                 "whole number from 8 to 5000",
                                 "e.g. --samples 240 (the default; 80 "
                                 "with --quick).");
              options.samples = static_cast<unsigned int>(n);
            }
          else
            throw unexpected(args[i]);
        }
      if (const std::string why = why_cannot_open(options.finer_mesh);
          !options.finer_mesh.empty() && !std::ifstream(options.finer_mesh))
        throw InputError("command line",
                         0,
                         "--finer-mesh " + options.finer_mesh,
                         "the mesh file '" + options.finer_mesh +
                           "' cannot be read: " +
                           (why.empty() ? "it cannot be opened" : why),
                         "give a finer mesh of the same organ, in the "
                         "scene's file unit (its Scale factor applies).");
      const Scene       scene  = read_and_report(args[1], settings, out);
      const StudyResult result = run_study(out, scene, options);
      if (result.stop_signal != 0)
        {
          out.flush();
          std::cerr << "\npalpate: the study was " << result.stopped
                    << "; what it measured was printed and written to "
                    << result.csv_file << ". Exit status "
                    << 128 + result.stop_signal << ".\n";
          return 128 + result.stop_signal;
        }
      return ExitStatus::success;
    }



    /**
     * ", did you mean 'solve'?" for a word at most two edits (Levenshtein)
     * from a command, else nothing.
     */
    std::string
    nearest_command(const std::string &word)
    {
      std::string best;
      std::size_t best_distance = 3;
      for (const std::string command :
           {"solve", "study", "precompute", "serve", "mesh"})
        {
          std::vector<std::size_t> row(command.size() + 1);
          for (std::size_t j = 0; j <= command.size(); ++j)
            row[j] = j;
          for (std::size_t i = 1; i <= word.size(); ++i)
            {
              std::size_t diagonal = row[0];
              row[0]               = i;
              for (std::size_t j = 1; j <= command.size(); ++j)
                {
                  const std::size_t above = row[j];
                  row[j] =
                    std::min({row[j] + 1,
                              row[j - 1] + 1,
                              diagonal + (word[i - 1] != command[j - 1])});
                  diagonal = above;
                }
            }
          if (row.back() < best_distance)
            {
              best_distance = row.back();
              best          = command;
            }
        }
      return best.empty() ? std::string() : " (did you mean '" + best + "'?)";
    }



    int
    dispatch(const std::vector<std::string> &args,
             const std::vector<std::string> &settings,
             std::ostream                   &out)
    {
      const bool reads_scene =
        !args.empty() && args[0] != "mesh" &&
        (args[0] == "solve" || args[0] == "serve" || args[0] == "precompute" ||
         args[0] == "study" || args[0].empty() || args[0][0] != '-');
      if (!settings.empty() && !reads_scene)
        throw InputError("command line",
                         0,
                         "--set " + settings.front(),
                         "--set changes an entry of a scene, and '" +
                           (args.empty() ? std::string("palpate") : args[0]) +
                           "' reads none",
                         "use it with a scene: 'palpate SCENE.prm --set "
                         "ENTRY=VALUE', or with solve, study, precompute or "
                         "serve.");
      // Asked anywhere (else `palpate solve --help` would read --help as
      // the scene), or as `palpate help`: the usage, which gives every
      // command's arguments (`palpate help solve` too: the usage is one
      // page for all commands).
      const bool asks_help = std::any_of(args.begin(),
                                         args.end(),
                                         [](const std::string &a) {
                                           return a == "--help" || a == "-h";
                                         }) ||
                             (!args.empty() && args[0] == "help" &&
                              !std::filesystem::exists(args[0]));
      if (args.empty() || asks_help)
        {
          out << usage;
          return args.empty() ? ExitStatus::input_error : ExitStatus::success;
        }
      if (args[0] == "--version")
        {
          out << "palpate " << PALPATE_VERSION << "\n";
          return ExitStatus::success;
        }
      if (args[0] == "--print-parameters")
        {
          const std::string format = args.size() > 1 ? args[1] : "prm";
          if (format != "prm" && format != "markdown")
            throw InputError("command line",
                             0,
                             "--print-parameters " + format,
                             "unknown format '" + format + "'",
                             "use 'prm' (default) or 'markdown'.");
          print_parameters(out,
                           format == "prm" ? ParameterFormat::prm :
                                             ParameterFormat::markdown);
          return ExitStatus::success;
        }
      if (args[0].size() > 1 && args[0][0] == '-')
        throw InputError("command line",
                         0,
                         args[0],
                         "unknown option '" + args[0] + "'",
                         "run 'palpate --help' for the options.");
      if (args[0] == "solve")
        return run_solve_command(args, settings, out);
      if (args[0] == "mesh")
        return run_mesh(args, out);
      if (args[0] == "serve")
        return run_serve_command(args, settings, out);
      if (args[0] == "precompute")
        return run_precompute_command(args, settings, out);
      if (args[0] == "study")
        return run_study_command(args, settings, out);
      // A first word that is no file, followed by more, is a command
      // mistyped ("palpate slove scene.prm"), not a scene with an
      // unexpected argument. Alone, a word two edits from a command is one
      // too ("palpate slove" is not a file 'slove' that does not exist).
      if ((args.size() > 1 || !nearest_command(args[0]).empty()) &&
          args[0].find('/') == std::string::npos &&
          std::filesystem::path(args[0]).extension() != ".prm" &&
          !std::filesystem::exists(args[0]))
        throw InputError("command line",
                         0,
                         args[0],
                         "unknown command '" + args[0] + "'",
                         "the commands are solve, study, precompute, serve "
                         "and mesh" +
                           nearest_command(args[0]) +
                           "; a scene alone runs as 'palpate SCENE.prm'.");
      if (args.size() > 1)
        throw InputError("command line",
                         0,
                         args[1],
                         "unexpected argument '" + args[1] + "'",
                         "run 'palpate --help' for the usage.");
      return run_scene(args[0], settings, std::nullopt, false, out);
    }
  } // namespace



  int
  run_application(int argc, char **argv, std::ostream &out, std::ostream &err)
  {
    // `--set ENTRY=VALUE` (or `--set=ENTRY=VALUE`), anywhere and
    // repeatable, changes the scene any subcommand reads; the rest is the
    // subcommand's.
    std::vector<std::string> args, settings;
    bool                     dangling_set = false;
    for (int i = 1; i < argc; ++i)
      {
        const std::string a = argv[i];
        if (a == "--set" && i + 1 < argc)
          settings.emplace_back(argv[++i]);
        else if (a.compare(0, 6, "--set=") == 0)
          settings.push_back(a.substr(6));
        else
          {
            dangling_set = dangling_set || a == "--set";
            args.push_back(a);
          }
      }
    ignore_broken_pipes();
    if (mpi_rank() > 0)
      return run_server_rank(args, settings, dangling_set, err);
    try
      {
        if (dangling_set)
          throw InputError(
            "command line",
            0,
            "--set",
            "--set needs ENTRY=VALUE after it",
            "e.g. --set 'Material model/Model name=Neo-Hookean'.");
        const int status = dispatch(args, settings, out);
        // Output that could not be written (a closed pipe: SIGPIPE is
        // ignored; /dev/full; a full disk) is an error, not exit 0.
        out.flush();
        if (!out && status == ExitStatus::success)
          {
            err << "\npalpate: output failed: the standard output could not "
                   "be written (a closed pipe, or a full disk); what it "
                   "printed was lost.\n  fix:     send it to a file on a "
                   "disk with room, or read the run's CSV/JSON summaries "
                   "(Output / Summary formats).\n";
            return ExitStatus::output_failed;
          }
        return status;
      }
    catch (const InputError &e)
      {
        out.flush();
        err << "\npalpate: the input has a problem, " << e.what() << "\n";
        return ExitStatus::input_error;
      }
    catch (const OutputError &e)
      {
        out.flush();
        err << "\npalpate: output failed: " << e.what() << "\n";
        return ExitStatus::output_failed;
      }
    catch (const std::filesystem::filesystem_error &e)
      {
        // A path the file system refuses (a loop of links, a name too
        // long, no permission) that no check above named: the user's
        // input, said as such, with the path.
        out.flush();
        err << "\npalpate: the input has a problem: the file system refuses "
               "the path '"
            << e.path1().string() << "' (" << e.code().message()
            << ")\n  fix:     check the paths the scene and the command "
               "line name (Output / Directory, State space / Store, the "
               "mesh): a loop of symbolic links, a name longer than the "
               "system allows, or a missing permission.\n";
        return ExitStatus::input_error;
      }
    catch (const NotAvailableError &e)
      {
        out.flush();
        err << "\npalpate: " << e.what() << "\n";
        return ExitStatus::not_available;
      }
    catch (const StoppedError &e)
      {
        out.flush();
        err << "\npalpate: " << e.what() << "\n";
        return e.exit_status;
      }
    catch (const std::exception &e)
      {
        out.flush();
        err << "\npalpate: internal error: " << e.what()
            << "\n  This is a bug or the machine ran out of a resource. "
               "Please report it with the scene file and this message.\n";
        return ExitStatus::internal_error;
      }
    catch (...)
      {
        out.flush();
        err << "\npalpate: internal error of unknown type.\n";
        return ExitStatus::internal_error;
      }
  }
} // namespace palpate
