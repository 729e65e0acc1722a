// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

#ifndef palpate_app_application_impl_h
#define palpate_app_application_impl_h

// Not an interface: the command line (run_application()), shared by its
// source files, one job each:
//   application.cc           run_application(): the arguments, the
//                            banner each kind of error ends in, and which
//                            command runs (the usage, a mistyped command)
//   application_scene.cc     running a scene (palpate SCENE.prm, solve),
//                            and the other MPI ranks' part in it
//   application_commands.cc  the commands' own options: mesh, solve,
//                            serve, precompute, study
// Users of the command line include application.h, never this header.

#include <palpate/base/exceptions.h>
#include <palpate/base/utilities.h>
#include <palpate/engine/mpi_engine.h>
#include <palpate/scene/scene.h>

#include <iosfwd>
#include <map>
#include <optional>
#include <string>
#include <vector>

namespace palpate
{
  namespace internal
  {
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
    release_servers_at_end(const Scene &scene);

    /**
     * A rank other than 0 of an MPI run: a solver server if the command
     * is an interaction with the MPI engine; otherwise nothing (rank 0
     * does the work and reports). Input errors are rank 0's to report.
     */
    int
    run_server_rank(const std::vector<std::string> &args,
                    const std::vector<std::string> &settings,
                    const bool                      dangling_set,
                    std::ostream                   &err);

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
              std::ostream                    &out);

    /** Read the scene @p file, build its mesh and nodes, and print its
     * report: what precompute, serve and study show first. */
    Scene
    read_and_report(const std::string              &file,
                    const std::vector<std::string> &settings,
                    std::ostream                   &out);

    /** The error for a command-line argument palpate does not know. */
    InputError
    unexpected(const std::string &argument);

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
                  const std::map<std::string, std::string> &values);

    /** A whole number or a positive number from the command line. */
    double
    number_argument(const std::string &option,
                    const std::string &value,
                    const double       lo,
                    const double       hi,
                    const std::string &example);

    /** palpate mesh SURFACE OUT.msh [--nodes N] [--scale S]
     * [--time-limit T]. */
    int
    run_mesh(const std::vector<std::string> &args, std::ostream &out);

    /** palpate solve SCENE.prm [--to X,Y,Z]: a static solve. */
    int
    run_solve_command(const std::vector<std::string> &args,
                      const std::vector<std::string> &settings,
                      std::ostream                   &out);

    /** palpate serve SCENE.prm [--port P] [--host H]: the live view. */
    int
    run_serve_command(const std::vector<std::string> &args,
                      const std::vector<std::string> &settings,
                      std::ostream                   &out);

    /** palpate precompute SCENE.prm [--radius R]: states into the store. */
    int
    run_precompute_command(const std::vector<std::string> &args,
                           const std::vector<std::string> &settings,
                           std::ostream                   &out);

    /** palpate study SCENE.prm [options]: what accuracy costs in time. */
    int
    run_study_command(const std::vector<std::string> &args,
                      const std::vector<std::string> &settings,
                      std::ostream                   &out);
  } // namespace internal
} // namespace palpate

#endif
