// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

// The client of an MPI run is lost (issue 26): `mpirun --enable-recovery
// -np 3 palpate parameters/liver-stvk-mpi.prm`, and once the motion has
// started rank 0 is killed (SIGKILL, as a crashed machine or the OOM
// killer would). Under --enable-recovery nobody ends the two solver
// servers; before, they idled for ever and so did mpirun. Now the client
// sends a heartbeat every 0.1 s, and a server that has heard nothing from
// it for Engine / Server timeout (3 s here: with 1 s, under CI's load
// beside other tests, a server's communicator stood still 1.1 s, blamed
// itself, "stood still ... and it ends", and the other said nothing) says
// so on standard error and ends (run_solver_server()):
// - mpirun ends within 30 s of the kill (about 3-4 s here);
// - each of the two servers said why it ended, naming the setting.
//
// The test starts mpirun itself (from PATH, with the harness's flags) and
// finds rank 0 among its children by OMPI_COMM_WORLD_RANK.

#include <chrono>
#include <filesystem>
#include <fstream>

#include "../tests.h"

#include "../processes.h"

namespace
{
  using namespace test_processes;

  /** The processes whose parent is @p parent. */
  std::vector<pid_t>
  children_of(const pid_t parent)
  {
    std::vector<pid_t> children;
    for (const auto &entry : std::filesystem::directory_iterator("/proc"))
      {
        const std::string name = entry.path().filename();
        if (name.find_first_not_of("0123456789") != std::string::npos)
          continue;
        // /proc/PID/stat: "PID (COMM) STATE PPID ...", COMM may hold spaces.
        const std::string stat = read_file(entry.path().string() + "/stat");
        const auto        end  = stat.rfind(')');
        if (end == std::string::npos)
          continue;
        std::istringstream rest(stat.substr(end + 1));
        std::string        state;
        pid_t              ppid = 0;
        rest >> state >> ppid;
        if (ppid == parent)
          children.push_back(std::stoi(name));
      }
    return children;
  }

  /** The child of @p mpirun that is MPI rank @p rank, or 0. */
  pid_t
  rank_process(const pid_t mpirun, const int rank)
  {
    const std::string wanted =
      "OMPI_COMM_WORLD_RANK=" + std::to_string(rank) + '\0';
    for (const pid_t child : children_of(mpirun))
      {
        const std::string environment =
          read_file("/proc/" + std::to_string(child) + "/environ");
        if (environment.find('\0' + wanted) != std::string::npos ||
            environment.rfind(wanted, 0) == 0)
          return child;
      }
    return 0;
  }
} // namespace



int
main()
{
  initlog();
  const std::string dir = std::filesystem::absolute("mpi-client-loss");
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  const std::string out = dir + "/stdout.txt", err = dir + "/stderr.txt";

  std::vector<std::string> argv{"mpirun",
                                "--oversubscribe",
                                "--enable-recovery"};
  if (geteuid() == 0)
    argv.push_back("--allow-run-as-root");
  const std::vector<std::string> run{"-np",
                                     "3",
                                     palpate_executable,
                                     palpate_source_dir +
                                       "/parameters/liver-stvk-mpi.prm",
                                     "--set",
                                     "Engine/Server timeout=3",
                                     "--set",
                                     "Haptics/Trajectory/Speed=0.001",
                                     "--set",
                                     "Haptics/Trajectory/Duration=60",
                                     "--set",
                                     "Output/Directory=" + dir};
  argv.insert(argv.end(), run.begin(), run.end());
  const pid_t mpirun  = start(argv, out, err);
  const bool  started = wait_for_text(out, "; motion starts", 300);
  deallog << "the motion started: " << ok(started) << std::endl;

  // Rank 0 is killed as soon as it is found: the servers are then serving
  // the motion.
  pid_t client = 0;
  wait_until(
    [&] {
      client = rank_process(mpirun, 0);
      return client > 0;
    },
    generous_deadline,
    "rank 0 among mpirun's children",
    std::chrono::milliseconds(50));
  deallog << "rank 0 found among mpirun's children: " << ok(client > 0)
          << std::endl;
  if (client > 0)
    kill(client, SIGKILL);

  int        status = 0;
  const bool ended  = wait_status_for(mpirun, 30, status);
  deallog << "mpirun ended within 30 s of the kill: " << ok(ended) << std::endl;
  if (!ended)
    {
      for (const pid_t child : children_of(mpirun))
        kill(child, SIGKILL);
      kill(mpirun, SIGKILL);
      wait_status(mpirun);
    }

  const std::string said = read_file(err);
  deallog << "servers that said the client was lost: "
          << count(said, "the client (rank 0) sent nothing for") << std::endl;
  deallog << "naming the setting: "
          << count(said, "(Engine / Server timeout): it is lost") << std::endl;
  deallog
    << "one of those lines: "
    << line_with(said, "palpate (solver server, MPI rank 1)").substr(0, 35)
    << std::endl;
  if (!started || !ended)
    std::cerr << "mpi_client_loss: stdout:\n"
              << read_file(out) << "\nstderr:\n"
              << said << std::endl;
}
