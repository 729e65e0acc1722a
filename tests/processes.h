// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

// For tests that run programs as children and watch them: start one with
// its output in files, wait for a line in that output, send it a signal,
// collect its status. Used by the tests of stops and of lost MPI peers.

#ifndef palpate_tests_processes_h
#define palpate_tests_processes_h

#include <fcntl.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <string>
#include <thread>
#include <vector>

#include "tests.h"

namespace test_processes
{
  /**
   * Start the program @p argv[0] (looked up in PATH unless it has a '/')
   * with @p argv, its stdout in @p out_file (truncated; "/dev/full" works
   * too) or, if @p out_fd >= 0, in that descriptor (the write end of a
   * pipe); stderr in @p err_file.
   */
  inline pid_t
  start(const std::vector<std::string> &argv,
        const std::string              &out_file,
        const std::string              &err_file,
        const int                       out_fd = -1)
  {
    const pid_t pid = fork();
    if (pid == 0)
      {
        const int out =
          out_fd >= 0 ?
            out_fd :
            open(out_file.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
        const int err =
          open(err_file.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
        dup2(out, 1);
        dup2(err, 2);
        std::vector<char *> args;
        for (const auto &a : argv)
          args.push_back(const_cast<char *>(a.c_str()));
        args.push_back(nullptr);
        execvp(args[0], args.data());
        _exit(127);
      }
    return pid;
  }

  /** Start the palpate program with @p args (see start()). */
  inline pid_t
  start_palpate(const std::vector<std::string> &args,
                const std::string              &out_file,
                const std::string              &err_file,
                const int                       out_fd = -1)
  {
    std::vector<std::string> argv{palpate_executable};
    argv.insert(argv.end(), args.begin(), args.end());
    return start(argv, out_file, err_file, out_fd);
  }

  /** Wait for the child @p pid to end: its exit status, or 1000 + the
   * signal that killed it (a failure wherever a status is expected). */
  inline int
  wait_status(const pid_t pid)
  {
    int status = 0;
    waitpid(pid, &status, 0);
    return WIFEXITED(status) ? WEXITSTATUS(status) : 1000 + WTERMSIG(status);
  }

  /** Wait at most @p seconds for the child @p pid to end: true and its
   * status (as wait_status()) in @p status if it did. */
  inline bool
  wait_status_for(const pid_t pid, const double seconds, int &status)
  {
    const auto end =
      std::chrono::steady_clock::now() + std::chrono::duration<double>(seconds);
    while (std::chrono::steady_clock::now() < end)
      {
        int raw = 0;
        if (waitpid(pid, &raw, WNOHANG) == pid)
          {
            status = WIFEXITED(raw) ? WEXITSTATUS(raw) : 1000 + WTERMSIG(raw);
            return true;
          }
        std::this_thread::sleep_for(std::chrono::milliseconds(50));
      }
    return false;
  }

  /** Wait (at most @p seconds) until the file @p file contains @p text. */
  inline bool
  wait_for_text(const std::string &file,
                const std::string &text,
                const double       seconds = 120)
  {
    return wait_until(
      [&] { return read_file(file).find(text) != std::string::npos; },
      seconds,
      "\"" + text + "\" in " + file,
      std::chrono::milliseconds(20));
  }

  /** The line of @p text that contains @p what, from there on; "(none)". */
  inline std::string
  line_with(const std::string &text, const std::string &what)
  {
    const auto at = text.find(what);
    if (at == std::string::npos)
      return "(none)";
    return text.substr(at, text.find('\n', at) - at);
  }

  /** How often @p what occurs in @p text. */
  inline unsigned int
  count(const std::string &text, const std::string &what)
  {
    unsigned int n = 0;
    for (auto at = text.find(what); at != std::string::npos;
         at      = text.find(what, at + 1))
      ++n;
    return n;
  }
} // namespace test_processes

#endif
