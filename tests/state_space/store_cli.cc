// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

// The state store as a user meets it (issue 26), running the palpate
// program on the beam with a store:
// - two `palpate precompute` on one store: while the first runs (stopped
//   with SIGSTOP, so that it surely runs), a second precompute and an
//   interaction on the same store are refused with exit status 2, naming
//   the first (pid, command) and the fix; the first then finishes with no
//   damaged record, and says exactly what the store keeps;
// - SIGHUP, SIGTERM and SIGINT stop a precompute cleanly: it says how many
//   states and failure points the store keeps, which is what the file
//   holds, and exits with 128 + the signal's number;
// - a precompute whose writes fail (a file size limit: as a full disk,
//   deterministically, with no mount and no root) exits 6, and every count
//   it prints (appended, kept) is what the file holds;
// - a store that cannot be opened says why, with its own fix: a
//   directory, a device, a text file, an empty file, an HDF5 file that is
//   not a store, a damaged (truncated) store, a store in a directory that
//   does not exist, a read-only store, a new store in a directory that is
//   not writable. Only the damaged one is called damaged.

#include <palpate/base/exceptions.h>
#include <palpate/state_space/state_store.h>

#include <fcntl.h>
#include <hdf5.h>
#include <signal.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <csignal>
#include <filesystem>
#include <functional>
#include <regex>
#include <thread>

#include "../tests.h"

namespace
{
  const std::string scene_text = "subsection Mesh\n"
                                 "  set Source = beam\n"
                                 "end\n"
                                 "subsection Boundary conditions\n"
                                 "  subsection Fixed nodes\n"
                                 "    set Selection    = boundary id\n"
                                 "    set Boundary ids = 0\n"
                                 "  end\n"
                                 "  subsection Active node\n"
                                 "    set Point = 0.1, 0, 0.01\n"
                                 "  end\n"
                                 "end\n"
                                 "subsection State space\n"
                                 "  set Store        = beam.h5\n"
                                 "  set Grid spacing = 0.002\n"
                                 "  set Extent       = 0.02\n"
                                 "end\n"
                                 "subsection Scheduler\n"
                                 "  set Cloud radius = 0.0045\n"
                                 "end\n";

  /** What a program run started by start() did. */
  struct Started
  {
    pid_t       pid;
    std::string output_file;
  };

  /**
   * Start `palpate ARGS` (split at spaces; '+' in an argument stands for a
   * space) in the background, stdout and stderr into @p output_file. With
   * @p file_size_limit > 0 (bytes), the program runs with RLIMIT_FSIZE set
   * to it and SIGXFSZ ignored: a write past the limit fails with EFBIG, as
   * one on a full disk fails with ENOSPC. Open MPI's shared-memory
   * session files would hit the limit too: PMIX_MCA_gds=hash keeps it out
   * of them.
   */
  Started
  start(const std::string &arguments,
        const std::string &output_file,
        const rlim_t       file_size_limit = 0)
  {
    std::vector<std::string> words{palpate_executable};
    std::istringstream       in(arguments);
    for (std::string w; in >> w;)
      words.push_back(std::regex_replace(w, std::regex("\\+"), " "));
    const pid_t pid = fork();
    if (pid == 0)
      {
        const int fd = open(output_file.c_str(),
                            O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC,
                            0644);
        dup2(fd, 1);
        dup2(fd, 2);
        if (file_size_limit > 0)
          {
            signal(SIGXFSZ, SIG_IGN);
            const rlimit l{file_size_limit, file_size_limit};
            setrlimit(RLIMIT_FSIZE, &l);
            setenv("PMIX_MCA_gds", "hash", 1);
          }
        std::vector<char *> argv;
        for (auto &w : words)
          argv.push_back(w.data());
        argv.push_back(nullptr);
        execv(argv[0], argv.data());
        _exit(127);
      }
    return {pid, output_file};
  }

  /** Wait for @p run to end: its exit status, or 128 + the signal that
   * ended it (as a shell says). */
  int
  finish(const Started &run)
  {
    int status = 0;
    waitpid(run.pid, &status, 0);
    return WIFEXITED(status)   ? WEXITSTATUS(status) :
           WIFSIGNALED(status) ? 128 + WTERMSIG(status) :
                                 -1;
  }

  /** Run `palpate ARGS` to its end: (exit status, output). */
  std::pair<int, std::string>
  run(const std::string &arguments, const rlim_t file_size_limit = 0)
  {
    const Started r      = start(arguments, "run.txt", file_size_limit);
    const int     status = finish(r);
    return {status, read_file("run.txt")};
  }

  /** The message palpate ended with ("palpate: ..." to the end), with
   * this machine's paths, pids, users and times made neutral. */
  std::string
  message(std::string output, const pid_t pid = 0)
  {
    const auto at = output.find("palpate:");
    output = at == std::string::npos ? "(no message)" : output.substr(at);
    while (!output.empty() && output.back() == '\n')
      output.pop_back();
    const std::string dir = std::filesystem::current_path().string();
    for (auto p = output.find(dir); p != std::string::npos;
         p      = output.find(dir))
      output.replace(p, dir.size(), "<dir>");
    if (pid > 0)
      output =
        std::regex_replace(output,
                           std::regex("\\b" + std::to_string(pid) + "\\b"),
                           "<pid>");
    output = std::regex_replace(output, std::regex("\\('[^']*'\\)"), "(...)");
    output = std::regex_replace(output,
                                std::regex("since [0-9-]+ [0-9:]+ UTC"),
                                "since <time>");
    output = std::regex_replace(output, std::regex("uid [0-9]+"), "uid <uid>");
    return output;
  }

  /** What the store @p file holds, read as a reader does. */
  palpate::StateStore::Loaded
  contents(const std::string &file)
  {
    palpate::Scene scene = palpate::Scene::read("beam-store.prm");
    const Body     body(scene);
    return palpate::StateStore(file,
                               palpate::StoreFingerprint::of(body.scene,
                                                             body.mesh,
                                                             body.nodes),
                               palpate::StateStore::Access::read)
      .contents();
  }

  /** The numbers after @p pattern's groups in @p text, or {} if none. */
  std::vector<unsigned long>
  numbers(const std::string &text, const std::string &pattern)
  {
    std::smatch                m;
    std::vector<unsigned long> n;
    if (std::regex_search(text, m, std::regex(pattern)))
      for (std::size_t i = 1; i < m.size(); ++i)
        n.push_back(std::stoul(m[i].str()));
    return n;
  }

  /** The "store keeps: X states and Y failure points ... (Z appended by
   * this run" line of a precompute: {X, Y, Z}. */
  std::vector<unsigned long>
  keeps(const std::string &output)
  {
    return numbers(output,
                   "store keeps: +([0-9]+) states and ([0-9]+) failure "
                   "points in [^ ]+ \\(([0-9]+) appended by this run");
  }
} // namespace

int
main(int argc, char **argv)
{
  palpate::Environment env(argc, argv);
  initlog();
  write_file("beam-store.prm", scene_text);
  for (const auto &f : std::filesystem::directory_iterator("."))
    if (f.path().extension() == ".h5" || f.path().extension() == ".lock")
      std::filesystem::remove(f.path());

  // --- Two writers: a precompute runs; another, and an interaction, are
  // refused. The refusals come while the first is stopped (SIGSTOP), so
  // its cloud needs only to outlast the wait for its lock: 12 mm, 925
  // points (about 1.5 s of solving; the signals below stop 4169-point
  // precomputes in their middle).
  {
    const Started first =
      start("precompute beam-store.prm --radius 0.012", "first.txt");
    const bool locked = wait_until(
      [&] {
        return read_file("beam.h5.lock")
                 .find("pid " + std::to_string(first.pid)) != std::string::npos;
      },
      generous_deadline,
      "the first precompute's lock");
    kill(first.pid, SIGSTOP);
    const auto second = run("precompute beam-store.prm --radius 0.012");
    const auto touch  = run("beam-store.prm --set Run/Mode=interaction");
    kill(first.pid, SIGCONT);
    const int         first_status = finish(first);
    const std::string output       = read_file("first.txt");
    const auto        c            = contents("beam.h5");
    const auto        kept         = keeps(output);
    deallog << "while a precompute writes the store (it took the lock "
            << ok(locked) << "):" << std::endl;
    deallog << "a second precompute: exit status " << second.first
            << ", naming it "
            << ok(second.second.find("process " + std::to_string(first.pid)) !=
                    std::string::npos &&
                  second.second.find("precompute beam-store.prm") !=
                    std::string::npos)
            << std::endl
            << message(second.second, first.pid) << std::endl;
    deallog << "an interaction on the store: exit status " << touch.first
            << ", naming it "
            << ok(touch.second.find("process " + std::to_string(first.pid)) !=
                  std::string::npos)
            << std::endl;
    deallog << "the first: exit status " << first_status << ", the store "
            << c.damaged << " damaged and " << c.incomplete
            << " incomplete records, what it says it keeps is in the file "
            << ok(kept.size() == 3 && kept[0] == c.states &&
                  kept[1] == c.failures && kept[2] == c.states + c.failures)
            << ", the whole cloud of 925 points "
            << ok(c.states + c.failures == 925) << std::endl;
    if (kept.size() != 3 || c.states + c.failures != 925)
      deallog << output << std::endl;
  }

  // --- A signal stops a precompute: it says what the store keeps. Last,
  // SIGTERM twice 0.1 s apart, as `timeout` under load delivers it to the
  // process and to its group: the same stop (METIS had made palpate's stop
  // handler a one-shot, and the second one killed it with nothing said).
  for (const auto &[signal, twice] : std::vector<std::pair<int, bool>>{
         {SIGHUP, false}, {SIGTERM, false}, {SIGINT, false}, {SIGTERM, true}})
    {
      const std::string store =
        "signal-" + std::to_string(signal) + (twice ? "-twice" : "") + ".h5";
      const Started p = start("precompute beam-store.prm --radius 0.02 --set "
                              "State+space/Store=" +
                                store,
                              "signal.txt");
      // Signalled in the middle: once the store holds 100 records.
      const bool middle = wait_until(
        [&] {
          try
            {
              const auto c = contents(store);
              return c.states + c.failures >= 100;
            }
          catch (const palpate::InputError &)
            {
              return false; // not made yet
            }
        },
        generous_deadline,
        "100 records in " + store);
      kill(p.pid, signal);
      if (twice)
        {
          std::this_thread::sleep_for(std::chrono::milliseconds(100));
          kill(p.pid, signal);
        }
      const int         status = finish(p);
      const std::string output = read_file("signal.txt");
      const auto        c      = contents(store);
      const auto        kept   = keeps(output);
      deallog << strsignal(signal) << (twice ? " twice, 0.1 s apart," : "")
              << " in the middle " << ok(middle) << ": exit status " << status
              << ", stopped by it "
              << ok(output.find("stopped by SIG") != std::string::npos)
              << ", what it says the store keeps is in the file "
              << ok(kept.size() == 3 && kept[0] == c.states &&
                    kept[1] == c.failures && kept[2] == c.states + c.failures)
              << ", fewer than the cloud " << ok(c.states + c.failures < 4169)
              << ", none damaged " << ok(c.damaged + c.incomplete == 0)
              << ", says how to go on "
              << ok(output.find("run the same command again") !=
                    std::string::npos)
              << std::endl;
      if (kept.size() != 3)
        deallog << output << std::endl;
    }

  // --- A full disk (a file size limit of 600 kB: room for about 150 beam
  // states).
  {
    const auto full = run(
      "precompute beam-store.prm --radius 0.02 --set State+space/Store=full.h5",
      300 * 1024);
    const auto c        = contents("full.h5");
    const auto kept     = keeps(full.second);
    const auto appended = numbers(full.second, "; appended ([0-9]+)");
    const auto said =
      numbers(full.second,
              "it keeps ([0-9]+) states and ([0-9]+) failure points \\(read "
              "back\\), ([0-9]+) of them appended by this run");
    const unsigned long held = c.states + c.failures;
    deallog << "a full disk: exit status " << full.first
            << ", the counts it prints are what the file holds: appended "
            << ok(appended.size() == 1 && appended[0] == held) << ", kept "
            << ok(kept.size() == 3 && kept[0] == c.states &&
                  kept[1] == c.failures && kept[2] == held)
            << ", in the message "
            << ok(said.size() == 3 && said[0] == c.states &&
                  said[1] == c.failures && said[2] == held)
            << "; some stored " << ok(held > 20) << ", not all "
            << ok(held < 4169) << ", none damaged " << ok(c.damaged == 0)
            << std::endl;
    if (appended.size() != 1 || kept.size() != 3 || said.size() != 3)
      deallog << full.second << std::endl;
  }

  // --- An interaction whose store fills the disk: the run goes on, its
  // summary and files are written, and it ends with exit status 6 naming
  // the store and what it kept.
  {
    const auto full =
      run("beam-store.prm --set State+space/Store=full-run.h5", 300 * 1024);
    const auto c = contents("full-run.h5");
    const auto said =
      numbers(full.second,
              "it keeps ([0-9]+) states and ([0-9]+) failure points \\(read "
              "back\\)");
    deallog << "an interaction on a full disk: exit status " << full.first
            << " " << ok(full.first == 6) << ", summary printed "
            << ok(full.second.find("Run summary") != std::string::npos)
            << ", the error names the store "
            << ok(full.second.find("the state store full-run.h5 stopped "
                                   "taking states") != std::string::npos)
            << ", counts are the file's "
            << ok(!said.empty() && said[0] == c.states && said[1] == c.failures)
            << std::endl;
  }

  // --- A store that cannot be opened says why.
  {
    std::filesystem::create_directory("a-directory");
    write_file("notes.txt", "subsection Mesh\n  set Source = beam\nend\n");
    write_file("empty.h5", "");
    {
      const std::string whole = read_file("beam.h5");
      write_file("truncated.h5", whole.substr(0, whole.size() / 3));
    }
    {
      // An HDF5 file of something else: one dataset of its own.
      const hid_t f =
        H5Fcreate("other.h5", H5F_ACC_TRUNC, H5P_DEFAULT, H5P_DEFAULT);
      const hsize_t n = 4;
      const hid_t   s = H5Screate_simple(1, &n, nullptr);
      const hid_t   d = H5Dcreate2(f,
                                 "temperature",
                                 H5T_NATIVE_DOUBLE,
                                 s,
                                 H5P_DEFAULT,
                                 H5P_DEFAULT,
                                 H5P_DEFAULT);
      H5Dclose(d);
      H5Sclose(s);
      H5Fclose(f);
    }
    std::filesystem::copy_file("beam.h5", "read-only.h5");
    chmod("read-only.h5", 0444);
    const auto case_of = [](const std::string &what, const std::string &store) {
      const auto r =
        run("precompute beam-store.prm --set State+space/Store=" + store);
      std::string m = message(r.second);
      m             = std::regex_replace(m, std::regex("= [0-9]+"), "= N");
      deallog << "=== " << what << ": exit status " << r.first << std::endl
              << m << std::endl;
    };
    case_of("a directory", "a-directory");
    case_of("a device", "/dev/null");
    case_of("a text file", "notes.txt");
    case_of("an empty file", "empty.h5");
    case_of("an HDF5 file that is not a store", "other.h5");
    case_of("a truncated store", "truncated.h5");
    case_of("a directory that does not exist", "missing/beam.h5");
    // Permissions: root may write anything (CAP_DAC_OVERRIDE), so as root
    // the program runs without that capability (setpriv, util-linux): it
    // is then held to the modes like the owner, and still reaches every
    // directory it did.
    std::filesystem::create_directory("read-only-directory");
    chmod("read-only-directory", 0555);
    const auto without_override = [&](const std::string &what,
                                      const std::string &store) {
      if (geteuid() != 0)
        return case_of(what, store);
      if (!std::filesystem::exists("/usr/bin/setpriv"))
        {
          deallog << "=== " << what
                  << ": CANNOT TEST as root without /usr/bin/setpriv "
                     "(util-linux)"
                  << std::endl;
          return;
        }
      const std::string setting = "State space/Store=" + store;
      const pid_t       pid     = fork();
      if (pid == 0)
        {
          const int fd = open("run.txt", O_WRONLY | O_CREAT | O_TRUNC, 0644);
          dup2(fd, 1);
          dup2(fd, 2);
          execl("/usr/bin/setpriv",
                "setpriv",
                "--bounding-set=-dac_override,-dac_read_search",
                palpate_executable.c_str(),
                "precompute",
                "beam-store.prm",
                "--set",
                setting.c_str(),
                static_cast<char *>(nullptr));
          _exit(127);
        }
      const int r = finish({pid, "run.txt"});
      deallog << "=== " << what << ": exit status " << r << std::endl
              << message(read_file("run.txt")) << std::endl;
    };
    without_override("a read-only store", "read-only.h5");
    without_override("a new store in a directory that is not writable",
                     "read-only-directory/beam.h5");
    chmod("read-only-directory", 0755);
  }
}
