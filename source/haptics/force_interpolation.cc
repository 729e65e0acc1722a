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
            for (unsigned int d = 0; d < 3; ++d)
              sum[d] += w[k] * f[d];
          }
      }
    sample.complete = sample.hits == 8;
    if (sample.complete)
      sample.force = sum;
    return sample;
  }
} // namespace palpate
