// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

#include <palpate/haptics/force_interpolation.h>
#include <palpate/state_space/state_cache.h>
#include <palpate/state_space/state_grid.h>

namespace palpate
{
  namespace
  {
    /** Locate @p x: inside, local coordinates and corners of @p sample;
     * false outside the grid. */
    bool
    locate(const StateGrid         &grid,
           const Utilities::Point3 &x,
           ForceSample             &sample) noexcept
    {
      GridIndex lower;
      if (!grid.locate(x, lower, sample.local))
        return false;
      sample.inside  = true;
      sample.corners = grid.corners(lower);
      return true;
    }

    /** Count the failure points among the corners of an incomplete
     * sample (bounded lock-free reads). */
    void
    count_failures(const StateCache &cache, ForceSample &sample) noexcept
    {
      for (unsigned int k = 0; k < 8; ++k)
        sample.failed += cache.status(sample.corners[k]) == PointStatus::failed;
    }

    /** The trilinear force and its stiffness K_ij = -df_i/dx_j from the
     * corner forces of a complete sample. */
    void
    trilinear(ForceSample &sample, const double h) noexcept
    {
      const auto &local = sample.local;
      const auto  w     = trilinear_weights(local);
      sample.force      = {{0, 0, 0}};
      sample.stiffness  = {};
      for (unsigned int k = 0; k < 8; ++k)
        for (unsigned int i = 0; i < 3; ++i)
          sample.force[i] += w[k] * sample.corner_forces[k][i];
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
                sample.corner_forces[k][i] * dw / h;
          }
    }
  } // namespace



  ForceSample
  interpolate_force(const StateGrid         &grid,
                    const StateCache        &cache,
                    const Utilities::Point3 &x) noexcept
  {
    ForceSample sample;
    if (!locate(grid, x, sample))
      return sample;
    const std::uint64_t generation = cache.generation();
    for (unsigned int k = 0; k < 8; ++k)
      if (cache.read_force(sample.corners[k],
                           generation,
                           sample.corner_forces[k]))
        ++sample.hits;
    sample.complete = sample.hits == 8;
    if (sample.complete)
      trilinear(sample, grid.spacing());
    else
      count_failures(cache, sample);
    return sample;
  }



  ForceSample
  interpolate_on_tetrahedron(const StateGrid         &grid,
                             const StateCache        &cache,
                             const Utilities::Point3 &x) noexcept
  {
    ForceSample sample;
    if (!locate(grid, x, sample))
      return sample;
    // Only the corners of the tetrahedron holding x are read: the cell's
    // others may still be on their way.
    const auto          path       = simplex_corners(sample.local);
    const std::uint64_t generation = cache.generation();
    sample.read                    = 0;
    for (const unsigned int k : path)
      sample.read |= 1u << k;
    for (const unsigned int k : path)
      if (cache.read_force(sample.corners[k],
                           generation,
                           sample.corner_forces[k]))
        ++sample.hits;
      else
        sample.failed += cache.status(sample.corners[k]) == PointStatus::failed;
    sample.complete = sample.hits == 4;
    if (!sample.complete)
      return sample;
    sample.failed = 0;
    // The force linear on the tetrahedron; along its path each step of one
    // axis changes it by the difference of the two corners.
    const auto w = simplex_weights(sample.local);
    sample.force = {{0, 0, 0}};
    for (const unsigned int k : path)
      for (unsigned int i = 0; i < 3; ++i)
        sample.force[i] += w[k] * sample.corner_forces[k][i];
    sample.stiffness = {};
    for (unsigned int k = 0; k < 3; ++k)
      {
        const unsigned int j = __builtin_ctz(path[k + 1] ^ path[k]);
        for (unsigned int i = 0; i < 3; ++i)
          sample.stiffness[3 * i + j] = -(sample.corner_forces[path[k + 1]][i] -
                                          sample.corner_forces[path[k]][i]) /
                                        grid.spacing();
      }
    return sample;
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
  interpolate_hermite(const StateGrid         &grid,
                      const StateCache        &cache,
                      const Utilities::Point3 &x) noexcept
  {
    ForceSample sample;
    if (!locate(grid, x, sample))
      return sample;
    const std::uint64_t generation = cache.generation();
    const double        h          = grid.spacing();
    // D[c][m][i]: derivative m (bits x, y, z: which directions) of force
    // component i at corner c, in the cell's unit coordinates (so scaled
    // by h per derivative). One read per corner: force and stiffness
    // under its sequence lock, then the cross derivatives under theirs.
    double D[8][8][3];
    bool   all_stiffness = true;
    for (unsigned int c = 0; c < 8; ++c)
      {
        Utilities::Point3     &f = sample.corner_forces[c];
        std::array<double, 9>  K;
        std::array<double, 12> cross;
        bool                   has = false;
        if (!cache.read_force_and_stiffness(
              sample.corners[c], generation, f, K, has))
          continue;
        ++sample.hits;
        if (!has || !cache.read_cross_derivatives(sample.corners[c], cross))
          {
            all_stiffness = false;
            continue;
          }
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
    sample.complete = sample.hits == 8;
    if (!sample.complete)
      {
        count_failures(cache, sample);
        return sample;
      }
    if (!all_stiffness)
      {
        // A corner without its stiffness: trilinear in this cell.
        trilinear(sample, h);
        return sample;
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
