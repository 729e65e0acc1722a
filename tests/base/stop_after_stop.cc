// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

// A stop signal delivered twice (`timeout` signals the process and then its
// group) may reach a run after it has written everything and its
// StopRequest is gone, in the exit's teardown. The second delivery must
// still be the same stop, not the default action that kills the process
// and replaces its exit status 128 + signal. And a StopRequest made after
// that one restores the caller's own disposition, not the one left behind.

#include <palpate/base/stop_request.h>

#include <signal.h>

#include "../tests.h"

namespace
{
  bool
  is_default(const int signal)
  {
    struct sigaction action
    {};
    sigaction(signal, nullptr, &action);
    return action.sa_handler == SIG_DFL;
  }
} // namespace

int
main()
{
  initlog();
  deallog << "SIGTERM's default action at the start: "
          << (is_default(SIGTERM) ? "yes" : "no") << std::endl;
  {
    const palpate::StopRequest stop;
    raise(SIGTERM);
    deallog << "first SIGTERM: stop requested by " << stop.description()
            << std::endl;
  }
  // Raised at once, within the half second that makes it the same stop: on
  // a restored default action the test ends here with no more output.
  raise(SIGTERM);
  deallog << "the same SIGTERM again after the StopRequest ended: alive"
          << std::endl;

  {
    const palpate::StopRequest stop;
    deallog << "a new StopRequest: no stop requested "
            << (stop.requested() ? "no" : "yes") << std::endl;
  }
  deallog << "after it, SIGTERM's default action again: "
          << (is_default(SIGTERM) ? "yes" : "no") << std::endl;
}
