// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

// Where `palpate study` looks: the HIP positions, on smooth random
// trajectories around rest, at which the interpolated force is compared
// with direct solves; the grid cells around them, whose states a setting
// computes; and the states a straight path needs per cm, which sets the
// speed the engine can keep up with.

#include <palpate/app/study_impl.h>
#include <palpate/state_space/state_grid.h>

#include <algorithm>
#include <array>
#include <random>

namespace palpate
{
  namespace internal
  {
    namespace
    {
      /**
       * HIP positions along smooth random trajectories in the ball of
       * @p radius around rest: Catmull-Rom splines through 5 random points,
       * @p per_trajectory positions each, in order along the path.
       */
      std::vector<std::vector<Point3>>
      trajectories(const unsigned int n,
                   const unsigned int per_trajectory,
                   const double       radius,
                   const unsigned int seed)
      {
        std::mt19937                           rng(seed);
        std::uniform_real_distribution<double> u(-1, 1);
        const auto                             random_point = [&]() {
          Point3 p;
          do
            p = {{u(rng), u(rng), u(rng)}};
          while (Utilities::norm(p) > 1);
          for (double &c : p)
            c *= radius;
          return p;
        };
        std::vector<std::vector<Point3>> result(n);
        for (auto &path : result)
          {
            std::vector<Point3> c(5);
            for (auto &p : c)
              p = random_point();
            // Catmull-Rom through c[1..3], with c[0] and c[4] as the ends'
            // tangent guides.
            for (unsigned int k = 0; k < per_trajectory; ++k)
              {
                const double s = 2.0 * k / std::max(1u, per_trajectory - 1);
                const unsigned int seg = std::min(1u, static_cast<unsigned>(s));
                const double       t   = s - seg;
                const Point3 &p0 = c[seg], &p1 = c[seg + 1], &p2 = c[seg + 2],
                             &p3 = c[seg + 3];
                Point3 x;
                for (unsigned int d = 0; d < 3; ++d)
                  x[d] = 0.5 *
                         (2 * p1[d] + (-p0[d] + p2[d]) * t +
                          (2 * p0[d] - 5 * p1[d] + 4 * p2[d] - p3[d]) * t * t +
                          (-p0[d] + 3 * p1[d] - 3 * p2[d] + p3[d]) * t * t * t);
                // Keep it in the ball.
                const double r = Utilities::norm(x);
                if (r > radius)
                  for (double &v : x)
                    v *= radius / r;
                path.push_back(x);
              }
          }
        return result;
      }
    } // namespace



    std::set<unsigned int>
    cell_corners(const StateGrid &grid, const std::vector<Point3> &x)
    {
      std::set<unsigned int> c;
      for (const Point3 &p : x)
        {
          GridIndex             lower;
          std::array<double, 3> local;
          if (grid.locate(p, lower, local))
            for (const unsigned int k : grid.corners(lower))
              c.insert(k);
        }
      return c;
    }

    std::set<unsigned int>
    with_neighbours(const StateGrid &grid, const std::set<unsigned int> &points)
    {
      std::set<unsigned int> r;
      for (const unsigned int q : points)
        for (const unsigned int n : grid.neighbourhood(q))
          r.insert(n);
      return r;
    }

    double
    states_per_cm(const double h)
    {
      const StateGrid                        grid(h, 0.2);
      std::mt19937                           rng(3);
      std::uniform_real_distribution<double> u(-1, 1);
      double                                 total = 0;
      const unsigned int                     lines = 200;
      for (unsigned int l = 0; l < lines; ++l)
        {
          Point3 start = {{0.02 * u(rng), 0.02 * u(rng), 0.02 * u(rng)}}, dir;
          do
            dir = {{u(rng), u(rng), u(rng)}};
          while (Utilities::norm(dir) > 1 || Utilities::norm(dir) < 0.1);
          const double        n = Utilities::norm(dir);
          std::vector<Point3> x;
          const unsigned int  steps = static_cast<unsigned>(0.1 / (h / 20));
          for (unsigned int k = 0; k <= steps; ++k)
            {
              Point3 p;
              for (unsigned int d = 0; d < 3; ++d)
                p[d] = start[d] + dir[d] / n * 0.1 * k / steps;
              x.push_back(p);
            }
          total += cell_corners(grid, x).size();
        }
      return total / lines / 10.0;
    }



    void
    Study::choose_positions()
    {
      // --- The HIP positions: smooth random trajectories in a ball of
      // 12 mm around rest (cells of up to 20 mm around them stay within the
      // range where the liver scenes' states exist), or of half the state
      // space's extent if that is smaller.
      const unsigned int n_samples =
        options.samples > 0 ? options.samples : (quick ? 80 : 240);
      const unsigned int per_path = 20;
      n_paths                     = (n_samples + per_path - 1) / per_path;
      radius = std::min(0.012, 0.5 * p0.state_space.extent);
      paths  = trajectories(n_paths, per_path, radius, 2026);
      for (const auto &path : paths)
        for (const Point3 &x : path)
          if (positions.size() < n_samples)
            positions.push_back(x);
    }
  } // namespace internal
} // namespace palpate
