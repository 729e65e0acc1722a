// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

#include <palpate/app/application.h>
#include <palpate/app/application_impl.h>
#include <palpate/base/exceptions.h>
#include <palpate/base/stop_request.h>
#include <palpate/engine/mpi_engine.h>
#include <palpate/scene/scene.h>

#include <algorithm>
#include <filesystem>
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
        return internal::run_solve_command(args, settings, out);
      if (args[0] == "mesh")
        return internal::run_mesh(args, out);
      if (args[0] == "serve")
        return internal::run_serve_command(args, settings, out);
      if (args[0] == "precompute")
        return internal::run_precompute_command(args, settings, out);
      if (args[0] == "study")
        return internal::run_study_command(args, settings, out);
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
      return internal::run_scene(args[0], settings, std::nullopt, false, out);
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
      return internal::run_server_rank(args, settings, dangling_set, err);
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
