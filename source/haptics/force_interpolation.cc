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

    const std::uint64_t generation = cache.generation();
    const double        h          = grid.spacing();
    // D[c][m][i]: derivative m (bits x, y, z: which directions) of force
    // component i at corner c, in the cell's unit coordinates (so scaled
    // by h per derivative).
    double D[8][8][3];
    for (unsigned int c = 0; c < 8; ++c)
      {
        Utilities::Point3      f;
        std::array<double, 9>  K;
        std::array<double, 12> cross;
        bool                   has = false;
        if (!cache.read_force_and_stiffness(
              sample.corners[c], generation, f, K, has) ||
            !has || !cache.read_cross_derivatives(sample.corners[c], cross))
          return sample; // trilinear this tick
        sample.corner_forces[c] = f;
        for (unsigned int i = 0; i < 3; ++i)
          {
            D[c][0][i] = f[i];
            D[c][1][i] = -h * K[3 * i + 0];
            D[c][2][i] = -h * K[3 * i + 1];
            D[c][4][i] = -h * K[3 * i + 2];
            D[c][3][i] = h * h * cross[4 * i + 0]; // xy
            D[c][5][i] = h * h * cross[4 * i + 1]; // xz
            D[c][6][i] = h * h * cross[4 * i + 2]; // yz
            D[c][7][i] = h * h * h * cross[4 * i + 3];
          }
      }

    const auto        &local = sample.local;
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
