// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

#include <palpate/hyperelastic/contact_patch.h>

#include <algorithm>
#include <atomic>
#include <cstring>
#include <stdexcept>

namespace palpate
{
  std::uint64_t
  ContactPatch::new_id() noexcept
  {
    static std::atomic<std::uint64_t> last{0};
    return ++last;
  }



  std::size_t
  ContactPatch::memory() const noexcept
  {
    return sizeof(ContactPatch) + nodes.size() * sizeof(unsigned int) +
           (position.size() + normal.size() + free_position.size() +
            lambda.size() + offset.size() + W.size() + neighbour_force.size()) *
             sizeof(double) +
           H.size() * sizeof(float);
  }



  namespace
  {
    /** The entries of ContactPatch::neighbour_force: the 3 x 3 x 3 grid
     * points around the state and its own. */
    constexpr std::size_t neighbour_entries = 27;

    /** The parts of a patch in the order its bytes hold them, for writing
     * and for reading. */
    template <typename Patch, typename Visit>
    void
    visit_arrays(Patch &patch, Visit &&visit)
    {
      visit(patch.nodes);
      visit(patch.position);
      visit(patch.normal);
      visit(patch.free_position);
      visit(patch.lambda);
      visit(patch.offset);
      visit(patch.W);
      visit(patch.H);
    }
  } // namespace



  std::vector<char>
  patch_bytes(const ContactPatch &patch)
  {
    const std::uint64_t n = patch.size();
    std::size_t         bytes =
      sizeof(n) + 11 * sizeof(double) + neighbour_entries * sizeof(double);
    visit_arrays(patch,
                 [&](const auto &v) { bytes += v.size() * sizeof(v[0]); });
    std::vector<char> out(bytes);
    char             *p   = out.data();
    const auto        put = [&p](const void *data, const std::size_t size) {
      std::memcpy(p, data, size);
      p += size;
    };
    put(&n, sizeof(n));
    put(patch.target.data(), 3 * sizeof(double));
    put(patch.center.data(), 3 * sizeof(double));
    put(&patch.radius, sizeof(double));
    put(patch.force.data(), 3 * sizeof(double));
    put(&patch.spacing, sizeof(double));
    visit_arrays(patch, [&](const auto &v) {
      put(v.data(), v.size() * sizeof(v[0]));
    });
    std::vector<double> neighbours(neighbour_entries, -1.0);
    if (patch.neighbour_force.size() == neighbour_entries)
      neighbours = patch.neighbour_force;
    put(neighbours.data(), neighbour_entries * sizeof(double));
    return out;
  }



  std::shared_ptr<const ContactPatch>
  patch_from_bytes(const char *data, const std::size_t size)
  {
    std::uint64_t n   = 0;
    const char   *p   = data;
    const char   *end = data + size;
    const auto    get = [&](void *to, const std::size_t bytes) {
      if (std::size_t(end - p) < bytes)
        throw std::runtime_error("a contact patch is truncated");
      std::memcpy(to, p, bytes);
      p += bytes;
    };
    get(&n, sizeof(n));
    // A patch of more nodes than bytes cannot be real: refused before the
    // arrays are sized for it.
    if (n > size)
      throw std::runtime_error("a contact patch has the wrong length");
    auto patch = std::make_shared<ContactPatch>();
    get(patch->target.data(), 3 * sizeof(double));
    get(patch->center.data(), 3 * sizeof(double));
    get(&patch->radius, sizeof(double));
    get(patch->force.data(), 3 * sizeof(double));
    get(&patch->spacing, sizeof(double));
    patch->nodes.resize(n);
    patch->position.resize(3 * n);
    patch->normal.resize(3 * n);
    patch->free_position.resize(3 * n);
    patch->lambda.resize(n);
    patch->offset.resize(n);
    patch->W.resize(n * n);
    patch->H.resize(9 * n * n);
    visit_arrays(*patch,
                 [&](auto &v) { get(v.data(), v.size() * sizeof(v[0])); });
    patch->neighbour_force.resize(neighbour_entries);
    get(patch->neighbour_force.data(), neighbour_entries * sizeof(double));
    // A patch written without the table has -1 throughout: none.
    if (std::all_of(patch->neighbour_force.begin(),
                    patch->neighbour_force.end(),
                    [](const double f) { return f < 0; }))
      patch->neighbour_force.clear();
    if (p != end)
      throw std::runtime_error("a contact patch has the wrong length");
    return patch;
  }



  void
  contact_patch_nodes(const std::vector<HyperelasticSystem::ContactRow> &rows,
                      const double               half_width,
                      const double               reach,
                      std::vector<unsigned int> &nodes,
                      std::vector<unsigned int> &unknowns)
  {
    nodes.clear();
    unknowns.clear();
    for (unsigned int k = 0; k < rows.size(); ++k)
      {
        const auto &r = rows[k];
        // The node's distance from the box of centres (rho n is its
        // position from the state's centre): the sphere meets it only
        // from there, and a ball around the state as wide as the box's
        // half-diagonal would hold about twice the surface nodes.
        double d2 = 0;
        for (unsigned int a = 0; a < 3; ++a)
          {
            const double out =
              std::max(0.0, std::abs(r.rho * r.n[a]) - half_width);
            d2 += out * out;
          }
        if (d2 <= reach * reach &&
            std::any_of(r.eq.begin(), r.eq.end(), [](int e) { return e >= 0; }))
          {
            nodes.push_back(k);
            for (const int e : r.eq)
              if (e >= 0)
                unknowns.push_back(e);
          }
      }
  }



  std::shared_ptr<ContactPatch>
  make_contact_patch(const HyperelasticSystem                    &system,
                     const std::vector<unsigned int>             &nodes,
                     const std::vector<double>                   &block,
                     const std::vector<double>                   &x,
                     const Utilities::Point3                     &target,
                     std::vector<HyperelasticSystem::ContactRow> &rows)
  {
    auto patch    = std::make_shared<ContactPatch>();
    patch->target = target;
    patch->center = system.sphere_center(target);
    patch->radius = system.sphere_radius();
    patch->nodes  = nodes;
    system.contact_rows(x, target, rows);
    const unsigned int m = patch->size();
    if (m == 0)
      return patch;

    // H = P K^-1 P^T on the nodes' free DoFs, the block of the inverse of
    // the contact-free tangent there (zero rows and columns for DoFs a
    // boundary condition fixes).
    std::vector<int> slot(3 * m, -1);
    unsigned int     k = 0;
    for (unsigned int j = 0; j < m; ++j)
      for (unsigned int a = 0; a < 3; ++a)
        if (rows[patch->nodes[j]].eq[a] >= 0)
          slot[3 * j + a] = k++;
    if (block.size() != std::size_t(k) * k)
      return nullptr;
    const unsigned int  M = 3 * m;
    std::vector<double> H(std::size_t(M) * M, 0.0);
    for (unsigned int r = 0; r < M; ++r)
      if (slot[r] >= 0)
        for (unsigned int c = 0; c < M; ++c)
          if (slot[c] >= 0)
            H[std::size_t(r) * M + c] =
              block[std::size_t(slot[r]) * k + slot[c]];
    patch->H.assign(H.begin(), H.end());
    patch->normal.resize(M);
    for (unsigned int i = 0; i < m; ++i)
      for (unsigned int a = 0; a < 3; ++a)
        patch->normal[3 * i + a] = rows[patch->nodes[i]].n[a];
    patch->W.resize(std::size_t(m) * m);
    for (unsigned int i = 0; i < m; ++i)
      for (unsigned int j = 0; j < m; ++j)
        {
          double w = 0;
          for (unsigned int a = 0; a < 3; ++a)
            for (unsigned int b = 0; b < 3; ++b)
              w += patch->normal[3 * i + a] *
                   H[std::size_t(3 * i + a) * M + 3 * j + b] *
                   patch->normal[3 * j + b];
          patch->W[std::size_t(i) * m + j] = w;
        }

    patch->position.resize(M);
    patch->lambda.resize(m);
    patch->offset.resize(m);
    for (unsigned int i = 0; i < m; ++i)
      {
        const auto &r = rows[patch->nodes[i]];
        for (unsigned int a = 0; a < 3; ++a)
          patch->position[3 * i + a] = patch->center[a] + r.rho * r.n[a];
        patch->lambda[i] = std::max(0.0, r.lambda_hat);
        for (unsigned int a = 0; a < 3; ++a)
          patch->force[a] -= patch->lambda[i] * r.n[a];
        patch->offset[i] =
          patch->lambda[i] > 0 ? -r.gap : std::max(0.0, -r.gap);
      }
    // x_free = x - H f_s, f_s the state's forces along its normals.
    patch->free_position = patch->position;
    for (unsigned int j = 0; j < m; ++j)
      if (patch->lambda[j] > 0)
        for (unsigned int b = 0; b < 3; ++b)
          {
            const double f = patch->lambda[j] * patch->normal[3 * j + b];
            const float *h = patch->H.data() + std::size_t(3 * j + b) * M;
            for (unsigned int r = 0; r < M; ++r)
              patch->free_position[r] -= h[r] * f;
          }
    return patch;
  }
} // namespace palpate
