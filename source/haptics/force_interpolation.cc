// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

#include <palpate/haptics/force_interpolation.h>
#include <palpate/state_space/state_cache.h>
#include <palpate/state_space/state_grid.h>

namespace palpate
{
  ForceSample
  interpolate_force(const StateGrid         &grid,
                    const StateCache        &cache,
                    const Utilities::Point3 &x) noexcept
  {
    ForceSample           sample;
    GridIndex             lower;
    std::array<double, 3> local;
    if (!grid.locate(x, lower, local))
      return sample;
    sample.inside         = true;
    sample.local          = local;
    sample.corners        = grid.corners(lower);
    const auto          w = trilinear_weights(local);
    Utilities::Point3   sum{{0, 0, 0}};
    const std::uint64_t generation = cache.generation();
    for (unsigned int k = 0; k < 8; ++k)
      {
        Utilities::Point3 f;
        if (cache.read_force(sample.corners[k], generation, f))
          {
            ++sample.hits;
            sample.corner_forces[k] = f;
            for (unsigned int d = 0; d < 3; ++d)
              sum[d] += w[k] * f[d];
          }
      }
    sample.complete = sample.hits == 8;
    // Why not: a failure point among the corners (bounded lock-free reads).
    if (!sample.complete)
      for (unsigned int k = 0; k < 8; ++k)
        sample.failed += cache.status(sample.corners[k]) == PointStatus::failed;
    if (sample.complete)
      {
        sample.force = sum;
        // K_ij = -df_i/dx_j of the trilinear field.
        for (unsigned int k = 0; k < 8; ++k)
          for (unsigned int j = 0; j < 3; ++j)
            {
              double dw = 1;
              for (unsigned int e = 0; e < 3; ++e)
                {
                  const bool upper = (k >> e) & 1;
                  if (e == j)
                    dw *= upper ? 1.0 : -1.0;
                  else
                    dw *= upper ? local[e] : 1.0 - local[e];
                }
              for (unsigned int i = 0; i < 3; ++i)
                sample.stiffness[3 * i + j] -=
                  sample.corner_forces[k][i] * dw / grid.spacing();
            }
      }
    return sample;
  }



  Interpolation
  interpolation_from_name(const std::string &name)
  {
    return name == "tricubic Hermite" ? Interpolation::hermite :
                                        Interpolation::trilinear;
  }



  namespace
  {
    /** The 1-D cubic Hermite basis on [0, 1] and its derivative:
     * [bit][order] for the value (order 0) or slope (order 1) at end bit. */
    struct HermiteBasis
    {
      double value[2][2], slope[2][2];

      explicit HermiteBasis(const double t) noexcept
      {
        const double t2 = t * t, t3 = t2 * t;
        value[0][0] = 2 * t3 - 3 * t2 + 1;
        value[0][1] = t3 - 2 * t2 + t;
        value[1][0] = -2 * t3 + 3 * t2;
        value[1][1] = t3 - t2;
        slope[0][0] = 6 * t2 - 6 * t;
        slope[0][1] = 3 * t2 - 4 * t + 1;
        slope[1][0] = -6 * t2 + 6 * t;
        slope[1][1] = 3 * t2 - 2 * t;
      }
    };

    /** The grid points around a cell, as the Hermite interpolation reads
     * them: block offsets -1..2 along each axis. */
    struct Block
    {
      bool                  available[4][4][4];
      std::array<double, 9> stiffness[4][4][4];
      Utilities::Point3     force[4][4][4];
    };
  } // namespace



  ForceSample
  interpolate_force(const StateGrid         &grid,
                    const StateCache        &cache,
                    const Utilities::Point3 &x,
                    const Interpolation      scheme) noexcept
  {
    ForceSample sample = interpolate_force(grid, cache, x);
    if (scheme != Interpolation::hermite || !sample.complete)
      return sample;

    GridIndex             lower;
    std::array<double, 3> local;
    grid.locate(x, lower, local);
    const std::uint64_t generation = cache.generation();
    Block               b;
    for (int i = 0; i < 4; ++i)
      for (int j = 0; j < 4; ++j)
        for (int k = 0; k < 4; ++k)
          {
            // The block's 8 outer corners are never used.
            const bool outer  = (i % 3 == 0) && (j % 3 == 0) && (k % 3 == 0);
            const GridIndex g = {
              {lower[0] + i - 1, lower[1] + j - 1, lower[2] + k - 1}};
            bool has = false;
            b.available[i][j][k] =
              !outer && grid.contains(g) &&
              cache.read_force_and_stiffness(grid.linear(g),
                                             generation,
                                             b.force[i][j][k],
                                             b.stiffness[i][j][k],
                                             has) &&
              has;
          }
    // Every corner must have its stiffness (a corner's force may also
    // have been rewritten since the trilinear read: use the block's).
    for (unsigned int c = 0; c < 8; ++c)
      if (!b.available[1 + (c & 1)][1 + ((c >> 1) & 1)][1 + ((c >> 2) & 1)])
        return sample;

    const double h = grid.spacing();
    // D[c][m][i]: derivative m (bits x, y, z: which directions) of force
    // component i at corner c, in the cell's unit coordinates.
    double D[8][8][3];
    for (unsigned int c = 0; c < 8; ++c)
      {
        const int  o[3] = {1 + int(c & 1),
                           1 + int((c >> 1) & 1),
                           1 + int((c >> 2) & 1)};
        const auto at   = [&](const int dx, const int dy, const int dz) {
          return b.available[o[0] + dx][o[1] + dy][o[2] + dz];
        };
        const auto K = [&](const int          dx,
                           const int          dy,
                           const int          dz,
                           const unsigned int i,
                           const unsigned int j) {
          return b.stiffness[o[0] + dx][o[1] + dy][o[2] + dz][3 * i + j];
        };
        const auto shift = [](const unsigned int axis, const int s) {
          std::array<int, 3> d = {{0, 0, 0}};
          d[axis]              = s;
          return d;
        };
        for (unsigned int i = 0; i < 3; ++i)
          {
            D[c][0][i] = b.force[o[0]][o[1]][o[2]][i];
            for (unsigned int a = 0; a < 3; ++a)
              D[c][1u << a][i] = -h * K(0, 0, 0, i, a);
            // Mixed second derivatives: d/db of df/da (= -K_ia), and d/da
            // of df/db, each by a central difference if both neighbours
            // along the other axis are there, one-sided if one is.
            for (unsigned int a = 0; a < 3; ++a)
              for (unsigned int e = a + 1; e < 3; ++e)
                {
                  double       sum = 0;
                  unsigned int n   = 0;
                  for (const auto &[along, of] :
                       {std::pair<unsigned, unsigned>(e, a), {a, e}})
                    {
                      const auto p = shift(along, 1), m = shift(along, -1);
                      const bool up = at(p[0], p[1], p[2]),
                                 dn = at(m[0], m[1], m[2]);
                      // h^2 d/d(along) (-K_i,of).
                      if (up && dn)
                        sum += 0.5 * h *
                               (K(m[0], m[1], m[2], i, of) -
                                K(p[0], p[1], p[2], i, of));
                      else if (up)
                        sum +=
                          h * (K(0, 0, 0, i, of) - K(p[0], p[1], p[2], i, of));
                      else if (dn)
                        sum +=
                          h * (K(m[0], m[1], m[2], i, of) - K(0, 0, 0, i, of));
                      n += up || dn;
                    }
                  D[c][(1u << a) | (1u << e)][i] = n > 0 ? sum / n : 0;
                }
            // d3f/dxdydz: mixed central differences of df/da over the
            // other two axes, averaged over a.
            double       sum = 0;
            unsigned int n   = 0;
            for (unsigned int a = 0; a < 3; ++a)
              {
                const unsigned int e1 = (a + 1) % 3, e2 = (a + 2) % 3;
                double             mixed = 0;
                bool               all   = true;
                for (const int s1 : {-1, 1})
                  for (const int s2 : {-1, 1})
                    {
                      std::array<int, 3> d = {{0, 0, 0}};
                      d[e1]                = s1;
                      d[e2]                = s2;
                      all                  = all && at(d[0], d[1], d[2]);
                      if (all)
                        mixed += s1 * s2 * K(d[0], d[1], d[2], i, a);
                    }
                if (all)
                  {
                    sum += -0.25 * h * mixed;
                    ++n;
                  }
              }
            D[c][7][i] = n > 0 ? sum / n : 0;
          }
      }

    const HermiteBasis bx(local[0]), by(local[1]), bz(local[2]);
    Utilities::Point3  f{{0, 0, 0}};
    double             g[3][3] = {}; // g[i][j] = df_i/du_j
    for (unsigned int c = 0; c < 8; ++c)
      {
        const unsigned int cx = c & 1, cy = (c >> 1) & 1, cz = (c >> 2) & 1;
        for (unsigned int m = 0; m < 8; ++m)
          {
            const unsigned int mx = m & 1, my = (m >> 1) & 1, mz = (m >> 2) & 1;
            const double       vx = bx.value[cx][mx], vy = by.value[cy][my],
                         vz    = bz.value[cz][mz];
            const double w     = vx * vy * vz;
            const double dw[3] = {bx.slope[cx][mx] * vy * vz,
                                  vx * by.slope[cy][my] * vz,
                                  vx * vy * bz.slope[cz][mz]};
            for (unsigned int i = 0; i < 3; ++i)
              {
                f[i] += w * D[c][m][i];
                for (unsigned int j = 0; j < 3; ++j)
                  g[i][j] += dw[j] * D[c][m][i];
              }
          }
      }
    sample.force   = f;
    sample.hermite = true;
    for (unsigned int i = 0; i < 3; ++i)
      for (unsigned int j = 0; j < 3; ++j)
        sample.stiffness[3 * i + j] = -g[i][j] / h;
    for (unsigned int c = 0; c < 8; ++c)
      sample.corner_forces[c] =
        b.force[1 + (c & 1)][1 + ((c >> 1) & 1)][1 + ((c >> 2) & 1)];
    return sample;
  }



  double
  directional_stiffness(const ForceSample       &s,
                        const Utilities::Point3 &n) noexcept
  {
    double n_K_n = 0;
    for (unsigned int i = 0; i < 3; ++i)
      for (unsigned int j = 0; j < 3; ++j)
        n_K_n += n[i] * s.stiffness[3 * i + j] * n[j];
    return n_K_n;
  }
} // namespace palpate
