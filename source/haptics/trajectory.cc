// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

#include <palpate/base/exceptions.h>
#include <palpate/base/plugins.templates.h>
#include <palpate/haptics/trajectory.h>
#include <palpate/scene/scene.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <random>
#include <sstream>

namespace palpate
{
  namespace
  {
    Utilities::Point3
    normalized(const Utilities::Point3 &v)
    {
      // Scaled by the largest component first: a direction of 1e308 (or
      // 1e-300) in each component has a norm beyond (below) a double's
      // range, but a perfectly good direction.
      const double m =
        std::max({std::abs(v[0]), std::abs(v[1]), std::abs(v[2])});
      const Utilities::Point3 u{{v[0] / m, v[1] / m, v[2] / m}};
      const double            n = Utilities::norm(u);
      return {{u[0] / n, u[1] / n, u[2] / n}};
    }
  } // namespace



  StraightLine::StraightLine(const Utilities::Point3 &direction,
                             const double             speed,
                             const double             duration)
    : d(normalized(direction))
    , speed(speed)
    , length(duration)
  {}



  Utilities::Point3
  StraightLine::position(const double t) const noexcept
  {
    const double s = speed * std::clamp(t, 0.0, length);
    return {{s * d[0], s * d[1], s * d[2]}};
  }



  std::string
  StraightLine::description() const
  {
    return "straight line along (" + Utilities::to_string(d, 3) + ") at " +
           Utilities::to_string(1000 * speed, 4) + " mm/s for " +
           Utilities::to_string(length, 3) + " s";
  }



  Circle::Circle(const Utilities::Point3 &normal,
                 const double             radius,
                 const double             speed,
                 const double             duration)
    : radius(radius)
    , omega(speed / radius)
    , length(duration)
  {
    const Utilities::Point3 n = normalized(normal);
    // Any unit vector normal to n, then the third by the cross product.
    const Utilities::Point3 a  = std::abs(n[0]) < 0.9 ?
                                   Utilities::Point3{{1, 0, 0}} :
                                   Utilities::Point3{{0, 1, 0}};
    const double            an = a[0] * n[0] + a[1] * n[1] + a[2] * n[2];
    e1 = normalized({{a[0] - an * n[0], a[1] - an * n[1], a[2] - an * n[2]}});
    e2 = {{n[1] * e1[2] - n[2] * e1[1],
           n[2] * e1[0] - n[0] * e1[2],
           n[0] * e1[1] - n[1] * e1[0]}};
  }



  Utilities::Point3
  Circle::position(const double t) const noexcept
  {
    const double phi = omega * std::clamp(t, 0.0, length);
    const double c = radius * (std::cos(phi) - 1), s = radius * std::sin(phi);
    return {
      {c * e1[0] + s * e2[0], c * e1[1] + s * e2[1], c * e1[2] + s * e2[2]}};
  }



  std::string
  Circle::description() const
  {
    return "circle of radius " + Utilities::to_string(1000 * radius, 4) +
           " mm at " + Utilities::to_string(1000 * omega * radius, 4) +
           " mm/s for " + Utilities::to_string(length, 3) + " s";
  }



  SmoothRandom::SmoothRandom(const double       radius,
                             const double       speed,
                             const double       duration,
                             const unsigned int seed)
    : length(duration)
    , radius(radius)
    , speed(speed)
    , seed(seed)
  {
    std::mt19937                           random(seed);
    std::uniform_real_distribution<double> u(0, 1);
    // Per axis, |sum_k a_k (sin(w_k t + phi_k) - sin(phi_k))| <= 2 sum_k
    // a_k <= radius / sqrt(3), so |p| <= radius. Frequencies are random
    // within a factor 3 of each other, then scaled together so that the
    // root-mean-square speed, sqrt(sum (a w)^2 / 2), is the given speed.
    double mean_square = 0;
    for (unsigned int d = 0; d < 3; ++d)
      for (unsigned int k = 0; k < 3; ++k)
        {
          amplitude[d][k] =
            radius / (6 * std::sqrt(3.0)) * (0.5 + 0.5 * u(random));
          frequency[d][k] = 1 + 2 * u(random);
          phase[d][k]     = 2 * M_PI * u(random);
          mean_square += 0.5 * std::pow(amplitude[d][k] * frequency[d][k], 2);
        }
    const double scale = speed / std::sqrt(mean_square);
    for (auto &axis : frequency)
      for (double &w : axis)
        w *= scale;
  }



  Utilities::Point3
  SmoothRandom::position(const double t) const noexcept
  {
    const double      s = std::clamp(t, 0.0, length);
    Utilities::Point3 p{{0, 0, 0}};
    for (unsigned int d = 0; d < 3; ++d)
      for (unsigned int k = 0; k < 3; ++k)
        p[d] += amplitude[d][k] * (std::sin(frequency[d][k] * s + phase[d][k]) -
                                   std::sin(phase[d][k]));
    return p;
  }



  std::string
  SmoothRandom::description() const
  {
    return "smooth random motion within " +
           Utilities::to_string(1000 * radius, 4) + " mm, RMS speed " +
           Utilities::to_string(1000 * speed, 4) + " mm/s, seed " +
           std::to_string(seed) + ", for " + Utilities::to_string(length, 3) +
           " s";
  }



  namespace
  {
    /**
     * Refuse a replay file that is not a regular file or is too large to
     * be a recording, before anything is read.
     */
    void
    check_replay_file(const std::string &filename)
    {
      // A recording is a CSV of at most an hour at 1 kHz (~150 MB at most,
      // a few MB usually): a device file (/dev/zero) or a huge file is
      // refused before anything is read, instead of growing without bound.
      constexpr std::uintmax_t max_bytes = std::uintmax_t(256) << 20;
      std::error_code          error;
      const auto status = std::filesystem::status(filename, error);
      if (!error && std::filesystem::exists(status) &&
          !std::filesystem::is_regular_file(status))
        throw InputError(filename,
                         0,
                         "trajectory replay (Haptics / Trajectory / File name)",
                         "this is not a regular file (a directory, a device "
                         "or a pipe)",
                         "name the recording's CSV file.");
      const auto size = std::filesystem::file_size(filename, error);
      if (!error && size > max_bytes)
        throw InputError(filename,
                         0,
                         "trajectory replay (Haptics / Trajectory / File name)",
                         "the file has " + std::to_string(size >> 20) +
                           " MiB; a recording of an hour at 1 kHz has about "
                           "150 MiB, and at most 256 MiB are read",
                         "check that this is the recording (t, x, y, z per "
                         "line), or shorten it.");
    }

    /** Drop a UTF-8 byte order mark from the first @p line; refuse UTF-16. */
    void
    strip_byte_order_mark(std::string       &line,
                          const unsigned int number,
                          const std::string &filename)
    {
      // A byte order mark (some editors begin UTF-8 with one) is not
      // part of the first line; UTF-16 is not a CSV palpate reads.
      if (number == 1 && line.rfind("\xEF\xBB\xBF", 0) == 0)
        line.erase(0, 3);
      else if (number == 1 && line.size() >= 2 &&
               (line.rfind("\xFF\xFE", 0) == 0 ||
                line.rfind("\xFE\xFF", 0) == 0))
        throw InputError(
          filename,
          1,
          "trajectory replay (Haptics / Trajectory / File name)",
          "the file is UTF-16 text (it begins with a UTF-16 byte order "
          "mark); a recording is plain text (ASCII or UTF-8)",
          "save it as UTF-8 or ASCII, or convert it: iconv -f UTF-16 -t "
          "UTF-8 '" +
            filename + "' > recording.csv");
    }

    /**
     * Whether the trimmed line @p t holds no position: empty, a comment, or
     * (@p before_data) a header line.
     */
    bool
    skipped_line(const std::string &t, const bool before_data)
    {
      // Comments, and a header line before the data: one whose first
      // field is not a number ("nan" and "inf" are numbers, refused
      // below, not a header to skip).
      const auto not_a_number = [](const std::string &field) {
        char *end = nullptr;
        std::strtod(field.c_str(), &end);
        return end == field.c_str();
      };
      return t.empty() || t[0] == '#' ||
             (before_data && std::isalpha(static_cast<unsigned char>(t[0])) &&
              not_a_number(t.substr(0, t.find(','))));
    }

    /** The four finite numbers t, x, y, z of the trimmed line @p t. */
    std::array<double, 4>
    timed_position(const std::string &t,
                   const unsigned int number,
                   const std::string &filename)
    {
      const auto            pieces = Utilities::split(t, ',');
      std::array<double, 4> v;
      bool                  ok = pieces.size() == 4;
      for (unsigned int k = 0; ok && k < 4; ++k)
        {
          std::size_t used = 0;
          try
            {
              v[k] = std::stod(pieces[k], &used);
            }
          catch (const std::exception &)
            {
              used = 0;
            }
          ok = used == pieces[k].size() && std::isfinite(v[k]);
        }
      if (!ok)
        throw InputError(
          filename,
          number,
          "trajectory replay (Haptics / Trajectory / File name)",
          "the line is not four numbers t, x, y, z",
          "write one timed position per line: t (s), x, y, z (m).");
      return v;
    }

    /**
     * Refuse the timed position @p v of line @p number if its time does not
     * follow the last one's, or a hand could not have moved so.
     */
    void
    check_motion(const std::array<double, 4>          &v,
                 const std::vector<double>            &times,
                 const std::vector<Utilities::Point3> &points,
                 const unsigned int                    number,
                 const std::string                    &filename)
    {
      if (!times.empty() && !(v[0] > times.back()))
        throw InputError(
          filename,
          number,
          "trajectory replay (Haptics / Trajectory / File name)",
          "the times do not increase",
          "sort the lines by time; each time must be later than the last.");
      // A hand on a device stays within reach and moves at most a few
      // m/s: positions far away or jumps faster than that are a unit
      // mistake (millimetres, milliseconds), and 1e308 would overflow.
      constexpr double max_reach = 1;  // m from the first position
      constexpr double max_speed = 10; // m/s between two lines
      if (points.empty())
        return;
      const Utilities::Point3 x{{v[1], v[2], v[3]}};
      const double from_first = Utilities::distance(x, points.front());
      if (!(from_first <= max_reach))
        throw InputError(
          filename,
          number,
          "trajectory replay (Haptics / Trajectory / File name)",
          "the position is " +
            (std::isfinite(from_first) ?
               Utilities::to_string(from_first, 3) + " m" :
               std::string("over 1e308 m")) +
            " from the first one; a hand on a device moves within "
            "about half a metre, and at most " +
            Utilities::to_string(max_reach, 3) + " m is accepted",
          "give the positions in metres (not millimetres).");
      const double speed =
        Utilities::distance(x, points.back()) / (v[0] - times.back());
      if (!(speed <= max_speed))
        throw InputError(
          filename,
          number,
          "trajectory replay (Haptics / Trajectory / File name)",
          "from the line before, the probe would move at " +
            Utilities::to_string(speed, 3) +
            " m/s; a hand moves at most a few m/s, and at most " +
            Utilities::to_string(max_speed, 3) + " m/s is accepted",
          "give the times in seconds and the positions in metres "
          "(not milliseconds or millimetres).");
    }

    /** Read the timed positions of @p filename into @p times and @p points. */
    void
    read_timed_positions(const std::string              &filename,
                         std::vector<double>            &times,
                         std::vector<Utilities::Point3> &points)
    {
      std::ifstream in(filename);
      if (!in)
        throw InputError(
          filename,
          0,
          "trajectory replay (Haptics / Trajectory / File name)",
          "the file cannot be opened",
          "check Haptics / Trajectory / File name (relative to the scene "
          "file's directory).");
      std::string  line;
      unsigned int number = 0;
      while (std::getline(in, line))
        {
          ++number;
          strip_byte_order_mark(line, number, filename);
          const std::string t = Utilities::trim(line);
          if (skipped_line(t, times.empty()))
            continue;
          const std::array<double, 4> v = timed_position(t, number, filename);
          check_motion(v, times, points, number, filename);
          times.push_back(v[0]);
          points.push_back({{v[1], v[2], v[3]}});
        }
    }
  } // namespace



  Replay::Replay(const std::string &filename)
    : file(filename)
  {
    check_replay_file(filename);
    read_timed_positions(filename, times, points);
    if (times.empty())
      throw InputError(
        filename,
        0,
        "trajectory replay (Haptics / Trajectory / File name)",
        "the file holds no positions",
        "write one timed position per line: t (s), x, y, z (m).");

    // Count from the first row: the replay starts at rest at t = 0.
    const double            t0       = times.front();
    const Utilities::Point3 x0       = points.front();
    double                  farthest = 0;
    for (std::size_t k = 0; k < times.size(); ++k)
      {
        times[k] -= t0;
        for (unsigned int d = 0; d < 3; ++d)
          points[k][d] -= x0[d];
        farthest = std::max(farthest, Utilities::norm(points[k]));
      }
    // A recording that does not move is no motion, as Speed = 0 is not
    // (Scene::check_haptics): a single line, or many lines at one position
    // or within a fraction of a millisecond, would replay as 0 N and exit 0,
    // as if a motion had been rendered.
    if (times.back() < Limits::min_replay_duration)
      throw InputError(filename,
                       0,
                       "trajectory replay (Haptics / Trajectory / File name)",
                       "the recording lasts " +
                         Utilities::to_string(times.back(), 3) + " s (" +
                         std::to_string(times.size()) +
                         (times.size() == 1 ? " position" : " positions") +
                         "): at least 0.01 s (ten ticks of a 1 kHz "
                         "loop) are needed for any motion",
                       "record at least two timed positions, with the times "
                       "in seconds.");
    if (farthest < Limits::min_motion_length)
      throw InputError(filename,
                       0,
                       "trajectory replay (Haptics / Trajectory / File name)",
                       "every position is within " +
                         Utilities::to_string(farthest, 3) +
                         " m of the first: at least " +
                         Utilities::to_string(Limits::min_motion_length, 3) +
                         " m (0.1 mm) of motion are needed for the force to "
                         "change",
                       "record a motion, with the positions in metres.");
    // Times in milliseconds read as seconds would replay a 2 s stroke of
    // 2,000 lines as 1,999 s at micrometres per second, without a word. A
    // device records at 100 Hz - 1 kHz: a long recording whose lines are
    // typically half a second or more apart is one in milliseconds (1 - 10
    // apart). The median step tells them apart where an average speed
    // cannot: a 99 ms stroke written in ms reads as a plausible 99 s one,
    // and a slow 61 s recording in seconds looks as slow as one in ms.
    if (times.size() >= 100)
      {
        std::vector<double> steps(times.size() - 1);
        for (std::size_t k = 1; k < times.size(); ++k)
          steps[k - 1] = times[k] - times[k - 1];
        std::nth_element(steps.begin(),
                         steps.begin() + steps.size() / 2,
                         steps.end());
        const double median = steps[steps.size() / 2];
        if (median >= 0.5)
          throw InputError(
            filename,
            0,
            "trajectory replay (Haptics / Trajectory / File name)",
            "its " + std::to_string(times.size()) +
              " positions are typically " + Utilities::to_string(median, 3) +
              " s apart (a recording of " +
              Utilities::to_string(times.back(), 4) +
              " s): a haptic device records at 100 - 1000 Hz, so the "
              "times look like milliseconds",
            "give the times in seconds (times in milliseconds divided by "
            "1000).");
      }
  }



  Utilities::Point3
  Replay::position(const double t) const noexcept
  {
    if (t <= times.front())
      return points.front();
    if (t >= times.back())
      return points.back();
    const std::size_t k =
      std::upper_bound(times.begin(), times.end(), t) - times.begin();
    const double      s = (t - times[k - 1]) / (times[k] - times[k - 1]);
    Utilities::Point3 p;
    for (unsigned int d = 0; d < 3; ++d)
      p[d] = points[k - 1][d] + s * (points[k][d] - points[k - 1][d]);
    return p;
  }



  double
  Replay::duration() const noexcept
  {
    return times.back();
  }



  std::string
  Replay::description() const
  {
    return "replay of " + std::to_string(times.size()) + " positions from '" +
           file + "' (" + Utilities::to_string(times.back(), 4) + " s)";
  }



  std::unique_ptr<Trajectory>
  Trajectory::create(const Scene &scene)
  {
    const auto &t   = scene.parameters.haptics.trajectory;
    const auto  own = t.own.find(t.type);
    try
      {
        return TrajectoryRegistry::create(
          t.type, own == t.own.end() ? Plugins::Entries() : own->second, scene);
      }
    catch (const Plugins::EntryError &e)
      {
        throw scene.error("Haptics/Trajectory/" + t.type + "/" + e.entry,
                          e.problem,
                          e.fix);
      }
  }



  template class Plugins::Registry<Trajectory, Scene>;
} // namespace palpate
