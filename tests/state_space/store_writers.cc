// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

// One writer per state store, readers see whole records, and a full disk
// says exactly what was kept (issue 26), on the small beam's states, with
// other processes made by fork():
// - a second process that opens a store another one writes is refused,
//   naming the writer (pid, command, lock file) and the fix; in the same
//   process a StoreLock shares the writer's lock; releasing it lets the
//   next writer in, and removes the lock file;
// - a store with two names (a hard link) is refused: the lock is by name;
// - two processes that open one store at the same moment and append: one
//   is refused, the other's records are all intact (none damaged; without
//   the lock both wrote, and records were damaged);
// - a writer killed with SIGKILL leaves its lock file, which does not block
//   the next writer (the kernel's lock went with the process);
// - a reader that opens the store again and again while a writer appends
//   reads only whole, right records;
// - a writer limited to a file size (RLIMIT_FSIZE: the write fails as on a
//   full disk, deterministically) stops appending, and what it says it
//   kept, appended() and its message, is what the file is read back to
//   hold.

#include <palpate/base/exceptions.h>
#include <palpate/hyperelastic/state_solver.h>
#include <palpate/state_space/state_grid.h>
#include <palpate/state_space/state_store.h>

#include <fcntl.h>
#include <signal.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstring>
#include <filesystem>
#include <functional>
#include <regex>
#include <thread>

#include "../tests.h"

namespace
{
  using StatesAt = std::vector<std::pair<unsigned int, palpate::State>>;

  bool
  identical(const palpate::State &a, const palpate::State &b)
  {
    return a.converged == b.converged &&
           std::memcmp(a.force.data(), b.force.data(), sizeof(a.force)) == 0 &&
           a.solution.size() == b.solution.size() &&
           std::memcmp(a.solution.data(),
                       b.solution.data(),
                       a.solution.size() * sizeof(double)) == 0 &&
           a.multipliers == b.multipliers;
  }

  /**
   * Run @p work in a child process (fork) and return its exit status. The
   * child leaves with _exit(): no destructor of the parent's objects runs
   * there (deal.II's, MPI's); @p work closes its own stores.
   */
  int
  in_child(const std::function<int()> &work)
  {
    const pid_t child = fork();
    if (child == 0)
      {
        int status = 1;
        try
          {
            status = work();
          }
        catch (...)
          {
            status = 99;
          }
        _exit(status);
      }
    int status = 0;
    waitpid(child, &status, 0);
    return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  }

  /** @p text with every decimal number @p pid replaced by "<pid>", and
   * the test directory by "<dir>". */
  std::string
  neutral(std::string text, const pid_t pid)
  {
    text                  = std::regex_replace(text,
                              std::regex("\\b" + std::to_string(pid) + "\\b"),
                              "<pid>");
    const std::string dir = std::filesystem::current_path().string();
    for (auto at = text.find(dir); at != std::string::npos; at = text.find(dir))
      text.replace(at, dir.size(), "<dir>");
    return text;
  }
} // namespace

int
main(int argc, char **argv)
{
  palpate::Environment env(argc, argv);
  initlog();

  // The states: computed here, before any fork (the children only write).
  palpate::Scene                  scene = small_beam_scene();
  const Body                      body(scene);
  const palpate::StoreFingerprint fingerprint =
    palpate::StoreFingerprint::of(body.scene, body.mesh, body.nodes);
  palpate::StateSolver     solver(body.mesh, body.nodes, scene.parameters);
  const palpate::StateGrid grid(scene.parameters.state_space.grid_spacing,
                                scene.parameters.state_space.extent);
  StatesAt                 states;
  for (const auto &g : std::vector<palpate::GridIndex>{
         {{0, 0, 0}}, {{0, 0, -1}}, {{1, 0, -1}}, {{0, 1, -2}}})
    states.emplace_back(grid.linear(g),
                        solver.solve(solver.rest_state(), grid.position(g)));
  palpate::State failure;
  failure.converged = false;
  failure.status    = palpate::SolveStatus::inverted_element;
  states.emplace_back(grid.linear({{0, 0, -3}}), failure);
  // Record k: the state states[k % 5] at grid point k % grid.size().
  const auto append = [&](palpate::StateStore &store, const unsigned int k) {
    store.append(k % grid.size(), states[k % states.size()].second);
  };
  const auto right = [&](const StatesAt &back) {
    bool same = true;
    for (std::size_t k = 0; same && k < back.size(); ++k)
      same = back[k].first == k % grid.size() &&
             identical(back[k].second, states[k % states.size()].second);
    return same;
  };
  for (const char *const f : {"one.h5",
                              "race.h5",
                              "stale.h5",
                              "read.h5",
                              "full.h5",
                              "refusal.txt",
                              "full.txt"})
    std::filesystem::remove(f);

  // --- A second process is refused while this one writes.
  {
    auto writer = std::make_unique<palpate::StateStore>("one.h5", fingerprint);
    const int         status  = in_child([&] {
      try
        {
          palpate::StateStore second("one.h5", fingerprint);
          return 0;
        }
      catch (const palpate::InputError &e)
        {
          write_file("refusal.txt", e.problem() + "\nfix: " + e.fix() + "\n");
          return 2;
        }
    });
    const std::string refusal = read_file("refusal.txt");
    deallog << "a second process opening the store is refused: "
            << ok(status == 2) << ", naming this process "
            << ok(refusal.find("process " + std::to_string(getpid())) !=
                  std::string::npos)
            << " and its command "
            << ok(refusal.find("store_writers") != std::string::npos)
            << std::endl;
    // Its message, with this machine's pid and paths made neutral.
    std::string message = neutral(refusal, getpid());
    message = std::regex_replace(message, std::regex("\\('[^']*'\\)"), "(...)");
    message = std::regex_replace(message,
                                 std::regex("since [0-9-]+ [0-9:]+ UTC"),
                                 "since <time>");
    while (!message.empty() && message.back() == '\n')
      message.pop_back();
    deallog << message << std::endl;

    // In this process the lock is shared: no refusal.
    bool shared = true;
    try
      {
        const palpate::StoreLock lock("one.h5");
        shared = lock.lock_file() ==
                 std::filesystem::current_path().string() + "/one.h5.lock";
      }
    catch (const palpate::InputError &)
      {
        shared = false;
      }
    deallog << "in this process, a StoreLock shares the writer's lock: "
            << ok(shared) << std::endl;

    // A StoreLock alone keeps other processes out too; released, it lets
    // the next writer in and removes its lock file.
    auto lock = std::make_unique<palpate::StoreLock>("one.h5");
    append(*writer, 0);
    writer.reset();
    const int while_locked = in_child([&] {
      try
        {
          palpate::StateStore second("one.h5", fingerprint);
          return 0;
        }
      catch (const palpate::InputError &)
        {
          return 2;
        }
    });
    lock.reset();
    const bool lock_file_gone = !std::filesystem::exists("one.h5.lock");
    const int  after          = in_child([&] {
      palpate::StateStore second("one.h5", fingerprint);
      append(second, 1);
      return second.appended() == 1 ? 0 : 1;
    });
    palpate::StateStore back("one.h5",
                             fingerprint,
                             palpate::StateStore::Access::read);
    const auto          c = back.contents();
    deallog << "a StoreLock alone refuses another process: "
            << ok(while_locked == 2)
            << "; released, its lock file is removed: " << ok(lock_file_gone)
            << " and the next writer appends: " << ok(after == 0) << " ("
            << c.states << " states in the store)" << std::endl;
  }

  // --- A store with two names (a hard link): each name would have its own
  // lock file, and two writers through the two names damaged hundreds of
  // records. It is refused, through either name.
  {
    std::filesystem::remove("two-names.h5");
    std::filesystem::create_hard_link("one.h5", "two-names.h5");
    unsigned int refused = 0;
    std::string  problem;
    for (const std::string name : {"one.h5", "two-names.h5"})
      try
        {
          const palpate::StoreLock lock(name);
        }
      catch (const palpate::InputError &e)
        {
          ++refused;
          problem = e.problem();
        }
    std::filesystem::remove("two-names.h5");
    bool one_name_again = true;
    try
      {
        const palpate::StoreLock lock("one.h5");
      }
    catch (const palpate::InputError &)
      {
        one_name_again = false;
      }
    deallog << "a store with two names (a hard link) is refused through "
               "both: "
            << ok(refused == 2) << ", saying so "
            << ok(problem.find("2 names (hard links") != std::string::npos)
            << "; with one name again it is taken: " << ok(one_name_again)
            << std::endl;
  }

  // --- Two processes open one store at the same moment and append.
  {
    // Each opens, then waits for the other to have tried (so that both
    // would hold it at once), then appends 60 records.
    int to_child[2], to_parent[2];
    AssertThrow(pipe(to_child) == 0 && pipe(to_parent) == 0,
                dealii::ExcMessage("pipe() failed"));
    const auto writer = [&](const int tell, const int hear) {
      int                                  refused = 0;
      std::unique_ptr<palpate::StateStore> store;
      try
        {
          store = std::make_unique<palpate::StateStore>("race.h5", fingerprint);
        }
      catch (const palpate::InputError &)
        {
          refused = 1;
        }
      char byte = 'x';
      AssertThrow(write(tell, &byte, 1) == 1 && read(hear, &byte, 1) == 1,
                  dealii::ExcMessage("the pipe failed"));
      if (store)
        for (unsigned int k = 0; k < 60; ++k)
          append(*store, k);
      return refused;
    };
    const pid_t child = fork();
    if (child == 0)
      {
        int refused = 0;
        try
          {
            refused = writer(to_parent[1], to_child[0]);
          }
        catch (...)
          {
            _exit(99);
          }
        _exit(refused);
      }
    const int parent_refused = writer(to_child[1], to_parent[0]);
    int       status         = 0;
    waitpid(child, &status, 0);
    const int child_refused = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
    palpate::StateStore store("race.h5", fingerprint);
    unsigned int        damaged = 0, incomplete = 0;
    const auto          back = store.read_all(damaged, &incomplete);
    deallog << "two processes open one store at once: one refused "
            << ok(parent_refused + child_refused == 1) << ", " << back.size()
            << " records intact and right " << ok(right(back)) << ", "
            << damaged << " damaged, " << incomplete << " incomplete"
            << std::endl;
    for (const int fd : {to_child[0], to_child[1], to_parent[0], to_parent[1]})
      close(fd);
  }

  // --- A writer killed with SIGKILL does not block the next one.
  {
    // The writer says (a byte on a pipe) when it has appended 10 records,
    // and goes on appending: it is killed in the middle of one. A writer
    // that ended before closes the pipe instead (ready: no).
    int appended[2];
    AssertThrow(pipe(appended) == 0, dealii::ExcMessage("pipe() failed"));
    const pid_t child = fork();
    if (child == 0)
      {
        close(appended[0]);
        palpate::StateStore store("stale.h5", fingerprint);
        for (unsigned int k = 0;; ++k)
          {
            append(store, k);
            if (k == 9)
              {
                const char byte = 'x';
                if (write(appended[1], &byte, 1) != 1)
                  _exit(1);
                close(appended[1]);
              }
          }
      }
    close(appended[1]);
    char       byte  = 0;
    const bool ready = read(appended[0], &byte, 1) == 1;
    close(appended[0]);
    kill(child, SIGKILL);
    waitpid(child, nullptr, 0);
    const bool left =
      read_file("stale.h5.lock").find("pid " + std::to_string(child)) !=
      std::string::npos;
    bool opened = false;
    try
      {
        palpate::StateStore store("stale.h5", fingerprint);
        unsigned int        damaged = 0;
        opened = right(store.read_all(damaged)) && damaged == 0;
        append(store, 0);
      }
    catch (const palpate::InputError &e)
      {
        deallog << "  refused: " << e.problem() << std::endl;
      }
    deallog << "a writer killed with SIGKILL while appending " << ok(ready)
            << ", its lock file is left naming it " << ok(left)
            << ", and the next writer opens the store, its records right "
            << ok(opened) << std::endl;
  }

  // --- A reader while a writer appends sees only whole records.
  {
    {
      palpate::StateStore store("read.h5", fingerprint);
      append(store, 0);
    }
    // The writer appends paced (at most 5000 records/s) and waits at
    // every 100th record until the reader has read once more (a byte each
    // way on two pipes): the reader reads in the middle of the appends at
    // least 5 times, however busy the machine, and reads while records are
    // appended in between.
    const unsigned int n_records = 600;
    int                paused[2], resume[2];
    AssertThrow(pipe(paused) == 0 && pipe(resume) == 0,
                dealii::ExcMessage("pipe() failed"));
    fcntl(paused[0], F_SETFL, O_NONBLOCK);
    const pid_t child = fork();
    if (child == 0)
      {
        close(paused[0]);
        close(resume[1]);
        {
          palpate::StateStore store("read.h5", fingerprint);
          for (unsigned int k = 1; k < n_records; ++k)
            {
              append(store, k);
              std::this_thread::sleep_for(std::chrono::microseconds(200));
              char byte = 'x';
              if (k % 100 == 0 && (write(paused[1], &byte, 1) != 1 ||
                                   read(resume[0], &byte, 1) != 1))
                _exit(1);
            }
        }
        _exit(0);
      }
    close(paused[1]);
    close(resume[0]);
    unsigned int reads = 0, refused = 0, damaged_seen = 0, incomplete_seen = 0,
                 wrong = 0, shrank = 0, during = 0;
    std::size_t last = 0;
    for (bool done = false; !done;)
      {
        // The writer waiting at a 100th record: this read is in the middle.
        char       byte    = 0;
        const bool waiting = read(paused[0], &byte, 1) == 1;
        done               = waitpid(child, nullptr, WNOHANG) == child;
        try
          {
            const palpate::StateStore store("read.h5",
                                            fingerprint,
                                            palpate::StateStore::Access::read);
            unsigned int              damaged = 0, incomplete = 0;
            const auto back = store.read_all(damaged, &incomplete);
            ++reads;
            during += !done && back.size() > 1 && back.size() < n_records;
            damaged_seen += damaged;
            incomplete_seen += incomplete;
            wrong += !right(back);
            shrank += back.size() < last;
            last = back.size();
          }
        catch (const palpate::InputError &e)
          {
            if (++refused == 1)
              deallog << "  a read failed: " << e.problem() << std::endl;
          }
        if (waiting && write(resume[1], &byte, 1) != 1)
          deallog << "  the writer could not be resumed" << std::endl;
      }
    close(paused[0]);
    close(resume[1]);
    deallog << "a reader while a writer appends " << n_records
            << " records: read " << (during >= 3 ? ">= 3" : "< 3")
            << " times in the middle, every record whole and right "
            << ok(wrong == 0 && damaged_seen == 0) << ", never fewer than "
            << "before " << ok(shrank == 0) << ", no read failed "
            << ok(refused == 0) << ", all " << last << " at the end"
            << std::endl;
    if (during < 3)
      deallog << "  (" << reads << " reads, " << during << " in the middle)"
              << std::endl;
  }

  // --- A full disk: a file size limit makes the writes fail.
  {
    {
      palpate::StateStore store("full.h5", fingerprint);
      for (unsigned int k = 0; k < 5; ++k)
        append(store, k);
    }
    const auto         size   = std::filesystem::file_size("full.h5");
    const int          status = in_child([&] {
      // Room for a few dozen records beyond what the file has; past that
      // the kernel refuses the write (EFBIG) instead of sending SIGXFSZ.
      signal(SIGXFSZ, SIG_IGN);
      const rlim_t limit = size + 64 * 1024;
      const rlimit l{limit, limit};
      setrlimit(RLIMIT_FSIZE, &l);
      palpate::StateStore store("full.h5", fingerprint);
      std::string         message;
      unsigned int        calls = 0;
      try
        {
          for (unsigned int k = 5; k < 100000; ++k, ++calls)
            append(store, k);
        }
      catch (const palpate::OutputError &e)
        {
          message = e.what();
        }
      const unsigned int appended = store.appended();
      // Stopped: appending again does nothing, and throws nothing.
      append(store, 0);
      write_file("full.txt",
                 std::to_string(appended) + " " + std::to_string(calls) + " " +
                   std::to_string(store.appended()) + " " +
                   std::to_string(store.stopped()) + "\n" + message + "\n");
      return message.empty() ? 1 : 0;
    });
    std::istringstream in(read_file("full.txt"));
    unsigned int       appended = 0, calls = 0, appended_later = 0, stopped = 0;
    in >> appended >> calls >> appended_later >> stopped;
    std::string message;
    std::getline(in >> std::ws, message);
    palpate::StateStore store("full.h5", fingerprint);
    const auto          c = store.contents();
    // What the message says the store keeps.
    std::smatch said;
    const bool  says = std::regex_search(
      message,
      said,
      std::regex("it keeps ([0-9]+) states and ([0-9]+) failure points "
                  "\\(read back\\), ([0-9]+) of them appended by this run"));
    deallog << "a full disk (file size limit): the write fails "
            << ok(status == 0) << ", naming the cause "
            << ok(message.find("File too large") != std::string::npos)
            << "; appended() is what the file holds beyond the 5 records "
            << "before " << ok(c.states + c.failures == 5 + appended)
            << ", the message says what the file holds "
            << ok(says && std::stoul(said[1].str()) == c.states &&
                  std::stoul(said[2].str()) == c.failures &&
                  std::stoul(said[3].str()) == appended)
            << ", some appended first " << ok(appended > 5)
            << ", appending stopped " << ok(stopped == 1)
            << ", and does nothing after " << ok(appended_later == appended)
            << "; " << c.damaged << " damaged" << std::endl;
    // And the store takes records again once there is room.
    append(store, c.states + c.failures);
    deallog << "with room again, the store appends: "
            << ok(store.appended() == 1 &&
                  store.contents().states + store.contents().failures ==
                    c.states + c.failures + 1)
            << std::endl;
    if (appended + 5 != c.states + c.failures || calls == 0)
      deallog << "  (" << calls << " appends, appended() " << appended
              << ", the file " << c.states << " + " << c.failures << ")"
              << std::endl;
  }
}
