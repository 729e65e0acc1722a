// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

// The simulated device's trajectories: each starts at the rest position;
// the straight line and the circle move at the given speed (central
// differences, 1e-6 s); the circle keeps its radius in its plane; the
// smooth random motion stays within its radius, has the given
// root-mean-square speed over a long run (within 5 %) and is reproducible
// from its seed; a replay counts times and positions from its first row,
// interpolates linearly, is found relative to the scene file, and rejects
// bad files with the file, the line and a fix.

#include <palpate/haptics/trajectory.h>

#include <cmath>
#include <filesystem>

#include "../tests.h"

namespace
{
  using palpate::Utilities::Point3;

  double
  speed(const palpate::Trajectory &t, const double time)
  {
    const double dt = 1e-6;
    return palpate::Utilities::distance(t.position(time + dt),
                                        t.position(time - dt)) /
           (2 * dt);
  }

  void
  try_replay(const std::string &name, const std::string &text)
  {
    write_file(name, text);
    try
      {
        palpate::Replay replay(name);
        deallog << name << ": accepted (WRONG)" << std::endl;
      }
    catch (const palpate::InputError &e)
      {
        deallog << name << ": " << e.what() << std::endl;
      }
  }
} // namespace

int
main(int argc, char **argv)
{
  palpate::Environment env(argc, argv);
  initlog();

  // Straight line along (3, 0, 4) at 20 mm/s for 1.5 s.
  const palpate::StraightLine line({{3, 0, 4}}, 0.02, 1.5);
  deallog << line.description() << std::endl;
  deallog << "  at 0: (" << palpate::Utilities::to_string(line.position(0), 6)
          << "), at 1 s: ("
          << palpate::Utilities::to_string(line.position(1), 6)
          << "), at 9 s: ("
          << palpate::Utilities::to_string(line.position(9), 6)
          << ") m; speed at 0.7 s " << speed(line, 0.7) << " m/s" << std::endl;

  // Circle normal to z, radius 10 mm, 30 mm/s, 5 s.
  const palpate::Circle circle({{0, 0, 1}}, 0.01, 0.03, 5);
  deallog << circle.description() << std::endl;
  double radius_error = 0, plane_error = 0, speed_error = 0;
  // The centre is opposite the start through the point reached at half a turn.
  const double half_turn = M_PI * 0.01 / 0.03;
  Point3       centre    = circle.position(half_turn);
  for (double &c : centre)
    c /= 2;
  for (double t = 0; t <= 5; t += 0.01)
    {
      const Point3 p = circle.position(t);
      radius_error =
        std::max(radius_error,
                 std::abs(palpate::Utilities::distance(p, centre) - 0.01));
      plane_error = std::max(plane_error, std::abs(p[2]));
      if (t > 0.01 && t < 4.99)
        speed_error = std::max(speed_error, std::abs(speed(circle, t) - 0.03));
    }
  deallog << "  at 0: (" << palpate::Utilities::to_string(circle.position(0), 6)
          << "); radius kept to 1e-12 m: "
          << (radius_error < 1e-12 ? "yes" : "NO")
          << ", in the plane z = 0: " << (plane_error < 1e-15 ? "yes" : "NO")
          << ", speed 30 mm/s to 1e-6 m/s: "
          << (speed_error < 1e-6 ? "yes" : "NO") << std::endl;

  // Smooth random, radius 10 mm, 20 mm/s RMS, 200 s.
  const palpate::SmoothRandom random(0.01, 0.02, 200, 7),
    same(0.01, 0.02, 200, 7), other(0.01, 0.02, 200, 8);
  deallog << random.description() << std::endl;
  double       largest = 0, square_sum = 0, reproducible = 0, differs = 0;
  unsigned int n = 0;
  for (double t = 0.005; t < 200; t += 0.01, ++n)
    {
      largest = std::max(largest, palpate::Utilities::norm(random.position(t)));
      square_sum += std::pow(speed(random, t), 2);
      reproducible = std::max(reproducible,
                              palpate::Utilities::distance(random.position(t),
                                                           same.position(t)));
      differs      = std::max(differs,
                         palpate::Utilities::distance(random.position(t),
                                                      other.position(t)));
    }
  const double rms = std::sqrt(square_sum / n);
  deallog << "  at 0: (" << palpate::Utilities::to_string(random.position(0), 6)
          << "); within the radius: " << (largest <= 0.01 ? "yes" : "NO")
          << ", RMS speed within 5 % of 20 mm/s: "
          << (std::abs(rms / 0.02 - 1) < 0.05 ? "yes" : "NO")
          << ", same seed same path: " << (reproducible == 0 ? "yes" : "NO")
          << ", another seed another path: " << (differs > 1e-3 ? "yes" : "NO")
          << std::endl;

  // A replay recorded with its own clock and frame.
  std::filesystem::create_directories("scenes");
  write_file("scenes/path.csv",
             "t,x,y,z\n"
             "# recorded on a device\n"
             "2.0, 0.100, 0.200, 0.300\n"
             "2.5, 0.110, 0.200, 0.300\n"
             "\n"
             "3.0, 0.110, 0.190, 0.310\n");
  write_file("scenes/replay.prm",
             "subsection Haptics\n"
             "  subsection Trajectory\n"
             "    set Type      = replay\n"
             "    set File name = path.csv\n"
             "  end\n"
             "end\n");
  const auto replay =
    palpate::Trajectory::create(palpate::Scene::read("scenes/replay.prm"));
  deallog << replay->description() << std::endl;
  deallog << "  duration " << replay->duration() << " s; at 0: ("
          << palpate::Utilities::to_string(replay->position(0), 6)
          << "), at 0.25 s: ("
          << palpate::Utilities::to_string(replay->position(0.25), 6)
          << "), at 0.75 s: ("
          << palpate::Utilities::to_string(replay->position(0.75), 6)
          << "), at 5 s: ("
          << palpate::Utilities::to_string(replay->position(5), 6) << ") m"
          << std::endl;

  try_replay("bad-number.csv", "0, 0, 0, 0\n0.1, 0, 0, 1e-3mm\n");
  try_replay("three-columns.csv", "0, 0, 0, 0\n0.1, 0, 0\n");
  try_replay("not-increasing.csv",
             "0, 0, 0, 0\n0.1, 0, 0, 0.001\n0.1, 0, 0, 0.002\n");
  try_replay("empty.csv", "t,x,y,z\n");
  {
    // A 2 s stroke of 14 mm recorded at 1 kHz with the times in
    // milliseconds: read as 1,999 s at 7 micrometres per second.
    std::string milliseconds = "t,x,y,z\n";
    for (unsigned int k = 0; k < 2000; ++k)
      milliseconds +=
        std::to_string(k) + "," + std::to_string(-0.014 * k / 1999) + ",0,0\n";
    try_replay("milliseconds.csv", milliseconds);
    // A slow 61 s recording in seconds at 100 Hz (5 mm, 0.08 mm/s) is a
    // motion: it was refused as milliseconds by its average speed.
    std::string slow = "t,x,y,z\n";
    for (unsigned int k = 0; k <= 6100; ++k)
      slow += std::to_string(0.01 * k) + "," +
              std::to_string(-0.005 * k / 6100) + ",0,0\n";
    write_file("slow.csv", slow);
    deallog << "slow.csv: a recording of "
            << palpate::Replay("slow.csv").duration() << " s" << std::endl;
  }
  try
    {
      palpate::Replay replay("no-such-file.csv");
    }
  catch (const palpate::InputError &e)
    {
      deallog << "no-such-file.csv: " << e.what() << std::endl;
    }
}
