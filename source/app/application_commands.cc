// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

#include <palpate/app/application.h>
#include <palpate/app/application_impl.h>
#include <palpate/app/precompute.h>
#include <palpate/app/serve.h>
#include <palpate/app/study.h>
#include <palpate/base/exceptions.h>
#include <palpate/base/stop_request.h>
#include <palpate/mesh/volume_mesher.h>
#include <palpate/scene/scene.h>

#include <algorithm>
#include <cctype>
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
  namespace internal
  {
    InputError
    unexpected(const std::string &argument)
    {
      return InputError("command line",
                        0,
                        argument,
                        "unexpected argument '" + argument + "'",
                        "run 'palpate --help' for the usage.");
    }



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



    namespace
    {
      /** What palpate mesh's options ask for. */
      struct MeshOptions
      {
        double       scale = 1, time_limit = 60;
        unsigned int nodes = 1500;
        MeshGrading  grading;
      };



      /** palpate mesh's options, from args[3] on, read and checked. */
      MeshOptions
      mesh_options(const std::vector<std::string> &args)
      {
        MeshOptions   options;
        double       &scale = options.scale, &time_limit = options.time_limit;
        unsigned int &nodes   = options.nodes;
        MeshGrading  &grading = options.grading;
        bool          refine = false, radius_given = false;
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
        return options;
      }



      /**
       * That palpate mesh may write its output args[2]: a .msh, no link to
       * nowhere, no file of the user's that is no mesh, a directory it can
       * write in.
       */
      void
      check_mesh_output(const std::vector<std::string> &args)
      {
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
      }
    } // namespace



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
      const MeshOptions options = mesh_options(args);
      check_mesh_output(args);
      out << "palpate mesh: " << args[1] << " -> " << args[2] << " (about "
          << options.nodes << " nodes, "
          << Utilities::to_string(options.scale, 6) << " m per file unit)\n";
      // A stop signal ends the meshing child and removes its files
      // (StoppedError); without it the child outlived palpate.
      const StopRequest       stop;
      const SurfaceMeshReport report = mesh_surface_file(args[1],
                                                         options.scale,
                                                         "--scale",
                                                         options.nodes,
                                                         options.time_limit,
                                                         args[2],
                                                         options.grading);
      for (const auto &line : report.lines())
        out << "  " << line << "\n";
      out << "  use it:        subsection Mesh: set Source = file, set File "
             "name = "
          << args[2] << ", set Scale factor = 1 (the mesh is in metres)\n";
      return ExitStatus::success;
    }



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
  } // namespace internal
} // namespace palpate
