// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

// The mutations the input fuzzers share (meshes, surfaces, recordings):
// bytes flipped, ranges deleted or repeated, lines dropped or duplicated,
// numbers replaced by nasty ones (nan, inf, 1e308, -1, huge counts), files
// truncated. Seeded by the caller: the counts a test prints are the same on
// every run.

#ifndef palpate_tests_fuzz_h
#define palpate_tests_fuzz_h

#include <cctype>
#include <ctime>
#include <random>
#include <string>
#include <vector>

namespace fuzz
{
  inline const std::vector<std::string> numbers = {"nan",
                                                   "inf",
                                                   "-inf",
                                                   "1e308",
                                                   "-1",
                                                   "0",
                                                   "4294967295",
                                                   "4294967296",
                                                   "99999999999999999999",
                                                   "-2147483648",
                                                   "1e-320",
                                                   "3.5",
                                                   "abc",
                                                   ""};

  inline std::size_t
  pick(std::mt19937 &rng, const std::size_t n)
  {
    return n == 0 ? 0 : rng() % n;
  }

  /**
   * The CPU time the calling thread has used since construction (s): what
   * the fuzzers bound a mutant's parse by. A hang shows in it as in the
   * wall clock, but the test suite's other processes on the same cores do
   * not lengthen it (the wall clock's bound tripped on a loaded machine),
   * nor do the fuzzer's other threads (fuzz_scenes runs mutants side by
   * side). A hang outside the thread is ctest's TIMEOUT's.
   */
  class CpuTimer
  {
  public:
    CpuTimer()
      : start(now())
    {}

    double
    seconds() const
    {
      return now() - start;
    }

  private:
    static double
    now()
    {
      timespec t{};
      clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
      return t.tv_sec + 1e-9 * t.tv_nsec;
    }

    double start;
  };

  /** One to three mutations of @p s. */
  inline std::string
  mutate(std::string s, std::mt19937 &rng)
  {
    const unsigned int n = 1 + pick(rng, 3);
    for (unsigned int m = 0; m < n && !s.empty(); ++m)
      switch (pick(rng, 7))
        {
          case 0: // flip a byte
            s[pick(rng, s.size())] = static_cast<char>(pick(rng, 256));
            break;
          case 1: // delete a range
            s.erase(pick(rng, s.size()), 1 + pick(rng, 64));
            break;
          case 2: // repeat a range
            {
              const auto at = pick(rng, s.size());
              s.insert(at, s.substr(at, 1 + pick(rng, 64)));
              break;
            }
          case 3: // drop a line
            {
              const auto at  = s.find('\n', pick(rng, s.size()));
              const auto end = at == std::string::npos ? std::string::npos :
                                                         s.find('\n', at + 1);
              if (at != std::string::npos)
                s.erase(at, end == std::string::npos ? end : end - at);
              break;
            }
          case 4: // duplicate a line
            {
              const auto at  = s.find('\n', pick(rng, s.size()));
              const auto end = at == std::string::npos ? std::string::npos :
                                                         s.find('\n', at + 1);
              if (end != std::string::npos)
                s.insert(at, s.substr(at, end - at));
              break;
            }
          case 5: // a nasty number in place of one
            {
              auto at = pick(rng, s.size());
              while (at < s.size() &&
                     !std::isdigit(static_cast<unsigned char>(s[at])))
                ++at;
              auto end = at;
              while (end < s.size() &&
                     (std::isdigit(static_cast<unsigned char>(s[end])) ||
                      s[end] == '.' || s[end] == 'e' || s[end] == '-'))
                ++end;
              if (at < s.size())
                s.replace(at, end - at, numbers[pick(rng, numbers.size())]);
              break;
            }
          default: // truncate
            s.resize(pick(rng, s.size()));
        }
    return s;
  }
} // namespace fuzz

#endif
