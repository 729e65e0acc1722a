// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

#include <palpate/haptics/patch_contact.h>
#include <palpate/hyperelastic/contact_lcp.h>
#include <palpate/hyperelastic/contact_patch.h>
#include <palpate/state_space/state_grid.h>

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
    , w(max_nodes)
    , rhs(3 * this->max_active)
    , rho(max_nodes)
    , u(max_nodes)
    , loaded(max_nodes)
  {
    for (Slot &s : slots)
      {
        s.lambda.resize(max_nodes);
        s.y.resize(3 * std::size_t(max_nodes));
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
    for (unsigned int a = 0; a < m; ++a)
      for (unsigned int b = 0; b < m; ++b)
        s.LU[a * m + b] = patch.W[std::size_t(s.index[a]) * n + s.index[b]];
    s.n_active = m;
    ++work.factorizations;
    // W is a compliance, symmetric positive definite at a stable state:
    // Cholesky, half the work of LU. LU where round-off (or an unstable
    // state's tangent) makes the block indefinite.
    s.cholesky = cholesky(s.LU.data(), m);
    if (!s.cholesky)
      {
        for (unsigned int a = 0; a < m; ++a)
          for (unsigned int b = 0; b < m; ++b)
            s.LU[a * m + b] = patch.W[std::size_t(s.index[a]) * n + s.index[b]];
        s.factored = lu_factorize(s.LU.data(), m, s.pivot.data());
      }
    else
      s.factored = true;
    return s.factored;
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
        q[i]     = rho[i] - patch.radius + patch.offset[i];
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
          rhs[a] = -q[s.index[a]];
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
        settled = true;
        for (unsigned int i = 0; i < n; ++i)
          {
            const bool now =
              s.active[i] ? s.lambda[i] > 0 : w[i] < -gap_tolerance;
            if (now != bool(s.active[i]))
              {
                s.active[i] = now;
                settled     = false;
              }
          }
        if (!settled)
          s.factored = false;
      }

    return settled;
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



  std::array<double, 8>
  PatchContact::weights(const std::array<double, 3> &local) noexcept
  {
    return simplex_weights(local);
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
} // namespace palpate
