// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

#include <palpate/base/exceptions.h>
#include <palpate/mesh/surface_repair.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <map>
#include <queue>
#include <set>
#include <unordered_map>

namespace palpate
{
  using Utilities::Point3;

  std::vector<std::string>
  SurfaceRepair::lines() const
  {
    std::vector<std::string> l;
    if (merged_vertices > 0)
      l.push_back("merged " + std::to_string(merged_vertices) +
                  " coincident vertices (STL and some exporters store each "
                  "triangle's own)");
    if (unused_vertices > 0)
      l.push_back("dropped " + std::to_string(unused_vertices) +
                  " vertices no triangle uses");
    if (degenerate_triangles > 0)
      l.push_back("dropped " + std::to_string(degenerate_triangles) +
                  " degenerate triangles (a repeated vertex)");
    if (duplicate_triangles > 0)
      l.push_back("dropped " + std::to_string(duplicate_triangles) +
                  " duplicate triangles");
    if (reoriented_triangles > 0)
      l.push_back("turned " + std::to_string(reoriented_triangles) +
                  " triangles to agree with their neighbours");
    if (turned_outward)
      l.push_back("the surface faced inward: turned it outward");
    if (removed_shells > 0)
      l.push_back("removed " + std::to_string(removed_shells) +
                  (removed_shells == 1 ? " tiny separate shell (" :
                                         " tiny separate shells (") +
                  std::to_string(removed_triangles) + " triangles, " +
                  Utilities::to_string(removed_volume * 1e9, 3) +
                  " mm^3 together)");
    if (filled_holes > 0)
      l.push_back("closed " + std::to_string(filled_holes) +
                  (filled_holes == 1 ? " small hole" : " small holes") +
                  " with " + std::to_string(fill_triangles) + " triangles");
    return l;
  }



  namespace
  {
    using Triangle = std::array<unsigned int, 3>;

    std::uint64_t
    edge_key(const unsigned int a, const unsigned int b)
    {
      return (std::uint64_t(std::min(a, b)) << 32) | std::max(a, b);
    }

    std::string
    at(const Point3 &x)
    {
      return "(" + Utilities::to_string(x, 4) + ") m";
    }

    /** Merge vertices closer than @p tol; returns the number merged. */
    unsigned int
    merge_vertices(Surface &s, const double tol)
    {
      std::unordered_map<std::uint64_t, std::vector<unsigned int>> cells;
      const auto                                                   cell_of =
        [&](const Point3 &x, const int dx, const int dy, const int dz) {
          const auto c = [&](const double v, const int d) {
            return static_cast<std::uint64_t>(
                     static_cast<std::int64_t>(std::floor(v / tol)) + d +
                     (1 << 20)) &
                   0x1fffff;
          };
          return (c(x[0], dx) << 42) | (c(x[1], dy) << 21) | c(x[2], dz);
        };
      std::vector<unsigned int> map(s.vertices.size());
      std::vector<Point3>       kept;
      for (unsigned int v = 0; v < s.vertices.size(); ++v)
        {
          const Point3 &x     = s.vertices[v];
          long          found = -1;
          for (int dx = -1; dx <= 1 && found < 0; ++dx)
            for (int dy = -1; dy <= 1 && found < 0; ++dy)
              for (int dz = -1; dz <= 1 && found < 0; ++dz)
                {
                  const auto it = cells.find(cell_of(x, dx, dy, dz));
                  if (it != cells.end())
                    for (const unsigned int k : it->second)
                      if (Utilities::distance(kept[k], x) <= tol)
                        {
                          found = k;
                          break;
                        }
                }
          if (found < 0)
            {
              found = kept.size();
              kept.push_back(x);
              cells[cell_of(x, 0, 0, 0)].push_back(found);
            }
          map[v] = found;
        }
      const unsigned int merged = s.vertices.size() - kept.size();
      s.vertices                = kept;
      for (auto &t : s.triangles)
        for (auto &v : t)
          v = map[v];
      return merged;
    }

    double
    signed_volume(const Surface &s, const std::vector<unsigned int> &tris)
    {
      double v = 0;
      for (const unsigned int t : tris)
        {
          const auto &T = s.triangles[t];
          v += Utilities::dot(s.vertices[T[0]],
                              Utilities::cross(s.vertices[T[1]],
                                               s.vertices[T[2]]));
        }
      return v / 6;
    }
  } // namespace



  namespace
  {
    /**
     * The steps of repair_surface() on one surface, and what they share:
     * the edges' triangles and each triangle's shell.
     */
    class Repairer
    {
    public:
      Repairer(Surface &s, const std::string &filename);

      /**
       * Triangles with a repeated vertex; duplicates (the same three
       * vertices). Two copies facing opposite ways are a fin: both go.
       */
      void
      drop_bad_triangles();

      /** Edges and their triangles. More than two: not a manifold. */
      void
      find_edges();

      /**
       * Shells (connected over edges), oriented consistently by a
       * breadth-first walk: a neighbour must run the shared edge the other
       * way round.
       */
      void
      orient_shells();

      /**
       * Holes: loops of boundary edges (one triangle). Small ones are
       * closed by a fan around their centroid; a large one means the
       * surface is open, which no repair can decide how to close.
       */
      void
      fill_holes(const unsigned int max_hole_edges);

      /**
       * Shells: keep the largest body; remove shells of almost no volume
       * (segmentation specks, zero-volume leftovers); refuse a second body.
       */
      void
      keep_largest_shell();

      /** Vertices no triangle uses. */
      void
      drop_unused_vertices();

      Surface      &s;
      SurfaceRepair r;
      /** The body's size (before any repair). */
      const double size;

    private:
      /** The error that refuses the surface. */
      InputError
      refuse(const std::string &problem, const std::string &fix) const;

      const std::string                                           &filename;
      std::unordered_map<std::uint64_t, std::vector<unsigned int>> edges;
      std::vector<int>                                             shell;
      int                                                          n_shells = 0;
    };



    Repairer::Repairer(Surface &s, const std::string &filename)
      : s(s)
      , size(s.diameter())
      , filename(filename)
    {}



    InputError
    Repairer::refuse(const std::string &problem, const std::string &fix) const
    {
      return InputError(filename, 0, "surface", problem, fix);
    }



    void
    Repairer::drop_bad_triangles()
    {
      std::map<std::array<unsigned int, 3>, std::vector<unsigned int>> seen;
      std::vector<Triangle>                                            kept;
      for (const auto &t : s.triangles)
        {
          if (t[0] == t[1] || t[1] == t[2] || t[0] == t[2])
            {
              ++r.degenerate_triangles;
              continue;
            }
          auto key = t;
          std::sort(key.begin(), key.end());
          seen[key].push_back(kept.size());
          kept.push_back(t);
        }
      std::vector<bool> drop(kept.size(), false);
      for (const auto &[key, copies] : seen)
        if (copies.size() > 1)
          {
            for (std::size_t k = 1; k < copies.size(); ++k)
              drop[copies[k]] = true;
            r.duplicate_triangles += copies.size() - 1;
          }
      s.triangles.clear();
      for (std::size_t t = 0; t < kept.size(); ++t)
        if (!drop[t])
          s.triangles.push_back(kept[t]);
    }



    void
    Repairer::find_edges()
    {
      for (unsigned int t = 0; t < s.triangles.size(); ++t)
        for (unsigned int k = 0; k < 3; ++k)
          edges[edge_key(s.triangles[t][k], s.triangles[t][(k + 1) % 3])]
            .push_back(t);
      {
        unsigned int bad = 0;
        Point3       where{{0, 0, 0}};
        for (const auto &[key, tris] : edges)
          if (tris.size() > 2)
            {
              if (bad++ == 0)
                where = s.vertices[key >> 32];
            }
        if (bad > 0)
          throw refuse(std::to_string(bad) +
                         " edges are shared by more than two triangles (the "
                         "first at " +
                         at(where) +
                         "): the surface is not the boundary of one solid",
                       "export a single closed surface of the organ (in 3D "
                       "Slicer: one segment, 'Export to files' as STL or OBJ; "
                       "in MeshLab: Filters > Cleaning and Repairing > Remove "
                       "Non Manifold Edges).");
      }
    }



    void
    Repairer::orient_shells()
    {
      shell.assign(s.triangles.size(), -1);
      std::vector<bool> turned(s.triangles.size(), false);
      for (unsigned int seed = 0; seed < s.triangles.size(); ++seed)
        if (shell[seed] < 0)
          {
            std::vector<unsigned int> members{seed};
            std::queue<unsigned int>  queue;
            queue.push(seed);
            shell[seed] = n_shells;
            while (!queue.empty())
              {
                const unsigned int t = queue.front();
                queue.pop();
                for (unsigned int k = 0; k < 3; ++k)
                  {
                    const unsigned int a = s.triangles[t][k],
                                       b = s.triangles[t][(k + 1) % 3];
                    for (const unsigned int n : edges[edge_key(a, b)])
                      if (n != t)
                        {
                          // Does n run a -> b too (then it disagrees)?
                          bool same = false;
                          for (unsigned int j = 0; j < 3; ++j)
                            same = same || (s.triangles[n][j] == a &&
                                            s.triangles[n][(j + 1) % 3] == b);
                          if (shell[n] < 0)
                            {
                              if (same)
                                {
                                  std::swap(s.triangles[n][1],
                                            s.triangles[n][2]);
                                  turned[n] = true;
                                }
                              shell[n] = n_shells;
                              members.push_back(n);
                              queue.push(n);
                            }
                          else if (same)
                            throw refuse(
                              "the surface cannot be oriented (a Moebius-like "
                              "twist near " +
                                at(s.vertices[a]) + ")",
                              "export the organ's closed surface again.");
                        }
                  }
              }
            // The walk followed the seed's orientation; the majority's is the
            // file's: if most were turned, turn the whole shell back.
            unsigned int n_turned = 0;
            for (const unsigned int t : members)
              n_turned += turned[t];
            if (2 * n_turned > members.size())
              {
                for (const unsigned int t : members)
                  std::swap(s.triangles[t][1], s.triangles[t][2]);
                n_turned = members.size() - n_turned;
              }
            r.reoriented_triangles += n_turned;
            ++n_shells;
          }
    }



    void
    Repairer::fill_holes(const unsigned int max_hole_edges)
    {
      std::map<unsigned int, unsigned int> next; // boundary a -> b
      for (const auto &[key, tris] : edges)
        if (tris.size() == 1)
          {
            const auto &t = s.triangles[tris[0]];
            for (unsigned int k = 0; k < 3; ++k)
              if (edge_key(t[k], t[(k + 1) % 3]) == key)
                next[t[(k + 1) % 3]] = t[k]; // the hole runs the other way
          }
      std::set<unsigned int> done;
      for (const auto &[start, unused] : next)
        {
          if (done.count(start) > 0)
            continue;
          std::vector<unsigned int> loop;
          unsigned int              v = start;
          while (done.count(v) == 0 && next.count(v) > 0)
            {
              done.insert(v);
              loop.push_back(v);
              v = next[v];
            }
          double perimeter = 0;
          Point3 centre{{0, 0, 0}};
          for (std::size_t k = 0; k < loop.size(); ++k)
            {
              perimeter +=
                Utilities::distance(s.vertices[loop[k]],
                                    s.vertices[loop[(k + 1) % loop.size()]]);
              for (unsigned int d = 0; d < 3; ++d)
                centre[d] += s.vertices[loop[k]][d] / loop.size();
            }
          if (v != start || loop.size() < 3 || loop.size() > max_hole_edges ||
              perimeter > 0.25 * size)
            throw refuse(
              "the surface is open: a hole with " +
                std::to_string(loop.size()) + " boundary edges and " +
                Utilities::to_string(perimeter * 1000, 3) + " mm of rim at " +
                at(centre) + " (palpate closes holes of up to " +
                std::to_string(max_hole_edges) +
                " edges and a rim of a quarter of the body's "
                "size itself)",
              "close the surface in your segmentation tool (3D Slicer: "
              "Segment Editor > Smoothing > Closing, or export the segment "
              "as a closed surface; MeshLab: Filters > Remeshing > Close "
              "Holes).");
          const unsigned int c = s.vertices.size();
          s.vertices.push_back(centre);
          const int sh = shell[edges[edge_key(loop[0], loop[1])][0]];
          for (std::size_t k = 0; k < loop.size(); ++k)
            {
              s.triangles.push_back(
                {{loop[k], loop[(k + 1) % loop.size()], c}});
              shell.push_back(sh);
            }
          ++r.filled_holes;
          r.fill_triangles += loop.size();
        }
    }



    void
    Repairer::keep_largest_shell()
    {
      std::vector<std::vector<unsigned int>> members(n_shells);
      for (unsigned int t = 0; t < s.triangles.size(); ++t)
        members[shell[t]].push_back(t);
      std::vector<double> volume(n_shells);
      int                 largest = 0;
      for (int k = 0; k < n_shells; ++k)
        {
          volume[k] = signed_volume(s, members[k]);
          if (std::abs(volume[k]) > std::abs(volume[largest]))
            largest = k;
        }
      std::vector<bool> keep_triangle(s.triangles.size(), true);
      for (int k = 0; k < n_shells; ++k)
        if (k != largest)
          {
            if (std::abs(volume[k]) > 0.01 * std::abs(volume[largest]))
              throw refuse(
                "the file holds " + std::to_string(n_shells) +
                  " separate surfaces, and two are bodies of comparable size (" +
                  Utilities::to_string(std::abs(volume[largest]) * 1e6, 3) +
                  " and " + Utilities::to_string(std::abs(volume[k]) * 1e6, 3) +
                  " cm^3)",
                "palpate meshes one organ: export its segment alone.");
            ++r.removed_shells;
            r.removed_triangles += members[k].size();
            r.removed_volume += std::abs(volume[k]);
            for (const unsigned int t : members[k])
              keep_triangle[t] = false;
          }
      {
        std::vector<Triangle> kept;
        for (unsigned int t = 0; t < s.triangles.size(); ++t)
          if (keep_triangle[t])
            kept.push_back(s.triangles[t]);
        s.triangles = kept;
      }
      if (volume[largest] < 0)
        {
          for (auto &t : s.triangles)
            std::swap(t[1], t[2]);
          r.turned_outward = true;
        }
    }



    void
    Repairer::drop_unused_vertices()
    {
      std::vector<int>    map(s.vertices.size(), -1);
      std::vector<Point3> kept;
      for (auto &t : s.triangles)
        for (auto &v : t)
          {
            if (map[v] < 0)
              {
                map[v] = kept.size();
                kept.push_back(s.vertices[v]);
              }
            v = map[v];
          }
      r.unused_vertices = s.vertices.size() - kept.size();
      s.vertices        = kept;
    }
  } // namespace



  SurfaceRepair
  repair_surface(Surface           &s,
                 const std::string &filename,
                 const unsigned int max_hole_edges)
  {
    Repairer repair(s, filename);
    // Coincident vertices (to 1e-7 of the body's size: far below any
    // segmentation's resolution, far above float round-off).
    repair.r.merged_vertices = merge_vertices(s, 1e-7 * repair.size);
    repair.drop_bad_triangles();
    repair.find_edges();
    repair.orient_shells();
    repair.fill_holes(max_hole_edges);
    repair.keep_largest_shell();
    repair.drop_unused_vertices();
    return repair.r;
  }



  namespace
  {
    /** Whether the segment p-q crosses the triangle a, b, c. */
    bool
    segment_crosses(const Point3 &p,
                    const Point3 &q,
                    const Point3 &a,
                    const Point3 &b,
                    const Point3 &c)
    {
      using namespace Utilities;
      const Point3 n  = cross(minus(b, a), minus(c, a));
      const double dp = dot(n, minus(p, a)), dq = dot(n, minus(q, a));
      if ((dp > 0 && dq > 0) || (dp < 0 && dq < 0) || dp == dq)
        return false;
      const double t = dp / (dp - dq);
      Point3       x;
      for (unsigned int d = 0; d < 3; ++d)
        x[d] = p[d] + t * (q[d] - p[d]);
      const double s1 = dot(n, cross(minus(b, a), minus(x, a)));
      const double s2 = dot(n, cross(minus(c, b), minus(x, b)));
      const double s3 = dot(n, cross(minus(a, c), minus(x, c)));
      return (s1 > 0 && s2 > 0 && s3 > 0) || (s1 < 0 && s2 < 0 && s3 < 0);
    }
  } // namespace



  unsigned int
  count_self_intersections(const Surface &s, Point3 &where)
  {
    if (s.triangles.empty())
      return 0;
    // Uniform grid of cells about twice the mean edge length.
    double mean = 0;
    for (const auto &t : s.triangles)
      mean += Utilities::distance(s.vertices[t[0]], s.vertices[t[1]]);
    mean /= s.triangles.size();
    const auto   box  = s.bounding_box();
    const double cell = std::max(2 * mean, 1e-12);
    std::unordered_map<std::uint64_t, std::vector<unsigned int>> grid;
    const auto index = [&](const double x, const unsigned int d) {
      return static_cast<std::uint64_t>(std::floor((x - box[0][d]) / cell));
    };
    for (unsigned int t = 0; t < s.triangles.size(); ++t)
      {
        std::array<std::uint64_t, 3> lo, hi;
        for (unsigned int d = 0; d < 3; ++d)
          {
            double a = s.vertices[s.triangles[t][0]][d], b = a;
            for (const unsigned int v : s.triangles[t])
              a = std::min(a, s.vertices[v][d]),
              b = std::max(b, s.vertices[v][d]);
            lo[d] = index(a, d), hi[d] = index(b, d);
          }
        for (auto i = lo[0]; i <= hi[0]; ++i)
          for (auto j = lo[1]; j <= hi[1]; ++j)
            for (auto k = lo[2]; k <= hi[2]; ++k)
              grid[(i << 42) | (j << 21) | k].push_back(t);
      }
    std::set<std::pair<unsigned int, unsigned int>> pairs;
    for (const auto &[key, tris] : grid)
      for (std::size_t i = 0; i < tris.size(); ++i)
        for (std::size_t j = i + 1; j < tris.size(); ++j)
          {
            const auto &A = s.triangles[tris[i]], &B = s.triangles[tris[j]];
            bool        shared = false;
            for (const unsigned int a : A)
              for (const unsigned int b : B)
                shared = shared || a == b;
            if (shared)
              continue;
            const auto pair = std::minmax(tris[i], tris[j]);
            if (pairs.count(pair) > 0)
              continue;
            bool cross = false;
            for (unsigned int k = 0; k < 3 && !cross; ++k)
              cross = segment_crosses(s.vertices[A[k]],
                                      s.vertices[A[(k + 1) % 3]],
                                      s.vertices[B[0]],
                                      s.vertices[B[1]],
                                      s.vertices[B[2]]) ||
                      segment_crosses(s.vertices[B[k]],
                                      s.vertices[B[(k + 1) % 3]],
                                      s.vertices[A[0]],
                                      s.vertices[A[1]],
                                      s.vertices[A[2]]);
            if (cross)
              {
                if (pairs.empty())
                  for (unsigned int d = 0; d < 3; ++d)
                    where[d] = (s.vertices[A[0]][d] + s.vertices[A[1]][d] +
                                s.vertices[A[2]][d]) /
                               3;
                pairs.insert(pair);
              }
          }
    return pairs.size();
  }
} // namespace palpate
