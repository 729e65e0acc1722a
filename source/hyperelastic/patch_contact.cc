// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

#include <palpate/hyperelastic/contact_lcp.h>
#include <palpate/hyperelastic/contact_patch.h>
#include <palpate/hyperelastic/patch_contact.h>

#include <algorithm>
#include <cmath>

namespace palpate
{
  namespace
  {
    // Gaps below this count as closed: far below any gap the Newton
    // solution leaves (its tolerance is 1e-3 of its increment tolerance),
    // far above the round-off of metres.
    constexpr double gap_tolerance = 1e-12;

    /** Cholesky factor L (lower, in place) of the symmetric m x m A;
     * false if A is not positive definite. */
    bool
    cholesky(double *A, const unsigned int m) noexcept
    {
      for (unsigned int j = 0; j < m; ++j)
        {
          double d = A[j * m + j];
          for (unsigned int k = 0; k < j; ++k)
            d -= A[j * m + k] * A[j * m + k];
          if (!(d > 0))
            return false;
          d            = std::sqrt(d);
          A[j * m + j] = d;
          for (unsigned int i = j + 1; i < m; ++i)
            {
              double v = A[i * m + j];
              for (unsigned int k = 0; k < j; ++k)
                v -= A[i * m + k] * A[j * m + k];
              A[i * m + j] = v / d;
            }
        }
      return true;
    }

    /** Solve L L^T x = b in place of @p b. */
    void
    cholesky_solve(const double *L, const unsigned int m, double *b) noexcept
    {
      for (unsigned int i = 0; i < m; ++i)
        {
          double v = b[i];
          for (unsigned int k = 0; k < i; ++k)
            v -= L[i * m + k] * b[k];
          b[i] = v / L[i * m + i];
        }
      for (int i = int(m) - 1; i >= 0; --i)
        {
          double v = b[i];
          for (unsigned int k = i + 1; k < m; ++k)
            v -= L[k * m + i] * b[k];
          b[i] = v / L[i * m + i];
        }
    }

    /**
     * y += f h over @p M entries: the nodes moved by one column of the
     * compliance, the tick's largest loop (nine per node in contact and
     * node of the patch). Compiled for AVX-512, AVX2 and plain x86-64,
     * chosen when the library is loaded, so that any x86-64 runs it and a
     * recent one at 4-8 doubles an instruction.
     */
#if defined(__x86_64__) && defined(__GNUC__) && !defined(__clang__)
    __attribute__((target_clones("avx512f", "avx2", "default")))
#endif
    void
    add_column(double           *y,
               const float      *h,
               const double      f,
               const std::size_t M) noexcept
    {
      for (std::size_t r = 0; r < M; ++r)
        y[r] += h[r] * f;
    }

    /** y += f w over @p n entries: a row of W (symmetric: a column). */
#if defined(__x86_64__) && defined(__GNUC__) && !defined(__clang__)
    __attribute__((target_clones("avx512f", "avx2", "default")))
#endif
    void
    add_row(double           *y,
            const double     *w,
            const double      f,
            const std::size_t n) noexcept
    {
      for (std::size_t i = 0; i < n; ++i)
        y[i] += w[i] * f;
    }

  } // namespace



  PatchContact::PatchContact(const unsigned int max_nodes,
                             const unsigned int max_active)
    : max_nodes(max_nodes)
    , max_active(std::min(max_active, max_nodes))
    // The 8 corners of the HIP's cell and the 4 a move into the next cell
    // brings: each keeps its warm start while the hand goes back and forth
    // across a face.
    , slots(12)
    , q(max_nodes)
    , gap(max_nodes)
    , w(max_nodes)
    , rhs(3 * this->max_active)
    , rho(max_nodes)
    , u(max_nodes)
    , loaded(max_nodes)
    , left(max_nodes)
    , block_capacity(std::min(this->max_active, 64u))
  {
    for (Slot &s : slots)
      {
        s.lambda.resize(max_nodes);
        s.y.resize(3 * std::size_t(max_nodes));
        s.direction.resize(3 * std::size_t(max_nodes));
        s.block.resize(std::size_t(block_capacity) * block_capacity * 9);
        s.block_nodes.resize(block_capacity);
        s.block_pos.assign(max_nodes, -1);
        s.active.resize(max_nodes);
        s.index.resize(this->max_active);
        s.LU.resize(std::size_t(this->max_active) * this->max_active);
        s.pivot.resize(this->max_active);
      }
  }



  PatchContact::Slot &
  PatchContact::slot_of(const ContactPatch &patch) noexcept
  {
    ++clock;
    Slot *oldest = &slots[0];
    for (Slot &s : slots)
      {
        if (s.patch == &patch && s.id == patch.id)
          {
            s.used = clock;
            return s;
          }
        if (s.used < oldest->used)
          oldest = &s;
      }
    // A patch seen for the first time starts from its state: the solution
    // there, and the nearest guess near it.
    ++work.new_corners;
    Slot &s    = *oldest;
    s.patch    = &patch;
    s.id       = patch.id;
    s.used     = clock;
    s.factored = false;
    forget_blocks(s);
    std::copy(patch.lambda.begin(), patch.lambda.end(), s.lambda.begin());
    std::copy(patch.position.begin(), patch.position.end(), s.y.begin());
    for (unsigned int i = 0; i < patch.size(); ++i)
      s.active[i] = patch.lambda[i] > 0;
    return s;
  }



  bool
  PatchContact::factorize_active(const ContactPatch &patch, Slot &s) noexcept
  {
    const unsigned int n = patch.size();
    unsigned int       m = 0;
    for (unsigned int i = 0; i < n; ++i)
      if (s.active[i])
        {
          if (m == max_active)
            return false;
          s.index[m++] = i;
        }
    assemble_active_block(patch, s, m);
    s.n_active = m;
    ++work.factorizations;
    // W is a compliance, symmetric positive definite at a stable state:
    // Cholesky, half the work of LU. LU where round-off (or an unstable
    // state's tangent) makes the block indefinite.
    s.cholesky = cholesky(s.LU.data(), m);
    if (!s.cholesky)
      {
        assemble_active_block(patch, s, m);
        s.factored = lu_factorize(s.LU.data(), m, s.pivot.data());
      }
    else
      s.factored = true;
    return s.factored;
  }



  void
  PatchContact::assemble_active_block(const ContactPatch &patch,
                                      Slot               &s,
                                      const unsigned int  m) noexcept
  {
    for (unsigned int a = 0; a < m; ++a)
      {
        const unsigned int i = s.index[a];
        for (unsigned int r = 0; r < 3; ++r)
          s.direction[3 * i + r] = u[i][r] / rho[i];
      }
    const bool        from_block = keep_blocks(patch, s, m);
    const std::size_t M          = 3 * std::size_t(patch.size());
    for (unsigned int a = 0; a < m; ++a)
      {
        const unsigned int i  = s.index[a];
        const double      *di = s.direction.data() + 3 * std::size_t(i);
        for (unsigned int b = a; b < m; ++b)
          {
            const unsigned int j  = s.index[b];
            const double      *dj = s.direction.data() + 3 * std::size_t(j);
            double             v  = 0;
            for (unsigned int r = 0; r < 3; ++r)
              {
                const float *h =
                  from_block ? s.block.data() +
                                 (std::size_t(s.block_pos[i]) * block_capacity +
                                  s.block_pos[j]) *
                                   9 +
                                 3 * r :
                               patch.H.data() + (3 * i + r) * M + 3 * j;
                v += di[r] * (h[0] * dj[0] + h[1] * dj[1] + h[2] * dj[2]);
              }
            s.LU[a * m + b] = s.LU[b * m + a] = v;
          }
      }
  }



  bool
  PatchContact::keep_blocks(const ContactPatch &patch,
                            Slot               &s,
                            const unsigned int  m) noexcept
  {
    // H's 3 x 3 blocks on the nodes in contact lie rows of H apart: each
    // tick that the normals turn would gather them through memory again.
    // The slot keeps them side by side for the nodes it has seen in
    // contact, adding those that join, and starts again when full.
    unsigned int missing = 0;
    for (unsigned int a = 0; a < m; ++a)
      missing += s.block_pos[s.index[a]] < 0;
    if (missing == 0)
      return true;
    if (m > block_capacity)
      return false;
    if (s.n_block + missing > block_capacity)
      forget_blocks(s);
    const std::size_t M = 3 * std::size_t(patch.size());
    for (unsigned int a = 0; a < m; ++a)
      {
        const unsigned int i = s.index[a];
        if (s.block_pos[i] >= 0)
          continue;
        const unsigned int p = s.n_block++;
        s.block_pos[i]       = p;
        s.block_nodes[p]     = i;
        for (unsigned int q = 0; q <= p; ++q)
          {
            const unsigned int j = s.block_nodes[q];
            // Both blocks as H holds them (not one the other's transpose):
            // W is then what gathering from H gives, to the bit.
            for (unsigned int r = 0; r < 3; ++r)
              for (unsigned int c = 0; c < 3; ++c)
                {
                  s.block[(std::size_t(p) * block_capacity + q) * 9 + 3 * r +
                          c] = patch.H[(3 * i + r) * M + 3 * j + c];
                  s.block[(std::size_t(q) * block_capacity + p) * 9 + 3 * r +
                          c] = patch.H[(3 * j + r) * M + 3 * i + c];
                }
          }
      }
    return true;
  }



  void
  PatchContact::forget_blocks(Slot &s) noexcept
  {
    for (unsigned int q = 0; q < s.n_block; ++q)
      s.block_pos[s.block_nodes[q]] = -1;
    s.n_block = 0;
  }



  void
  PatchContact::solve_active(const Slot &s, double *b) const noexcept
  {
    if (s.cholesky)
      cholesky_solve(s.LU.data(), s.n_active, b);
    else
      lu_solve(s.LU.data(), s.n_active, s.pivot.data(), b);
  }



  bool
  PatchContact::measure_gaps(const ContactPatch      &patch,
                             const Utilities::Point3 &x,
                             const Slot              &s,
                             unsigned int            &n_loaded) noexcept
  {
    const unsigned int n = patch.size();
    Utilities::Point3  c;
    for (unsigned int a = 0; a < 3; ++a)
      c[a] = patch.center[a] + x[a] - patch.target[a];
    bool touching = false;
    for (unsigned int i = 0; i < n; ++i)
      {
        // u_i from the centre to the node, normalised below only for the
        // few nodes that carry a force: a division per node of the patch
        // is the loop's largest cost.
        double r2 = 0;
        for (unsigned int a = 0; a < 3; ++a)
          {
            u[i][a] = s.y[3 * i + a] - c[a];
            r2 += u[i][a] * u[i][a];
          }
        rho[i]   = std::sqrt(r2);
        gap[i]   = rho[i] - patch.radius + patch.offset[i];
        q[i]     = gap[i];
        touching = touching || q[i] < -gap_tolerance;
        if (s.lambda[i] > 0)
          loaded[n_loaded++] = i;
      }
    return touching;
  }



  bool
  PatchContact::solve_contact(const ContactPatch &patch,
                              Slot               &s,
                              const unsigned int  n_loaded) noexcept
  {
    const unsigned int n = patch.size();
    // The gaps linear in the new forces about the current ones: q = g - W
    // lambda, so that the contact problem is W lambda' + q >= 0 (by rows
    // of W, which is symmetric: contiguous, vectorised).
    for (unsigned int l = 0; l < n_loaded; ++l)
      add_row(q.data(),
              patch.W.data() + std::size_t(loaded[l]) * n,
              -s.lambda[loaded[l]],
              n);
    std::fill(left.begin(), left.begin() + n, 0);
    // The factors are of W along the directions of their time: stale once
    // the sphere's normals at the nodes in contact have turned.
    if (s.factored)
      for (unsigned int a = 0; a < s.n_active && s.factored; ++a)
        {
          const unsigned int i = s.index[a];
          for (unsigned int r = 0; r < 3; ++r)
            if (std::abs(u[i][r] / rho[i] - s.direction[3 * i + r]) >
                direction_tolerance)
              s.factored = false;
        }

    // Primal-dual active set: the forces of the nodes in contact close
    // their gaps, the others carry none; nodes pulled leave, nodes inside
    // join.
    bool         settled    = false;
    unsigned int iterations = 0;
    while (!settled && iterations < max_iterations)
      {
        ++iterations;
        ++work.iterations;
        if (!s.factored && !factorize_active(patch, s))
          break;
        const unsigned int m = s.n_active;
        for (unsigned int a = 0; a < m; ++a)
          rhs[a] = -free_gap(patch, s, s.index[a]);
        solve_active(s, rhs.data());
        std::fill(s.lambda.begin(), s.lambda.begin() + n, 0.0);
        for (unsigned int a = 0; a < m; ++a)
          s.lambda[s.index[a]] = rhs[a];
        // The gaps the new forces leave, w = q + W lambda.
        std::copy(q.begin(), q.begin() + n, w.begin());
        for (unsigned int a = 0; a < m; ++a)
          add_row(w.data(),
                  patch.W.data() + std::size_t(s.index[a]) * n,
                  rhs[a],
                  n);
        // The gaps w of the nodes not in contact are predicted along the
        // state's normals, their forces along the sphere's current ones:
        // a node the prediction brings in and the solve pushes out again
        // stays out for this step (the next step's gaps are exact), so
        // that the two cannot take turns.
        settled = true;
        for (unsigned int i = 0; i < n; ++i)
          {
            const bool now =
              s.active[i] ? s.lambda[i] > 0 : w[i] < -gap_tolerance && !left[i];
            if (now != bool(s.active[i]))
              {
                left[i]     = !now;
                s.active[i] = now;
                settled     = false;
              }
          }
        if (!settled)
          s.factored = false;
      }

    return settled;
  }



  double
  PatchContact::free_gap(const ContactPatch &patch,
                         const Slot         &s,
                         const unsigned int  i) const noexcept
  {
    // The nodes are at y = x_free + H f: node i's gap along its direction
    // of factorisation with every force taken off.
    const double *d    = s.direction.data() + 3 * std::size_t(i);
    double        move = 0;
    for (unsigned int r = 0; r < 3; ++r)
      move += d[r] * (s.y[3 * i + r] - patch.free_position[3 * i + r]);
    return gap[i] - move;
  }



  void
  PatchContact::apply_forces(const ContactPatch &patch,
                             Slot               &s,
                             Utilities::Point3  &force) noexcept
  {
    const unsigned int n = patch.size();
    for (unsigned int i = 0; i < n; ++i)
      if (s.active[i] || s.lambda[i] > 0)
        for (unsigned int a = 0; a < 3; ++a)
          u[i][a] /= rho[i];

    // The force, and the nodes moved by it for the next tick:
    // y = x_free + H f.
    std::copy(patch.free_position.begin(),
              patch.free_position.end(),
              s.y.begin());
    const std::size_t M = 3 * std::size_t(n);
    for (unsigned int j = 0; j < n; ++j)
      {
        s.lambda[j] = std::max(0.0, s.lambda[j]);
        if (s.lambda[j] == 0)
          continue;
        for (unsigned int b = 0; b < 3; ++b)
          {
            const double f = s.lambda[j] * u[j][b];
            force[b] -= f;
            add_column(s.y.data(),
                       patch.H.data() + (3 * std::size_t(j) + b) * M,
                       f,
                       M);
          }
      }
  }



  void
  PatchContact::add_stiffness(const Slot            &s,
                              std::array<double, 9> &stiffness) noexcept
  {
    const unsigned int m = s.n_active;
    for (unsigned int b = 0; b < 3; ++b)
      {
        double *col = rhs.data() + std::size_t(b) * m;
        for (unsigned int a = 0; a < m; ++a)
          col[a] = u[s.index[a]][b];
        solve_active(s, col);
      }
    for (unsigned int a = 0; a < m; ++a)
      for (unsigned int r = 0; r < 3; ++r)
        for (unsigned int b = 0; b < 3; ++b)
          stiffness[3 * r + b] +=
            u[s.index[a]][r] * rhs[std::size_t(b) * m + a];
  }



  bool
  PatchContact::force(const ContactPatch      &patch,
                      const Utilities::Point3 &x,
                      Utilities::Point3       &force,
                      std::array<double, 9>   *stiffness) noexcept
  {
    work = Work();
    return corner_force(patch, x, force, stiffness);
  }



  bool
  PatchContact::corner_force(const ContactPatch      &patch,
                             const Utilities::Point3 &x,
                             Utilities::Point3       &force,
                             std::array<double, 9>   *stiffness) noexcept
  {
    force = {{0, 0, 0}};
    if (stiffness)
      stiffness->fill(0.0);
    const unsigned int n = patch.size();
    if (n == 0)
      return true;
    if (n > max_nodes)
      return false;
    Slot &s = slot_of(patch);
    ++work.corners;
    work.largest_patch = std::max(work.largest_patch, n);

    // The gaps at the nodes' current positions, for the sphere's centre at
    // this HIP, and the directions nu_i of their forces.
    unsigned int n_loaded = 0;
    const bool   touching = measure_gaps(patch, x, s, n_loaded);
    // Off the surface and nothing pressed: no force, exactly, for the cost
    // of the gaps.
    if (!touching && n_loaded == 0)
      return true;

    const bool settled  = solve_contact(patch, s, n_loaded);
    work.largest_active = std::max(work.largest_active, s.n_active);

    apply_forces(patch, s, force);

    // The normal forces' growth as the gaps close, U_A^T W_AA^-1 U_A.
    if (stiffness && settled && s.factored)
      add_stiffness(s, *stiffness);
    return settled;
  }



  bool
  PatchContact::blend(const std::array<const ContactPatch *, 8> &corners,
                      const std::array<double, 8>               &weights,
                      const Utilities::Point3                   &x,
                      Utilities::Point3                         &force,
                      std::array<double, 9> *stiffness) noexcept
  {
    work  = Work();
    force = {{0, 0, 0}};
    if (stiffness)
      stiffness->fill(0.0);
    bool                  settled = true;
    double                total   = 0;
    Utilities::Point3     f;
    std::array<double, 9> k;
    for (unsigned int c = 0; c < 8; ++c)
      {
        if (weights[c] == 0)
          continue;
        settled =
          corner_force(*corners[c], x, f, stiffness ? &k : nullptr) && settled;
        const double stiffening = stiffening_ratio(corners, weights, c);
        for (unsigned int a = 0; a < 3; ++a)
          f[a] *= stiffening;
        if (stiffness)
          for (double &e : k)
            e *= stiffening;
        // A corner pressing harder than the contact at x does is trusted
        // less (see blend() in the header).
        const double own = Utilities::norm(corners[c]->force);
        const double d =
          std::max(0.0, own - Utilities::norm(f)) / (own + force_floor);
        const double ratio = d / confidence_scale;
        const double w     = weights[c] / (1 + ratio * ratio);
        total += w;
        for (unsigned int a = 0; a < 3; ++a)
          force[a] += w * f[a];
        if (stiffness)
          for (unsigned int e = 0; e < 9; ++e)
            (*stiffness)[e] += w * k[e];
      }
    if (total > 0)
      {
        for (unsigned int a = 0; a < 3; ++a)
          force[a] /= total;
        if (stiffness)
          for (unsigned int e = 0; e < 9; ++e)
            (*stiffness)[e] /= total;
      }
    return settled;
  }



  double
  PatchContact::stiffening_ratio(
    const std::array<const ContactPatch *, 8> &corners,
    const std::array<double, 8>               &weights,
    const unsigned int                         c) noexcept
  {
    const ContactPatch &patch = *corners[c];
    if (patch.neighbour_force.size() != 27)
      return 1;
    double log_ratio = 0;
    for (unsigned int j = 0; j < 8; ++j)
      {
        if (j == c || weights[j] == 0)
          continue;
        // Corner j's offset from corner c in grid steps: the bits of the
        // corner numbers are the axes (StateGrid::corners()).
        unsigned int entry = 0, stride = 1;
        for (unsigned int a = 0; a < 3; ++a, stride *= 3)
          entry += stride * (1 + int((j >> a) & 1) - int((c >> a) & 1));
        const double model = patch.neighbour_force[entry];
        const double state = Utilities::norm(corners[j]->force);
        if (model < force_floor || state < force_floor)
          continue;
        const double r =
          std::clamp(state / model, 1 / largest_ratio, largest_ratio);
        log_ratio += weights[j] * std::log(r);
      }
    return std::exp(log_ratio);
  }



  void
  PatchContact::forget() noexcept
  {
    for (Slot &s : slots)
      {
        s.patch = nullptr;
        s.id    = 0;
        s.used  = 0;
      }
  }



  void
  tabulate_neighbours(ContactPatch &patch, const double spacing)
  {
    patch.spacing = spacing;
    patch.neighbour_force.assign(27, 0.0);
    const unsigned int n = patch.size();
    if (n == 0)
      return;
    PatchContact solver(n, n);
    // The largest step on the way (m): ten ticks of a hand at 25 mm/s,
    // 2.5 % of the sphere's 1 cm radius, which keeps each node on the
    // side of the sphere it is on.
    constexpr double step = 2.5e-4;
    for (int k = -1; k <= 1; ++k)
      for (int j = -1; j <= 1; ++j)
        for (int i = -1; i <= 1; ++i)
          {
            // The corners of a tetrahedron of the grid's Kuhn triangulation
            // (simplex_corners()) differ by steps all up or all down: a
            // neighbour up one axis and down another never shares one with
            // this state, and blend() never asks for it (-1: none).
            if (std::min({i, j, k}) < 0 && std::max({i, j, k}) > 0)
              {
                patch.neighbour_force[9 * (k + 1) + 3 * (j + 1) + (i + 1)] = -1;
                continue;
              }
            const Utilities::Point3 to = {{patch.target[0] + i * spacing,
                                           patch.target[1] + j * spacing,
                                           patch.target[2] + k * spacing}};
            const unsigned int      steps =
              std::max(1.0,
                       std::ceil(Utilities::distance(patch.target, to) / step));
            solver.forget();
            Utilities::Point3 f;
            for (unsigned int t = 1; t <= steps; ++t)
              {
                const double      s = double(t) / steps;
                Utilities::Point3 x;
                for (unsigned int a = 0; a < 3; ++a)
                  x[a] = patch.target[a] + s * (to[a] - patch.target[a]);
                solver.force(patch, x, f);
              }
            // Then held there until the model settles (it converges
            // at the rate of its slowest sliding mode).
            Utilities::Point3 last = f;
            for (unsigned int t = 0; t < 200; ++t)
              {
                const bool settled = solver.force(patch, to, f);
                if (settled && Utilities::distance(f, last) <=
                                 1e-6 * std::max(Utilities::norm(f),
                                                 PatchContact::force_floor))
                  break;
                last = f;
              }
            patch.neighbour_force[9 * (k + 1) + 3 * (j + 1) + (i + 1)] =
              Utilities::norm(f);
          }
  }
} // namespace palpate
