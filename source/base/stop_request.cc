// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

#include <palpate/base/stop_request.h>

#include <signal.h>
#include <time.h>

#include <atomic>
#include <csignal>

namespace palpate
{
  namespace
  {
    // The first stop signal's number. A lock-free atomic is
    // async-signal-safe; the handler touches nothing else.
    std::atomic<int> received{0};
    static_assert(std::atomic<int>::is_always_lock_free);

    constexpr int stop_signals[] = {SIGINT, SIGTERM, SIGHUP};

    struct sigaction previous[3];

    // When the first one came (CLOCK_MONOTONIC, ns), to tell a second
    // Ctrl-C from one signal delivered twice.
    std::atomic<long long> received_at{0};
    static_assert(std::atomic<long long>::is_always_lock_free);

    // Whether a StopRequest lives (its handlers are installed).
    std::atomic<bool> alive{false};

    long long
    now_ns() noexcept
    {
      timespec t{}; // clock_gettime is async-signal-safe
      clock_gettime(CLOCK_MONOTONIC, &t);
      return static_cast<long long>(t.tv_sec) * 1000000000LL + t.tv_nsec;
    }

    void
    on_stop_signal(const int signal)
    {
      // The first signal is the one whose time is stored first. Two
      // deliveries may run this handler in two threads at once: had the
      // first marked `received` before storing its time, the second could
      // read no time yet and take itself for a second Ctrl-C.
      const long long now   = now_ns();
      long long       first = 0;
      if (received_at.compare_exchange_strong(first, now))
        received.store(signal);
      // A second stop signal within half a second of the first is the same
      // stop: `timeout`, a terminal or a process manager may deliver one
      // signal to the process and again to its group, and the run would
      // then end at once without its outputs. A person's second Ctrl-C
      // comes later.
      else if (now - first >= 500000000LL)
        {
          // The second one: the default action, now (sigaction and raise
          // are async-signal-safe).
          struct sigaction default_action
          {};
          default_action.sa_handler = SIG_DFL;
          sigemptyset(&default_action.sa_mask);
          sigaction(signal, &default_action, nullptr);
          raise(signal);
        }
    }

    /** A stop signal's name for messages ("" for none). */
    std::string
    describe(const int signal)
    {
      switch (signal)
        {
          case 0:
            return "";
          case SIGINT:
            return "SIGINT (Ctrl-C)";
          case SIGTERM:
            return "SIGTERM";
          case SIGHUP:
            return "SIGHUP (the terminal closed)";
          default:
            return "signal " + std::to_string(signal);
        }
    }
  } // namespace



  StopRequest::StopRequest()
  {
    received.store(0);
    received_at.store(0);
    alive.store(true);
    struct sigaction action
    {};
    action.sa_handler = on_stop_signal;
    sigemptyset(&action.sa_mask);
    // SA_RESTART: a read or write interrupted by Ctrl-C goes on; the
    // driver sees the flag at its next poll.
    action.sa_flags = SA_RESTART;
    for (unsigned int i = 0; i < 3; ++i)
      {
        struct sigaction current
        {};
        sigaction(stop_signals[i], nullptr, &current);
        // The handler a stopped StopRequest left behind (see the destructor)
        // is not the caller's: the one saved before it stays the one to
        // restore.
        if (current.sa_handler != on_stop_signal)
          previous[i] = current;
        // A signal the caller ignores (nohup ignores SIGHUP) stays ignored.
        if (previous[i].sa_handler != SIG_IGN)
          sigaction(stop_signals[i], &action, nullptr);
      }
  }



  StopRequest::~StopRequest()
  {
    alive.store(false);
    // After a stop the process is on its way out with 128 + the signal. The
    // same signal delivered again (to the process and its group) may land
    // after this destructor, in the exit's teardown: with the previous
    // (default) action restored it would kill the process and replace that
    // exit status. The handler stays, and keeps its half-second rule.
    if (received.load() != 0)
      return;
    for (unsigned int i = 0; i < 3; ++i)
      sigaction(stop_signals[i], &previous[i], nullptr);
  }



  bool
  StopRequest::requested() const noexcept
  {
    return received.load() != 0;
  }



  bool
  StopRequest::pending() noexcept
  {
    return alive.load() && received.load() != 0;
  }



  StoppedError::StoppedError(const std::string &what)
    : std::runtime_error(what + " was stopped by " + describe(received.load()) +
                         "; nothing was written")
    , exit_status(128 + received.load())
  {}



  int
  StopRequest::signal_number() const noexcept
  {
    return received.load();
  }



  std::string
  StopRequest::description() const
  {
    return describe(received.load());
  }



  int
  StopRequest::exit_status() const noexcept
  {
    return 128 + received.load();
  }



  void
  StopRequest::request(const int signal) noexcept
  {
    int expected = 0;
    received.compare_exchange_strong(expected, signal);
  }



  void
  ignore_broken_pipes() noexcept
  {
    std::signal(SIGPIPE, SIG_IGN);
  }
} // namespace palpate
