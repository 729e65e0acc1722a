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



  std::vector<std::pair<unsigned int, double>>
  Scheduler::path_corners(const Utilities::Point3 &hip,
                          const Utilities::Point3 &velocity) const
  {
    // The cells the HIP is in and will pass through along its predicted
    // path (located as the interpolation locates it), and the arc length
    // to the first point of the path in their cell.
    std::vector<std::pair<unsigned int, double>> needed; // (point, arc)
    const double                                 h = grid.spacing();
    {
      Utilities::Point3 step;
      for (unsigned int k = 0; k < 3; ++k)
        step[k] = look_ahead * velocity[k];
      // At least two grid spacings along the motion. At slow speeds the
      // look-ahead time covers a fraction of a cell, and the next cell's
      // corners would count as needed only once the HIP is in that cell,
      // while a state on a real organ takes seconds. And a cell's new
      // corners take two workers about two state times, more than a hand
      // at 28 mm/s takes to cross one 10 mm cell from the moment the next
      // one is in view (doc/benchmarks/organ-speed.md, round 6).
      // Only the order changes: the cloud itself stays the look-ahead's.
      const double speed_step = Utilities::norm(step);
      if (speed_step > 0 && speed_step < 2 * h)
        for (unsigned int k = 0; k < 3; ++k)
          step[k] *= 2 * h / speed_step;
      const double       length = Utilities::norm(step);
      const unsigned int samples =
        std::min(1000u, 1u + static_cast<unsigned int>(4 * length / h));
      for (unsigned int s = 0; s <= samples; ++s)
        {
          const double      t = samples > 0 ? double(s) / samples : 0.0;
          Utilities::Point3 x;
          for (unsigned int k = 0; k < 3; ++k)
            x[k] = hip[k] + t * step[k];
          GridIndex             cell;
          std::array<double, 3> local;
          if (!grid.locate(x, cell, local))
            continue;
          for (const unsigned int c : grid.corners(cell))
            needed.emplace_back(c, t * length);
        }
      // The first arc for each point.
      std::stable_sort(needed.begin(),
                       needed.end(),
                       [](const auto &a, const auto &b) {
                         return a.first < b.first;
                       });
      needed.erase(std::unique(needed.begin(),
                               needed.end(),
                               [](const auto &a, const auto &b) {
                                 return a.first == b.first;
                               }),
                   needed.end());
    }
    return needed;
  }



  namespace
  {
    /** The grid steps to a point's six axis neighbours. */
    const int axis[6][3] =
      {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};

    /**
     * The grid box around the path from @p hip to @p hip + @p look_ahead
     * @p velocity, widened by @p radius, in @p low and @p high; false if
     * the path is not finite.
     */
    bool
    box_around_path(const StateGrid         &grid,
                    const Utilities::Point3 &hip,
                    const Utilities::Point3 &velocity,
                    const double             look_ahead,
                    const double             radius,
                    GridIndex               &low,
                    GridIndex               &high)
    {
      // The grid box around the path, widened by the radius (clamped in
      // floating point before the conversion: the host controls the HIP).
      const double h = grid.spacing(), n = grid.half_width();
      for (unsigned int k = 0; k < 3; ++k)
        {
          const double a = hip[k], b = hip[k] + look_ahead * velocity[k];
          if (!std::isfinite(a) || !std::isfinite(b))
            return false;
          low[k] = static_cast<int>(
            std::clamp(std::floor((std::min(a, b) - radius) / h), -n, n));
          high[k] = static_cast<int>(
            std::clamp(std::ceil((std::max(a, b) + radius) / h), -n, n));
        }
      return true;
    }

    /**
     * The arc length at which the path reaches @p p's cells, from
     * Scheduler::path_corners()'s list @p needed; -1 if it does not.
     */
    double
    arc_to(const std::vector<std::pair<unsigned int, double>> &needed,
           const unsigned int                                  p)
    {
      const auto it = std::lower_bound(needed.begin(),
                                       needed.end(),
                                       p,
                                       [](const auto &a, const unsigned int q) {
                                         return a.first < q;
                                       });
      return it != needed.end() && it->first == p ? it->second : -1.0;
    }

    /**
     * The candidate tasks of one Scheduler::plan(), and the questions its
     * steps ask about the grid, what is known and the HIP's path.
     */
    class Candidates
    {
    public:
      Candidates(const Scheduler                                   &scheduler,
                 const StateGrid                                   &grid,
                 const std::function<PointKnowledge(unsigned int)> &knowledge,
                 const Utilities::Point3                           &hip,
                 const Utilities::Point3                           &velocity,
                 const double                                       radius,
                 std::vector<Task>                                 &tasks)
        : scheduler(scheduler)
        , grid(grid)
        , knowledge(knowledge)
        , hip(hip)
        , velocity(velocity)
        , radius(radius)
        , tasks(tasks)
      {}

      /**
       * Add the cloud's points in the box from @p low to @p high, the
       * path's corners (@p needed) first.
       */
      void
      add_cloud(const GridIndex                                    &low,
                const GridIndex                                    &high,
                const std::vector<std::pair<unsigned int, double>> &needed);

      /** Whether the cloud is cut off from what is held. */
      bool
      cut_off() const
      {
        return tasks.empty() && unreached > 0 && under_way == 0;
      }

      /** Add the bridge's points toward the path. */
      void
      add_bridge();

    private:
      /** Distance of @p p from the HIP's predicted path. */
      double
      distance(const unsigned int p) const
      {
        return scheduler.distance_to_path(grid.position(p), hip, velocity);
      }

      /**
       * The axis neighbour of @p g with a held state nearest the HIP (ties:
       * the lower grid number), among those accepted by @p admissible; -1
       * if none.
       */
      template <typename Admissible>
      int
      find_source(const GridIndex &g, const Admissible &admissible) const;

      /** Whether @p g has an unknown axis neighbour accepted by @p wanted. */
      template <typename Wanted>
      bool
      leads_to(const GridIndex &g, const Wanted &wanted) const;

      const Scheduler                                   &scheduler;
      const StateGrid                                   &grid;
      const std::function<PointKnowledge(unsigned int)> &knowledge;
      const Utilities::Point3                           &hip;
      const Utilities::Point3                           &velocity;
      const double                                       radius;
      std::vector<Task>                                 &tasks;
      unsigned int                                       unreached = 0;
      unsigned int                                       under_way = 0;
    };



    template <typename Admissible>
    int
    Candidates::find_source(const GridIndex  &g,
                            const Admissible &admissible) const
    {
      int    source = -1;
      double best   = 0;
      for (const auto &a : axis)
        {
          const GridIndex n{{g[0] + a[0], g[1] + a[1], g[2] + a[2]}};
          if (!grid.contains(n))
            continue;
          const unsigned int q = grid.linear(n);
          if (knowledge(q) != PointKnowledge::source || !admissible(q))
            continue;
          const double d = Utilities::distance(grid.position(n), hip);
          if (source < 0 || d < best || (d == best && q < unsigned(source)))
            source = q, best = d;
        }
      return source;
    }



    template <typename Wanted>
    bool
    Candidates::leads_to(const GridIndex &g, const Wanted &wanted) const
    {
      for (const auto &a : axis)
        {
          const GridIndex n{{g[0] + a[0], g[1] + a[1], g[2] + a[2]}};
          if (grid.contains(n) &&
              knowledge(grid.linear(n)) == PointKnowledge::unknown &&
              wanted(grid.linear(n)))
            return true;
        }
      return false;
    }



    void
    Candidates::add_cloud(
      const GridIndex                                    &low,
      const GridIndex                                    &high,
      const std::vector<std::pair<unsigned int, double>> &needed)
    {
      const auto any = [](const unsigned int) { return true; };
      // The cloud: unknown points, and points whose whole state was dropped
      // (memory budget) where the cloud needs it again as a source.
      for (int k = low[2]; k <= high[2]; ++k)
        for (int j = low[1]; j <= high[1]; ++j)
          for (int i = low[0]; i <= high[0]; ++i)
            {
              const GridIndex      g{{i, j, k}};
              const unsigned int   p     = grid.linear(g);
              const PointKnowledge known = knowledge(p);
              if (known != PointKnowledge::unknown &&
                  known != PointKnowledge::computed &&
                  known != PointKnowledge::in_progress)
                continue;
              const double d   = distance(p);
              const double arc = arc_to(needed, p);
              if (d > radius && arc < 0)
                continue;
              if (known == PointKnowledge::in_progress)
                {
                  ++under_way;
                  continue;
                }
              if (known == PointKnowledge::computed &&
                  !leads_to(g, [&](const unsigned int q) {
                    return distance(q) <= radius || arc_to(needed, q) >= 0;
                  }))
                continue;
              const int source = find_source(g, any);
              if (source >= 0)
                tasks.push_back({p,
                                 static_cast<unsigned int>(source),
                                 arc >= 0 ? arc : d,
                                 arc >= 0});
              else if (known == PointKnowledge::unknown)
                ++unreached;
            }
    }



    void
    Candidates::add_bridge()
    {
      for (unsigned int p = 0; p < grid.size(); ++p)
        {
          const PointKnowledge known = knowledge(p);
          if (known != PointKnowledge::unknown &&
              known != PointKnowledge::computed)
            continue;
          const GridIndex g = grid.index(p);
          const double    d = distance(p);
          if (known == PointKnowledge::computed &&
              !leads_to(g, [&](const unsigned int q) {
                return distance(q) < d - 1e-12;
              }))
            continue;
          const int source = find_source(g, [&](const unsigned int q) {
            return d < distance(q) - 1e-12;
          });
          if (source >= 0)
            tasks.push_back({p, static_cast<unsigned int>(source), d});
        }
    }

    /** Keep the @p max_tasks most urgent of @p tasks, most urgent first. */
    void
    keep_most_urgent(std::vector<Task> &tasks, const unsigned int max_tasks)
    {
      // Most urgent first: the HIP's cell, then the distance from the path
      // (to the nanometre, so that the order is a strict weak ordering and
      // does not depend on round-off), then the grid number.
      const auto order = [](const Task &a, const Task &b) {
        if (a.corner != b.corner)
          return a.corner;
        const long long da = std::llround(a.priority * 1e9),
                        db = std::llround(b.priority * 1e9);
        if (da != db)
          return da < db;
        return a.target < b.target;
      };
      if (tasks.size() > max_tasks)
        {
          std::partial_sort(tasks.begin(),
                            tasks.begin() + max_tasks,
                            tasks.end(),
                            order);
          tasks.resize(max_tasks);
        }
      else
        std::sort(tasks.begin(), tasks.end(), order);
    }
  } // namespace



  std::vector<Task>
  Scheduler::plan(const Utilities::Point3                           &hip,
                  const Utilities::Point3                           &velocity,
                  const std::function<PointKnowledge(unsigned int)> &knowledge,
                  const unsigned int                                 max_tasks,
                  const bool allow_bridge) const
  {
    std::vector<Task> candidates;
    if (max_tasks == 0)
      return candidates;
    GridIndex low, high;
    if (!box_around_path(grid, hip, velocity, look_ahead, radius, low, high))
      return candidates;

    // The cells the HIP is in and will pass through along its predicted
    // path: their corners come before everything else, in the order the
    // HIP will need them.
    const std::vector<std::pair<unsigned int, double>> needed =
      path_corners(hip, velocity);
    // The path's corners are scheduled wherever they are: the path runs
    // two cells ahead, beyond the cloud around the look-ahead's segment.
    for (const auto &[point, arc] : needed)
      {
        const GridIndex g = grid.index(point);
        for (unsigned int k = 0; k < 3; ++k)
          {
            low[k]  = std::min(low[k], g[k]);
            high[k] = std::max(high[k], g[k]);
          }
      }
    Candidates steps(*this, grid, knowledge, hip, velocity, radius, candidates);
    steps.add_cloud(low, high, needed);

    // Points of the cloud are unknown, none can be reached from what is
    // held and none is under way (the HIP jumped, or outran the computed
    // front): build a bridge, points next to held states that are nearer
    // to the HIP's path than their source, even outside the cloud. Only
    // steps toward the path: a bridge ends where the cloud begins, and
    // cloud points walled off by failure points do not make it grow.
    if (allow_bridge && steps.cut_off())
      steps.add_bridge();

    keep_most_urgent(candidates, max_tasks);
    return candidates;
  }
} // namespace palpate
