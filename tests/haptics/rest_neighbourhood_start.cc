// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

// Haptics / Trajectory / Start = after rest neighbourhood (issue 25): the
// motion waits only for the 27 grid points around the rest position (the
// corners of every cell that touches it), not for the whole initial cloud
// (515 points on the paper's liver); the rest of the cloud is computed
// during the motion. Through the palpate program on the paper's liver,
// a 6 s stroke at 5 mm/s (slow enough that a machine loaded by other
// tests' solves keeps ahead of the probe: the check is of what the
// scheduler plans first, not of the machine's speed):
// - the report says what the motion waits for, and when it starts it says
//   the 27 are there, with fewer states computed than the cloud has (at
//   least the 27);
// - the stroke has no missing data (the scheduler computes the cells on
//   the predicted path first).

#include "../tests.h"

namespace
{
  std::string
  line_with(const std::string &output, const std::string &key)
  {
    const auto at = output.find(key);
    if (at == std::string::npos)
      return "(none)";
    const auto begin = output.rfind('\n', at) + 1;
    return output.substr(begin, output.find('\n', at) - begin);
  }
} // namespace

int
main()
{
  initlog();
  const ProgramRun r =
    run_palpate(palpate_source_dir + "/parameters/paper-stvk.prm" +
                " --set 'Haptics/Trajectory/Start=after rest neighbourhood'" +
                " --set Haptics/Trajectory/Speed=0.005" +
                " --set Haptics/Trajectory/Duration=6");
  const std::string waits    = line_with(r.output, "the motion starts when");
  const std::string starts   = line_with(r.output, "; motion starts");
  unsigned int      computed = 0;
  if (const auto at = starts.find("initial cloud: "); at != std::string::npos)
    computed = std::stoul(starts.substr(at + 15));
  deallog << "exit status " << r.exit_status << " " << ok(r.exit_status == 0)
          << std::endl;
  deallog << "the report says the motion waits for the 27 around rest: "
          << ok(waits.find("515 grid points") != std::string::npos &&
                waits.find("the 27 around it are computed") !=
                  std::string::npos)
          << std::endl;
  deallog << "the motion starts with the 27 there: "
          << ok(starts.find("the 27 grid points around rest are there") !=
                std::string::npos)
          << ", states computed then at least 27 and fewer than the cloud's "
             "515: "
          << ok(computed >= 27 && computed < 515) << std::endl;
  deallog << "the stroke: " << line_with(r.output, "missing data:").substr(2)
          << std::endl;
  std::cout << starts << std::endl;
}
