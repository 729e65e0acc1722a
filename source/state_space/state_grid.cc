// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

#include <palpate/state_space/state_grid.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <utility>

namespace palpate
{
  StateGrid::StateGrid(const double spacing, const double extent)
    : h(spacing)
    , n(static_cast<int>(std::floor(extent / spacing + 1e-9)))
    , side(2 * n + 1)
  {
    if (!(spacing > 0) || n < 1)
      throw std::invalid_argument(
        "a state grid needs a positive spacing and at "
        "least one cell per half-axis");
  }



  bool
  StateGrid::contains(const GridIndex &g) const noexcept
  {
    return std::abs(g[0]) <= n && std::abs(g[1]) <= n && std::abs(g[2]) <= n;
  }



  unsigned int
  StateGrid::linear(const GridIndex &g) const noexcept
  {
    return ((g[2] + n) * side + (g[1] + n)) * side + (g[0] + n);
  }



  GridIndex
  StateGrid::index(const unsigned int p) const noexcept
  {
    return {{static_cast<int>(p % side) - n,
             static_cast<int>((p / side) % side) - n,
             static_cast<int>(p / (side * side)) - n}};
  }



  Utilities::Point3
  StateGrid::position(const GridIndex &g) const noexcept
  {
    return {{h * g[0], h * g[1], h * g[2]}};
  }



  Utilities::Point3
  StateGrid::position(const unsigned int p) const noexcept
  {
    return position(index(p));
  }



  bool
  StateGrid::behind(const unsigned int source,
                    const unsigned int target,
                    unsigned int      &point) const noexcept
  {
    const GridIndex s = index(source), t = index(target);
    GridIndex       b;
    for (unsigned int d = 0; d < 3; ++d)
      b[d] = 2 * s[d] - t[d];
    if (!contains(b))
      return false;
    point = linear(b);
    return true;
  }



  GridIndex
  StateGrid::nearest(const Utilities::Point3 &x) const noexcept
  {
    GridIndex g;
    for (unsigned int d = 0; d < 3; ++d)
      {
        const double v = std::isfinite(x[d]) ? std::round(x[d] / h) : 0.0;
        g[d]           = static_cast<int>(std::clamp(v, double(-n), double(n)));
      }
    return g;
  }



  bool
  StateGrid::locate(const Utilities::Point3 &x,
                    GridIndex               &lower,
                    std::array<double, 3>   &local) const noexcept
  {
    for (unsigned int d = 0; d < 3; ++d)
      {
        if (!std::isfinite(x[d]))
          return false;
        const double s = x[d] / h;
        if (s < -n || s > n)
          return false;
        // The upper boundary belongs to the last cell.
        const int i = std::min(static_cast<int>(std::floor(s)), n - 1);
        lower[d]    = i;
        local[d]    = s - i;
      }
    return true;
  }



  std::array<unsigned int, 8>
  StateGrid::corners(const GridIndex &lower) const noexcept
  {
    std::array<unsigned int, 8> c;
    for (unsigned int k = 0; k < 8; ++k)
      c[k] = linear({{lower[0] + int(k & 1),
                      lower[1] + int((k >> 1) & 1),
                      lower[2] + int((k >> 2) & 1)}});
    return c;
  }



  std::array<unsigned int, 4>
  simplex_corners(const std::array<double, 3> &s) noexcept
  {
    // The axes by decreasing coordinate: the tetrahedron from corner 0
    // through one more upper bit per axis in that order to corner 7.
    std::array<unsigned int, 3> axis = {{0, 1, 2}};
    if (s[axis[0]] < s[axis[1]])
      std::swap(axis[0], axis[1]);
    if (s[axis[1]] < s[axis[2]])
      std::swap(axis[1], axis[2]);
    if (s[axis[0]] < s[axis[1]])
      std::swap(axis[0], axis[1]);
    std::array<unsigned int, 4> path = {{0, 0, 0, 7}};
    path[1]                          = 1u << axis[0];
    path[2]                          = path[1] | (1u << axis[1]);
    return path;
  }



  std::array<double, 8>
  simplex_weights(const std::array<double, 3> &s) noexcept
  {
    // Along the path, corner k has the weight s of the axis it steps from
    // less the s of the axis the next corner steps along.
    const auto            path = simplex_corners(s);
    std::array<double, 8> w{};
    double                above = 1;
    for (unsigned int k = 0; k < 3; ++k)
      {
        const unsigned int axis = __builtin_ctz(path[k + 1] ^ path[k]);
        w[path[k]] += above - s[axis];
        above = s[axis];
      }
    w[7] += above;
    return w;
  }



  std::array<double, 8>
  trilinear_weights(const std::array<double, 3> &s) noexcept
  {
    std::array<double, 8> w;
    for (unsigned int k = 0; k < 8; ++k)
      w[k] = ((k & 1) ? s[0] : 1 - s[0]) * (((k >> 1) & 1) ? s[1] : 1 - s[1]) *
             (((k >> 2) & 1) ? s[2] : 1 - s[2]);
    return w;
  }
  bool
  StateGrid::beside_origin(const unsigned int point) const noexcept
  {
    const GridIndex g = index(point);
    return std::abs(g[0]) <= 1 && std::abs(g[1]) <= 1 && std::abs(g[2]) <= 1 &&
           (g[0] != 0 || g[1] != 0 || g[2] != 0);
  }



  std::vector<unsigned int>
  StateGrid::neighbourhood(const unsigned int point) const
  {
    const GridIndex           g = index(point);
    std::vector<unsigned int> points;
    for (int i = -1; i <= 1; ++i)
      for (int j = -1; j <= 1; ++j)
        for (int k = -1; k <= 1; ++k)
          {
            const GridIndex n = {{g[0] + i, g[1] + j, g[2] + k}};
            if (contains(n))
              points.push_back(linear(n));
          }
    return points;
  }
} // namespace palpate
