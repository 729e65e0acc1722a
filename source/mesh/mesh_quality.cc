// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

#include <palpate/mesh/mesh_quality.h>

#include <algorithm>
#include <cmath>

namespace palpate
{
  std::string
  MeshQuality::summary() const
  {
    return "radius ratio min " + Utilities::to_string(min_radius_ratio, 3) +
           ", mean " + Utilities::to_string(mean_radius_ratio, 3) +
           "; dihedral angles " +
           Utilities::to_string(min_dihedral_degrees, 3) + " - " +
           Utilities::to_string(max_dihedral_degrees, 4) + " degrees; " +
           std::to_string(slivers.size()) + " slivers";
  }



  MeshQuality
  mesh_quality(const std::vector<Utilities::Point3>           &x,
               const std::vector<std::array<unsigned int, 4>> &cells)
  {
    using namespace Utilities;
    MeshQuality q;
    if (cells.empty())
      return q;
    double sum = 0;
    for (unsigned int c = 0; c < cells.size(); ++c)
      {
        const auto  &t = cells[c];
        const Point3 a = minus(x[t[1]], x[t[0]]), b = minus(x[t[2]], x[t[0]]),
                     d      = minus(x[t[3]], x[t[0]]);
        const double volume = std::abs(dot(a, cross(b, d))) / 6;
        // Outward face normals (face k is opposite vertex k), scaled by
        // twice the face area.
        std::array<Point3, 4> n;
        double                area = 0;
        for (unsigned int k = 0; k < 4; ++k)
          {
            const auto &p = x[t[(k + 1) % 4]], &q1 = x[t[(k + 2) % 4]],
                       &r = x[t[(k + 3) % 4]];
            n[k]          = cross(minus(q1, p), minus(r, p));
            if (dot(n[k], minus(x[t[k]], p)) > 0) // point away from vertex k
              n[k] = scaled(n[k], -1);
            area += 0.5 * norm(n[k]);
          }
        // Radius ratio: r_in = 3 V / A; the circumradius from the edge
        // vectors, R = |a^2 (b x d) + b^2 (d x a) + d^2 (a x b)| / (12 V).
        Point3 w{{0, 0, 0}};
        for (unsigned int i = 0; i < 3; ++i)
          w[i] = dot(a, a) * cross(b, d)[i] + dot(b, b) * cross(d, a)[i] +
                 dot(d, d) * cross(a, b)[i];
        const double r_in   = 3 * volume / area;
        const double r_circ = norm(w) / (12 * volume);
        const double ratio =
          volume > 0 && std::isfinite(r_circ) ? 3 * r_in / r_circ : 0;
        q.min_radius_ratio = std::min(q.min_radius_ratio, ratio);
        sum += ratio;
        // Dihedral angle at the edge shared by faces k and l: pi minus the
        // angle between their outward normals.
        double lo = 180, hi = 0;
        for (unsigned int k = 0; k < 4; ++k)
          for (unsigned int l = k + 1; l < 4; ++l)
            {
              const double cosine =
                std::clamp(dot(n[k], n[l]) / (norm(n[k]) * norm(n[l])),
                           -1.0,
                           1.0);
              const double angle = 180 - std::acos(cosine) * 180 / M_PI;
              lo                 = std::min(lo, angle);
              hi                 = std::max(hi, angle);
            }
        q.min_dihedral_degrees = std::min(q.min_dihedral_degrees, lo);
        q.max_dihedral_degrees = std::max(q.max_dihedral_degrees, hi);
        if (lo < 5 || hi > 170 || ratio < 0.1)
          q.slivers.push_back(c);
      }
    q.mean_radius_ratio = sum / cells.size();
    return q;
  }
} // namespace palpate
