// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

// A stop loses nothing (issue 26): SIGINT, SIGTERM and SIGHUP in the middle
// of an interaction end it through its normal path - the run summary with a
// STOPPED line, the force log up to the stop, the CSV/JSON summaries and a
// closed PVD index whose frame count is the summary's - and the exit status
// is 128 + the signal. A closed pipe on standard output (what `| head -1`
// does) and /dev/full are output errors (status 6) that still write the
// files. SIGKILL leaves a whole PVD index of the frames on disk.
// `palpate study` stopped by SIGINT, or past --time-limit, prints
// and writes (CSV) the rows it measured.
//
// The program runs as a child with its standard output in a file; the
// signal is sent once the output says the motion started (or, for the
// study, once a knob's first state was computed).

#include <fcntl.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <thread>

#include "../tests.h"

#include "../processes.h"

namespace
{
  using namespace test_processes;

  /** The last force-log row's time (s), and the number of rows. */
  std::pair<double, unsigned int>
  force_log(const std::string &file)
  {
    std::ifstream in(file);
    std::string   line;
    double        last = -1;
    unsigned int  rows = 0;
    std::getline(in, line); // the header
    while (std::getline(in, line))
      if (!line.empty())
        {
          last = std::stod(line);
          ++rows;
        }
    return {last, rows};
  }

  /** The processor time (s) the process @p pid has used so far, all its
   * threads (/proc/PID/stat: utime and stime); -1 if it cannot be read. */
  double
  cpu_seconds(const pid_t pid)
  {
    const std::string stat =
      read_file("/proc/" + std::to_string(pid) + "/stat");
    // The fields after the command name (which may hold spaces), from the
    // third on: utime and stime are the 14th and 15th.
    const auto name_end = stat.rfind(')');
    if (name_end == std::string::npos)
      return -1;
    std::istringstream fields(stat.substr(name_end + 2));
    std::string        field;
    for (unsigned int k = 3; k < 14; ++k)
      fields >> field;
    double user = -1, system = -1;
    fields >> user >> system;
    if (!fields)
      return -1;
    return (user + system) / sysconf(_SC_CLK_TCK);
  }

  /** How many frames the PVD index @p file lists now. */
  unsigned int
  frames_listed(const std::string &file)
  {
    return test_processes::count(read_file(file), "<DataSet");
  }

  /**
   * Wait until the force log @p file has more than @p rows rows, the last
   * past t = @p t (s): the progress a check after a stop counts on having
   * happened before it. False (and a line on stderr) if it does not come
   * within a generous deadline. (palpate serve writes its log as it runs;
   * an interaction writes it at its end: see wait_for_motion().)
   */
  bool
  wait_for_rows(const std::string &file,
                const unsigned int rows,
                const double       t = 0)
  {
    return wait_until(
      [&] {
        const auto [last, logged] = force_log(file);
        return logged > rows && last > t;
      },
      generous_deadline,
      "more than " + std::to_string(rows) + " rows in " + file,
      std::chrono::milliseconds(20));
  }

  /**
   * Wait until the PVD index @p file lists a frame past @p t seconds of
   * motion (its timestep): an interaction's progress while it runs, since
   * its force log (a row per tick of motion) is written at its end. False
   * (and a line on stderr) if that does not come.
   */
  bool
  wait_for_motion(const std::string &file, const double t)
  {
    const auto last_timestep = [&] {
      const std::string pvd = read_file(file);
      const auto        at  = pvd.rfind("timestep=\"");
      return at == std::string::npos ? -1. : std::atof(pvd.c_str() + at + 10);
    };
    return wait_until([&] { return last_timestep() > t; },
                      generous_deadline,
                      "a frame past " + std::to_string(t) + " s of motion in " +
                        file,
                      std::chrono::milliseconds(20));
  }

  /** Wait until the PVD index @p file lists more than @p frames frames
   * (false, and a line on stderr, if that does not come). */
  bool
  wait_for_frames(const std::string &file, const unsigned int frames)
  {
    return wait_until([&] { return frames_listed(file) > frames; },
                      generous_deadline,
                      "more than " + std::to_string(frames) +
                        " frames listed in " + file,
                      std::chrono::milliseconds(20));
  }
} // namespace



int
main()
{
  initlog();
  const std::string dir = std::filesystem::absolute("stop-signals").string();
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  const std::string scene = palpate_source_dir + "/parameters/paper-stvk.prm";
  // A 30 s stroke at 1 mm/s, every output on. The cloud is the smallest
  // the scene checks allow (the 27 grid points of the cells around rest;
  // at least sqrt(3) grid spacings): the stops below come 1-2 s into the
  // motion, within the cell the probe starts in, and the scene's 515-point
  // cloud would only make each run wait for it.
  const std::vector<std::string> interaction = {
    scene,
    "--set",
    "Scheduler/Cloud radius=0.009",
    "--set",
    "Haptics/Trajectory/Speed=0.001",
    "--set",
    "Haptics/Trajectory/Duration=30",
    "--set",
    "Effects/Force log=true",
    "--set",
    "Effects/Shape output=true",
    "--set",
    "Output/Summary formats=csv,json",
    "--set",
    "Output/Directory=" + dir};
  const std::string out = dir + "/stdout.txt", err = dir + "/stderr.txt";
  // Before each run: no file of the last one (its outputs, its stdout's
  // "motion starts"); the .txt of other runs' stderr stay.
  const auto start_afresh = [&] {
    for (const auto &f : std::filesystem::directory_iterator(dir))
      if (f.path().extension() != ".txt")
        std::filesystem::remove(f.path());
    std::filesystem::remove(out);
  };

  for (const auto &[signal, name] : std::vector<std::pair<int, std::string>>{
         {SIGINT, "SIGINT"}, {SIGTERM, "SIGTERM"}, {SIGHUP, "SIGHUP"}})
    {
      start_afresh();
      const pid_t pid     = start_palpate(interaction, out, err);
      const bool  started = wait_for_text(out, "; motion starts");
      // Stopped once the shape output shows more than a second of motion
      // (1.2 s: 1000 ticks of the force log and a frame listed, what the
      // checks below look for; they fail if it never came).
      wait_for_motion(dir + "/paper-stvk-shape.pvd", 1.2);
      kill(pid, signal);
      const int         status = wait_status(pid);
      const std::string text   = read_file(out);
      const auto [last, rows]  = force_log(dir + "/paper-stvk-forces.csv");
      const std::string pvd    = read_file(dir + "/paper-stvk-shape.pvd");
      const std::string json   = read_file(dir + "/paper-stvk-summary.json");
      const std::string frames = line_with(text, "shape output:");
      deallog << name << ": motion started " << ok(started) << ", exit status "
              << status << " (128 + " << signal << ": "
              << ok(status == 128 + signal) << ")" << std::endl;
      deallog << "  summary printed "
              << ok(text.find("Run summary") != std::string::npos)
              << ", STOPPED line "
              << ok(line_with(text, "STOPPED:").find("by " + name) !=
                    std::string::npos)
              << ", stderr says so "
              << ok(read_file(err).find("stopped by " + name) !=
                    std::string::npos)
              << std::endl;
      // The force log runs until the stop (past the second waited for,
      // far short of the 30 s planned), a row per tick.
      deallog << "  force log: last row at t in (1, 25) s "
              << ok(last > 1 && last < 25) << ", rows " << ok(rows > 1000)
              << std::endl;
      deallog << "  JSON summary names the stop "
              << ok(json.find("\"stopped_by\": \"by " + name) !=
                    std::string::npos)
              << ", CSV summary written "
              << ok(std::filesystem::exists(dir + "/paper-stvk-summary.csv"))
              << std::endl;
      // The PVD index is complete and lists as many frames as the summary
      // says were written.
      const unsigned int listed = count(pvd, "<DataSet");
      deallog << "  PVD index closed "
              << ok(pvd.find("</VTKFile>") != std::string::npos)
              << ", frames listed = summary's "
              << ok(listed > 0 && frames.find(" " + std::to_string(listed) +
                                              " frames") != std::string::npos)
              << std::endl;
    }

  // A second Ctrl-C while the used states are written as VTU (the slowest
  // output) ends the process at once, as documented; the force log and the
  // summaries are on disk by then, since they are written before the VTU.
  // One signal delivered twice within milliseconds (as `timeout` or a
  // process manager may, to the process and to its group): the same stop,
  // not "a second Ctrl-C, end at once" - everything is written.
  {
    start_afresh();
    const pid_t pid     = start_palpate(interaction, out, err);
    const bool  started = wait_for_text(out, "; motion starts");
    wait_for_motion(dir + "/paper-stvk-shape.pvd", 0.7); // 500 ticks logged
    const auto first = std::chrono::steady_clock::now();
    kill(pid, SIGTERM);
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
    kill(pid, SIGTERM);
    // Under CI's load (a browser test beside it) the 5 ms sleep once took
    // longer than the 0.5 s that make two signals one stop: the second was
    // then a second Ctrl-C, as documented, and ended the process after it
    // had written everything. What this case checks holds only when the
    // two came within that time.
    const double gap =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - first)
        .count();
    const int status = wait_status(pid);
    deallog << "SIGTERM twice within 5 ms: motion started " << ok(started)
            << ", exit status 143 "
            << ok(status == 143 || (gap >= 0.45 && status == 1000 + SIGTERM))
            << ", summary printed "
            << ok(read_file(out).find("Run summary") != std::string::npos)
            << ", force log and JSON written "
            << ok(force_log(dir + "/paper-stvk-forces.csv").second > 500 &&
                  std::filesystem::exists(dir + "/paper-stvk-summary.json"))
            << std::endl;
  }

  // A stop in the initial cloud does not wait for the states being
  // computed: they give up at their next Newton iteration (on a large
  // organ a state takes seconds, too long to wait for at a stop). Here
  // each state takes seconds (increments of 0.1 mm), so two are running
  // when the signal comes, and the summary counts them given up.
  {
    start_afresh();
    std::vector<std::string> slow = interaction;
    slow.insert(slow.end(),
                {"--set", "Nonlinear solver/Maximum increment length=0.0001"});
    const pid_t pid     = start_palpate(slow, out, err);
    const bool  waiting = wait_for_text(out, "grid points around the rest");
    // The solver threads are the only ones working now (the haptic loop
    // sleeps between ticks, the main thread polls): once they have used a
    // second of processor time since the cloud started, states are being
    // computed, and none of them (seconds each) is done yet.
    const double at_start = cpu_seconds(pid);
    wait_until([&] { return cpu_seconds(pid) > at_start + 1; },
               generous_deadline,
               "a second of solving in the initial cloud",
               std::chrono::milliseconds(20));
    kill(pid, SIGTERM);
    const int         status = wait_status(pid);
    const std::string text   = read_file(out);
    const std::string json   = read_file(dir + "/paper-stvk-summary.json");
    const auto        given  = json.find("\"tasks_cancelled\": ");
    const int         given_up =
      given == std::string::npos ?
                -1 :
                std::stoi(json.substr(given + std::strlen("\"tasks_cancelled\": ")));
    deallog << "SIGTERM in the initial cloud: cloud started " << ok(waiting)
            << ", exit status 143 " << ok(status == 143)
            << ", before the motion "
            << ok(line_with(text, "STOPPED:").find("before the motion") !=
                  std::string::npos)
            << ", the running states given up " << ok(given_up >= 1)
            << std::endl;
  }

  // Two runs of one scene into one output directory would write the same
  // files (both said "wrote", the second's were the first's): the second
  // is refused before it computes anything, naming the first; the first
  // goes on and removes its lock file when it ends.
  {
    start_afresh();
    const pid_t       first      = start_palpate(interaction, out, err);
    const bool        started    = wait_for_text(out, "; motion starts");
    const std::string second_out = dir + "/second.txt";
    const pid_t second = start_palpate(interaction, second_out, second_out);
    const int   second_status = wait_status(second);
    const std::string message = read_file(second_out);
    kill(first, SIGTERM);
    const int first_status = wait_status(first);
    deallog << "a second run into the same directory: refused (exit 2) "
            << ok(started && second_status == 2) << ", naming the first "
            << ok(message.find("another palpate (process " +
                               std::to_string(first)) != std::string::npos)
            << "; the first goes on (stopped by SIGTERM: 143) "
            << ok(first_status == 143) << ", its lock file removed "
            << ok(!std::filesystem::exists(dir + "/paper-stvk.lock"))
            << std::endl;
  }

  // SIGKILL (or a crash, or mpirun ending a lost MPI client) cannot be
  // caught: nothing is written at the end. The PVD index is whole at every
  // moment and names every frame on disk but the one being written (it was
  // rewritten every 5 s: the last seconds' frames were on disk unnamed).
  {
    start_afresh();
    const pid_t pid     = start_palpate(interaction, out, err);
    const bool  started = wait_for_text(out, "; motion starts");
    wait_for_frames(dir + "/paper-stvk-shape.pvd", 10);
    kill(pid, SIGKILL);
    const int          status = wait_status(pid);
    const std::string  pvd    = read_file(dir + "/paper-stvk-shape.pvd");
    const unsigned int listed = count(pvd, "<DataSet");
    unsigned int       files  = 0;
    for (const auto &f : std::filesystem::directory_iterator(dir))
      files +=
        f.path().filename().string().find("-shape-") != std::string::npos &&
        f.path().extension() == ".vtu";
    bool named_exist = true;
    for (std::size_t at = pvd.find("file=\""); at != std::string::npos;
         at             = pvd.find("file=\"", at + 1))
      named_exist =
        named_exist &&
        std::filesystem::exists(
          dir + "/" + pvd.substr(at + 6, pvd.find('"', at + 6) - at - 6));
    deallog << "SIGKILL: motion started " << ok(started) << ", killed "
            << ok(status == 1000 + SIGKILL) << ", PVD index closed "
            << ok(pvd.find("</VTKFile>") != std::string::npos)
            << ", frames listed: all on disk but at most the one being "
               "written "
            << ok(listed > 10 && listed <= files && files <= listed + 1)
            << ", every listed frame there " << ok(named_exist) << std::endl;
  }

  {
    start_afresh();
    auto with_vtu = interaction;
    with_vtu.push_back("--set");
    with_vtu.push_back("Effects/VTU export=true");
    const pid_t pid     = start_palpate(with_vtu, out, err);
    const bool  started = wait_for_text(out, "; motion starts");
    wait_for_motion(dir + "/paper-stvk-shape.pvd", 1.2); // 1000 ticks logged
    kill(pid, SIGINT);
    // The export has begun once a state's file (or its temporary) is there.
    const auto exporting_now = [&] {
      for (const auto &f : std::filesystem::directory_iterator(dir))
        if (f.path().filename().string().rfind("paper-stvk-state-", 0) == 0)
          return true;
      return false;
    };
    const bool exporting = wait_until(exporting_now,
                                      generous_deadline,
                                      "a state file being exported",
                                      std::chrono::microseconds(500));
    kill(pid, SIGINT);
    const int status = wait_status(pid);
    // No state file cut short under its name: every .vtu is whole (one
    // being written when the signal came is left as NAME.vtu.part).
    bool no_partial = true;
    for (const auto &f : std::filesystem::directory_iterator(dir))
      if (f.path().extension() == ".vtu")
        no_partial =
          no_partial &&
          read_file(f.path().string()).find("</VTKFile>") != std::string::npos;
    const bool summary_kept =
      read_file(out).find("Run summary") != std::string::npos;
    deallog << "second SIGINT during the VTU export: motion started "
            << ok(started) << ", export began " << ok(exporting)
            << ", ended (status 130 or killed by SIGINT) "
            << ok(status == 130 || status == 1000 + SIGINT)
            << ", force log written "
            << ok(force_log(dir + "/paper-stvk-forces.csv").second > 1000)
            << ", summaries written "
            << ok(std::filesystem::exists(dir + "/paper-stvk-summary.csv") &&
                  std::filesystem::exists(dir + "/paper-stvk-summary.json"))
            << ", the printed summary kept " << ok(summary_kept)
            << ", no state file cut short " << ok(no_partial) << std::endl;
  }

  // One SIGINT after the motion, while the used states are exported as VTU:
  // everything is still written whole, and the exit status says the run was
  // stopped (it was 0, the signal unmentioned).
  {
    start_afresh();
    auto with_vtu = interaction;
    for (auto &argument : with_vtu)
      if (argument == "Haptics/Trajectory/Duration=30")
        argument = "Haptics/Trajectory/Duration=1";
    with_vtu.push_back("--set");
    with_vtu.push_back("Effects/VTU export=true");
    const pid_t pid       = start_palpate(with_vtu, out, err);
    const bool  exporting = wait_until(
      [&] {
        for (const auto &f : std::filesystem::directory_iterator(dir))
          if (f.path().filename().string().rfind("paper-stvk-state-", 0) == 0)
            return true;
        return false;
      },
      120,
      "a state file being exported after the motion",
      std::chrono::microseconds(500));
    kill(pid, SIGINT);
    const int status     = wait_status(pid);
    bool      no_partial = true;
    for (const auto &f : std::filesystem::directory_iterator(dir))
      if (f.path().extension() == ".vtu")
        no_partial =
          no_partial &&
          read_file(f.path().string()).find("</VTKFile>") != std::string::npos;
    deallog << "SIGINT during the VTU export after the motion: export began "
            << ok(exporting) << ", exit status 130 " << ok(status == 130)
            << ", stderr says when "
            << ok(read_file(err).find("while the outputs were written") !=
                  std::string::npos)
            << ", summaries written "
            << ok(std::filesystem::exists(dir + "/paper-stvk-summary.json"))
            << ", every state file whole " << ok(no_partial) << std::endl;
  }

  // `palpate solve` stopped in the middle of a long path (1000 increments):
  // within a Newton iteration it prints the history and how far it got,
  // writes the shape output and the force log, and exits 128 + 2.
  {
    std::filesystem::remove(out);
    const pid_t pid =
      start_palpate({"solve",
                     scene,
                     "--to",
                     "0,0,-0.02",
                     "--set",
                     "Nonlinear solver/Number of increments=1000",
                     "--set",
                     "Effects/Force log=true",
                     "--set",
                     "Effects/Shape output=true",
                     "--set",
                     "Output/Directory=" + dir},
                    out,
                    err);
    const bool started = wait_for_text(out, "active node:    from rest");
    // Stopped in the middle of the path, once two frames are listed.
    wait_for_frames(dir + "/paper-stvk-shape.pvd", 1);
    kill(pid, SIGINT);
    const int         status  = wait_status(pid);
    const std::string text    = read_file(out);
    const std::string reached = line_with(text, "reached:");
    const std::string pvd     = read_file(dir + "/paper-stvk-shape.pvd");
    const std::string log     = read_file(dir + "/paper-stvk-forces.csv");
    deallog << "solve, SIGINT: started " << ok(started) << ", exit status "
            << status << " " << ok(status == 130) << ", STOPPED line "
            << ok(line_with(text, "STOPPED:").find("by SIGINT") !=
                  std::string::npos)
            << ", part of the path reached "
            << ok(reached.find("% of the path") != std::string::npos &&
                  reached.find(" 100 %") == std::string::npos)
            << ", history printed "
            << ok(text.find("Newton history") != std::string::npos)
            << ", PVD closed with frames "
            << ok(pvd.find("</VTKFile>") != std::string::npos &&
                  count(pvd, "<DataSet") > 1)
            << std::endl;
    // The force log's row: not converged, the part of the path reached
    // and the force there (what the summary printed), not zero.
    std::vector<double> row;
    {
      std::istringstream lines(log);
      std::string        line;
      std::getline(lines, line); // the header
      std::getline(lines, line);
      std::istringstream fields(line);
      for (std::string field; std::getline(fields, field, ',');)
        row.push_back(std::atof(field.c_str()));
    }
    deallog << "  force log row: not converged "
            << ok(row.size() == 12 && row[6] == 0)
            << ", the part of the path reached "
            << ok(row.size() == 12 && row[8] > 0 && row[8] < 1)
            << ", the force there "
            << ok(row.size() == 12 &&
                  std::abs(row[3]) + std::abs(row[4]) + std::abs(row[5]) > 0)
            << std::endl;
  }

  // `palpate serve`: SIGINT is its normal end (status 0). The summary
  // names the stop and the state store; the force log, written as the
  // view runs, has a row per tick; Shape output is said to be not written.
  {
    std::filesystem::remove(out);
    const std::string port      = std::to_string(20000 + getpid() % 20000);
    const pid_t       pid       = start_palpate({"serve",
                                                 scene,
                                                 "--port",
                                                 port,
                                                 "--set",
                                                 "Effects/Force log=true",
                                                 "--set",
                                                 "Effects/Shape output=true",
                                                 "--set",
                                                 "Output/Summary formats=json",
                                                 "--set",
                                                 "State space/Store=" + dir + "/serve.h5",
                                                 "--set",
                                                 "Output/Directory=" + dir},
                                    out,
                                    err);
    const bool        listening = wait_for_text(out, "Live view: open");
    // A second live view of the scene into the same directory, on another
    // port: refused, naming the first (two would overwrite each other's
    // force log and summary).
    const std::string second_out = dir + "/second-serve.txt";
    const pid_t       second =
      start_palpate({"serve",
                     scene,
                     "--port",
                     std::to_string(20000 + (getpid() + 1) % 20000),
                     "--set",
                     "Effects/Force log=true",
                     "--set",
                     "Output/Summary formats=json",
                     "--set",
                     "Output/Directory=" + dir},
                    second_out,
                    second_out);
    const int second_status = wait_status(second);
    deallog << "a second serve into the same directory: refused (exit 2) "
            << ok(second_status == 2) << ", naming the first "
            << ok(read_file(second_out)
                    .find("another palpate (process " + std::to_string(pid) +
                          ") is running this scene with its outputs") !=
                  std::string::npos)
            << std::endl;
    wait_for_rows(dir + "/paper-stvk-serve-forces.csv", 1000, 1);
    kill(pid, SIGINT);
    const int         status = wait_status(pid);
    const std::string text   = read_file(out);
    const auto [last, rows]  = force_log(dir + "/paper-stvk-serve-forces.csv");
    deallog << "serve, SIGINT: listening " << ok(listening) << ", exit status "
            << status << " " << ok(status == 0) << ", STOPPED line "
            << ok(line_with(text, "STOPPED:").find("by SIGINT") !=
                  std::string::npos)
            << ", state store line "
            << ok(line_with(text, "state store:").find("serve.h5") !=
                  std::string::npos)
            << ", shape output said not written "
            << ok(text.find("Shape output: not written by palpate serve") !=
                  std::string::npos)
            << ", force log: a row per tick past 1 s "
            << ok(rows > 1000 && last > 1) << ", JSON names the stop "
            << ok(read_file(dir + "/paper-stvk-serve-summary.json")
                    .find("\"stopped_by\": \"by SIGINT") != std::string::npos)
            << std::endl;
  }

  // Standard output closed (a reader that went away, `| head -1`): the
  // write fails instead of SIGPIPE killing the program; the run stops,
  // writes its files and exits with status 6.
  {
    std::filesystem::remove(dir + "/paper-stvk-forces.csv");
    int fds[2];
    if (pipe(fds) != 0)
      return 1;
    fcntl(fds[0], F_SETFD, FD_CLOEXEC); // the child keeps only the write end
    const pid_t pid = start_palpate(interaction, "", err, fds[1]);
    close(fds[1]);
    char c = 0;
    while (read(fds[0], &c, 1) == 1 && c != '\n')
      {} // the first line, as head -1 reads it
    close(fds[0]);
    const int status = wait_status(pid);
    deallog << "closed pipe: exit status " << status << " " << ok(status == 6)
            << ", message "
            << ok(read_file(err).find("standard output could not be written") !=
                  std::string::npos)
            << ", force log written "
            << ok(std::filesystem::exists(dir + "/paper-stvk-forces.csv"))
            << std::endl;
  }

  // Standard output on a full device.
  {
    std::filesystem::remove(dir + "/paper-stvk-forces.csv");
    const pid_t pid    = start_palpate(interaction, "/dev/full", err);
    const int   status = wait_status(pid);
    deallog << "/dev/full: exit status " << status << " " << ok(status == 6)
            << ", message "
            << ok(read_file(err).find("standard output could not be written") !=
                  std::string::npos)
            << ", force log written "
            << ok(std::filesystem::exists(dir + "/paper-stvk-forces.csv"))
            << std::endl;
  }

  // --print-parameters on a full device: an output error (it was an
  // internal error: deal.II asserted on the failed stream).
  {
    const pid_t pid = start_palpate({"--print-parameters"}, "/dev/full", err);
    const int   status = wait_status(pid);
    deallog << "--print-parameters > /dev/full: exit status " << status << " "
            << ok(status == 6) << ", no internal error "
            << ok(read_file(err).find("internal error") == std::string::npos)
            << std::endl;
  }

  // The study, stopped by SIGINT once a grid knob's states are being
  // computed: the rows measured until then are printed and in the CSV.
  {
    const std::string csv = dir + "/study.csv";
    std::filesystem::remove(out);
    const pid_t pid     = start_palpate({"study",
                                         scene,
                                         "--quick",
                                         "--csv",
                                         csv,
                                         "--set",
                                         "Output/Directory=" + dir},
                                    out,
                                    err);
    const bool  started = wait_for_text(out, "  ... ");
    // Past the reference solves, into the grid knob's states.
    const bool in_grid = wait_for_text(out, ": grid ");
    std::this_thread::sleep_for(std::chrono::milliseconds(3000));
    kill(pid, SIGINT);
    const int         status = wait_status(pid);
    const std::string text   = read_file(out);
    // The rows it says it measured (printed in the tables after the
    // message) are the CSV's rows.
    // (None, if the stop came before the first knob setting was complete.)
    unsigned int printed = ~0u;
    if (const auto at = text.find("What it measured until then follows (");
        at != std::string::npos)
      printed = std::stoul(text.substr(at + 37));
    else if (text.find("Nothing was measured") != std::string::npos)
      printed = 0;
    const unsigned int in_csv = count(read_file(csv), "\n") - 1;
    deallog << "study, SIGINT: progress seen " << ok(started && in_grid)
            << ", exit status " << status << " " << ok(status == 130)
            << ", says it ended early "
            << ok(text.find("The study ended early: stopped by SIGINT") !=
                  std::string::npos)
            << ", rows printed = rows in the CSV " << ok(printed == in_csv)
            << ", no plot drawn after the stop "
            << ok(text.find("No Pareto plot: the study was stopped") !=
                    std::string::npos ||
                  printed == 0)
            << std::endl;
  }

  // The study stopped while its Pareto plot is drawn: a plot that hangs
  // (here python's start-up, through a sitecustomize on PYTHONPATH that
  // says it started and sleeps) is ended, and the study ends as stopped
  // (it held the plot's 120 s, then ended 0). On the beam: what is stopped
  // is the plot, whatever the study measured before it, and the beam's
  // study reaches its plot in seconds.
  {
    const std::string site   = dir + "/site";
    const std::string marker = dir + "/plot-started";
    std::filesystem::create_directories(site);
    write_file(site + "/sitecustomize.py",
               "import time\nopen('" + marker +
                 "', 'w').close()\ntime.sleep(600)\n");
    std::filesystem::remove(out);
    setenv("PYTHONPATH", site.c_str(), 1);
    const pid_t pid =
      start_palpate({"study",
                     palpate_source_dir + "/parameters/beam.prm",
                     "--quick",
                     "--skip",
                     "tolerance,increment,combined,mesh,"
                     "element",
                     "--samples",
                     "8",
                     "--csv",
                     dir + "/study-plot.csv",
                     "--set",
                     "Output/Directory=" + dir},
                    out,
                    err);
    unsetenv("PYTHONPATH");
    const bool started =
      wait_until([&] { return std::filesystem::exists(marker); },
                 300,
                 "the Pareto plot's python to start",
                 std::chrono::milliseconds(100));
    kill(pid, SIGTERM);
    int        status = -1;
    const bool ended  = wait_status_for(pid, 20, status);
    if (!ended)
      {
        kill(pid, SIGKILL);
        wait_status(pid);
      }
    const std::string text = read_file(out);
    deallog << "study, SIGTERM while the plot is drawn: plot started "
            << ok(started) << ", ended within 20 s " << ok(ended)
            << ", exit status " << status << " " << ok(status == 143)
            << ", says so "
            << ok(text.find("the study was stopped while drawing it") !=
                  std::string::npos)
            << std::endl;
  }

  // The study's time budget: the same path, exit status 0.
  {
    const std::string csv    = dir + "/study-budget.csv";
    const pid_t       pid    = start_palpate({"study",
                                              scene,
                                              "--quick",
                                              "--skip",
                                              "element,mesh",
                                              "--time-limit",
                                              "1",
                                              "--csv",
                                              csv,
                                              "--set",
                                              "Output/Directory=" + dir},
                                    out,
                                    err);
    const int         status = wait_status(pid);
    const std::string text   = read_file(out);
    deallog << "study, --time-limit 1: exit status " << status << " "
            << ok(status == 0) << ", says why "
            << ok(text.find("time budget (--time-limit 1 s) ran out") !=
                  std::string::npos)
            << ", CSV written " << ok(std::filesystem::exists(csv))
            << ", no element rows "
            << ok(text.find("Element order") == std::string::npos) << std::endl;
    // 1 s ends it before a knob setting is complete (here in its reference
    // solves): nothing measured is said, and no recommendation is made of
    // no rows.
    deallog << "  nothing measured, said "
            << ok(text.find("Nothing was measured, so there is no table and "
                            "no recommendation") != std::string::npos)
            << ", no recommendation "
            << ok(text.find("Recommendation (") == std::string::npos)
            << std::endl;
  }
  std::filesystem::remove_all(dir);
}
