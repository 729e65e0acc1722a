// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

// Fuzzing the replay reader (Haptics / Trajectory / Type = replay; issue
// 26: the fuzzers cover every input file): a recorded stroke of 2 s at
// 1 kHz (a header, comments, t, x, y, z per line), mutated 1,000 times
// (tests/fuzz.h, seeded). Every mutant must either give a trajectory whose
// duration is finite and non-negative and whose positions are finite at
// every millisecond of it, or an InputError naming the file: any other
// exception, a crash or a read slower than 2 s fails the test.

#include <palpate/base/exceptions.h>
#include <palpate/haptics/trajectory.h>

#include <cmath>
#include <fstream>
#include <iomanip>

#include "../tests.h"

#include "../fuzz.h"

int
main()
{
  initlog();
  {
    std::ofstream seed("seed.csv");
    seed << "# a stroke recorded at 1 kHz\nt,x,y,z\n" << std::setprecision(9);
    for (unsigned int k = 0; k <= 2000; ++k)
      {
        const double t = 1e-3 * k;
        seed << 10 + t << "," << -0.01 * t << "," << 0.002 * std::sin(3 * t)
             << "," << -0.005 * t * t << "\n";
      }
  }
  const std::string text = read_file("seed.csv");
  {
    const palpate::Replay replay("seed.csv");
    deallog << "seed: " << replay.duration() << " s, ends at ("
            << palpate::Utilities::to_string(replay.position(2), 6) << ") m"
            << std::endl;
  }

  std::mt19937       rng(20261125);
  const unsigned int n     = 1000;
  unsigned int       valid = 0, rejected = 0, other = 0, slow = 0, named = 0;
  for (unsigned int i = 0; i < n; ++i)
    {
      write_file("mutant.csv", fuzz::mutate(text, rng));
      const fuzz::CpuTimer timer;
      try
        {
          const palpate::Replay replay("mutant.csv");
          const double          T  = replay.duration();
          bool                  ok = std::isfinite(T) && T >= 0;
          for (double t = 0; ok && t <= T + 1e-3 && t < 10; t += 1e-3)
            for (const double x : replay.position(t))
              ok = ok && std::isfinite(x);
          if (ok)
            ++valid;
          else if (++other <= 3)
            deallog << "mutant " << i << ": a duration of " << T
                    << " s or a non-finite position" << std::endl;
        }
      catch (const palpate::InputError &e)
        {
          ++rejected;
          named += e.file() == "mutant.csv";
        }
      catch (const std::exception &e)
        {
          if (++other <= 3)
            deallog << "mutant " << i << ": NOT an input error: " << e.what()
                    << std::endl;
        }
      if (timer.seconds() > 2)
        ++slow;
    }
  deallog << n << " mutants: " << valid << " valid recordings, " << rejected
          << " input errors (" << named << " naming the file), " << other
          << " other outcomes (must be 0), " << slow
          << " slower than 2 s (must be 0)" << std::endl;
}
