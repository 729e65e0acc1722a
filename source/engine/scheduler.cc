// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

#include <palpate/engine/scheduler.h>

#include <algorithm>
#include <cmath>

namespace palpate
{
  Scheduler::Scheduler(const StateGrid &grid,
                       const double     cloud_radius,
                       const double     look_ahead_time)
    : grid(grid)
    , radius(cloud_radius)
    , look_ahead(look_ahead_time)
  {}



  double
  Scheduler::distance_to_path(const Utilities::Point3 &x,
                              const Utilities::Point3 &hip,
                              const Utilities::Point3 &velocity) const
  {
    // The segment hip -> hip + T v; the nearest point on it to x.
    Utilities::Point3 d, r;
    double            dd = 0, rd = 0;
    for (unsigned int k = 0; k < 3; ++k)
      {
        d[k] = look_ahead * velocity[k];
        r[k] = x[k] - hip[k];
        dd += d[k] * d[k];
        rd += r[k] * d[k];
      }
    const double t = dd > 0 ? std::clamp(rd / dd, 0.0, 1.0) : 0.0;
    return Utilities::norm(
      {{r[0] - t * d[0], r[1] - t * d[1], r[2] - t * d[2]}});
  }



  bool
  Scheduler::in_cloud(const unsigned int       point,
                      const Utilities::Point3 &hip,
                      const Utilities::Point3 &velocity) const
  {
    return distance_to_path(grid.position(point), hip, velocity) <= radius;
  }



  std::vector<Task>
  Scheduler::plan(const Utilities::Point3                           &hip,
                  const Utilities::Point3                           &velocity,
                  const std::function<PointKnowledge(unsigned int)> &knowledge,
                  const unsigned int max_tasks) const
  {
    std::vector<Task> candidates;
    if (max_tasks == 0)
      return candidates;

    // The grid box around the path, widened by the radius.
    const double h = grid.spacing();
    GridIndex    low, high;
    for (unsigned int k = 0; k < 3; ++k)
      {
        const double a = hip[k], b = hip[k] + look_ahead * velocity[k];
        if (!std::isfinite(a) || !std::isfinite(b))
          return candidates;
        low[k] =
          std::max(-grid.half_width(),
                   static_cast<int>(std::floor((std::min(a, b) - radius) / h)));
        high[k] =
          std::min(grid.half_width(),
                   static_cast<int>(std::ceil((std::max(a, b) + radius) / h)));
      }

    // The cell the HIP is in: its corners come before everything else.
    GridIndex             cell;
    std::array<double, 3> local;
    const bool            located         = grid.locate(hip, cell, local);
    const auto            in_current_cell = [&](const GridIndex &g) {
      return located && g[0] - cell[0] >= 0 && g[0] - cell[0] <= 1 &&
             g[1] - cell[1] >= 0 && g[1] - cell[1] <= 1 &&
             g[2] - cell[2] >= 0 && g[2] - cell[2] <= 1;
    };

    static const int axis[6][3] = {
      {1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};
    for (int k = low[2]; k <= high[2]; ++k)
      for (int j = low[1]; j <= high[1]; ++j)
        for (int i = low[0]; i <= high[0]; ++i)
          {
            const GridIndex    g{{i, j, k}};
            const unsigned int p = grid.linear(g);
            if (knowledge(p) != PointKnowledge::unknown)
              continue;
            const double distance =
              distance_to_path(grid.position(g), hip, velocity);
            if (distance > radius)
              continue;
            // Source: the axis neighbour with a held state nearest the HIP.
            int    source = -1;
            double best   = 0;
            for (const auto &a : axis)
              {
                const GridIndex n{{i + a[0], j + a[1], k + a[2]}};
                if (!grid.contains(n))
                  continue;
                const unsigned int q = grid.linear(n);
                if (knowledge(q) != PointKnowledge::source)
                  continue;
                const double d = Utilities::distance(grid.position(n), hip);
                if (source < 0 || d < best - 1e-15 ||
                    (std::abs(d - best) <= 1e-15 && q < unsigned(source)))
                  source = q, best = d;
              }
            if (source >= 0)
              candidates.push_back(
                {p,
                 static_cast<unsigned int>(source),
                 in_current_cell(g) ? distance - 1.0 : distance});
          }

    // Nothing in the cloud can be reached from what is computed (the HIP
    // jumped, or outran the computed front): build a bridge, the frontier
    // points (unknown, next to a held state) nearest the HIP's path.
    if (candidates.empty())
      for (unsigned int p = 0; p < grid.size(); ++p)
        {
          if (knowledge(p) != PointKnowledge::unknown)
            continue;
          const GridIndex g      = grid.index(p);
          int             source = -1;
          double          best   = 0;
          for (const auto &a : axis)
            {
              const GridIndex n{{g[0] + a[0], g[1] + a[1], g[2] + a[2]}};
              if (!grid.contains(n))
                continue;
              const unsigned int q = grid.linear(n);
              if (knowledge(q) != PointKnowledge::source)
                continue;
              const double d = Utilities::distance(grid.position(n), hip);
              if (source < 0 || d < best - 1e-15 ||
                  (std::abs(d - best) <= 1e-15 && q < unsigned(source)))
                source = q, best = d;
            }
          // Only steps toward the path: a bridge ends where the cloud
          // begins, and points the cloud cannot reach because failure
          // points wall them off do not make it grow without bound.
          const double distance =
            distance_to_path(grid.position(g), hip, velocity);
          if (source >= 0 &&
              distance < distance_to_path(grid.position(
                                            static_cast<unsigned int>(source)),
                                          hip,
                                          velocity) -
                           1e-12)
            candidates.push_back(
              {p, static_cast<unsigned int>(source), distance});
        }

    const auto order = [](const Task &a, const Task &b) {
      if (std::abs(a.priority - b.priority) > 1e-12)
        return a.priority < b.priority;
      return a.target < b.target;
    };
    if (candidates.size() > max_tasks)
      {
        std::partial_sort(candidates.begin(),
                          candidates.begin() + max_tasks,
                          candidates.end(),
                          order);
        candidates.resize(max_tasks);
      }
    else
      std::sort(candidates.begin(), candidates.end(), order);
    return candidates;
  }
} // namespace palpate
