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
      sample.force = sum;
    return sample;
  }



  double
  directional_stiffness(const ForceSample       &s,
                        const double             h,
                        const Utilities::Point3 &n) noexcept
  {
    // d f_i / d x_j of the trilinear interpolation: corner k has the bits
    // (x, y, z) = (k & 1, k >> 1 & 1, k >> 2 & 1).
    double n_J_n = 0;
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
                dw *= upper ? s.local[e] : 1.0 - s.local[e];
            }
          double n_f = 0;
          for (unsigned int i = 0; i < 3; ++i)
            n_f += n[i] * s.corner_forces[k][i];
          n_J_n += n_f * dw / h * n[j];
        }
    return -n_J_n;
  }
} // namespace palpate
