// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

#include <palpate/base/exceptions.h>
#include <palpate/state_space/state_cache.h>
#include <palpate/state_space/state_grid.h>
#include <palpate/state_space/state_store_impl.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <fstream>
#include <memory>
#include <vector>

namespace palpate
{
  using internal::acquire_lock;
  using internal::check_store_file;
  using internal::WriteFailure;



  StateStore::StateStore(const std::string      &file,
                         const StoreFingerprint &fingerprint,
                         const Access            access)
    : impl(std::make_unique<Impl>())
  {
    // HDF5 prints its error stack by default; palpate reports errors itself.
    H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr);
    Impl &s            = *impl;
    s.file             = file;
    s.access           = access;
    const bool writing = access == Access::write;
    // What the file is, before HDF5 sees it: a file that is fine but not
    // writable, a directory, a text file are not "damaged".
    check_store_file(file, writing);
    bool exists = true;
    if (writing)
      {
        // The writer's lock, before anything is written; then look again
        // (another writer may have made the store meanwhile).
        s.lock = acquire_lock(file);
        exists = check_store_file(file, writing);
      }
    if (!exists)
      {
        // The sizes come with the first state: create lazily then. Until
        // then the fingerprint is kept.
        try
          {
            s.create(fingerprint, 0, 0);
          }
        catch (const WriteFailure &f)
          {
            s.fail("the store cannot be made: " + f.reason,
                   "make room on its disk, or name a store where there is "
                   "room and you can write (State space / Store).");
          }
        return;
      }
    s.open();
    for (const auto &[field, value] : fingerprint.fields)
      {
        const std::string stored = s.attribute(field);
        if (stored != value)
          s.fail("the store was computed for other physics: its " + field +
                   " is '" + stored + "', the scene's is '" + value +
                   "'; its states would be wrong here",
                 "use another store file for this scene (State space / "
                 "Store), or delete this one to compute the states again.");
      }
  }



  StateStore::~StateStore() = default;



  unsigned int
  StateStore::appended() const
  {
    const Impl &s = *impl;
    return s.stopped ? s.kept : s.rows - std::min(s.rows, s.first_row);
  }



  bool
  StateStore::stopped() const
  {
    return impl->stopped;
  }



  StateStore::Loaded
  StateStore::load(StateCache &cache, const StateGrid &grid)
  {
    Impl      &s = *impl;
    Loaded     loaded;
    const auto all        = read_all(loaded.damaged, &loaded.incomplete);
    const auto generation = cache.generation();
    for (const auto &[point, state] : all)
      {
        if (point >= grid.size())
          {
            ++loaded.damaged;
            continue;
          }
        s.stored.insert(point);
        if (state.converged)
          {
            State copy               = state;
            copy.active_displacement = grid.position(point);
            cache.publish(point,
                          std::make_shared<const State>(std::move(copy)),
                          generation);
            ++loaded.states;
          }
        else
          {
            cache.publish_failure(point, generation, state.status);
            ++loaded.failures;
          }
      }
    return loaded;
  }



  StateStore::Loaded
  StateStore::contents() const
  {
    Loaded     c;
    const auto all = read_all(c.damaged, &c.incomplete);
    for (const auto &[point, state] : all)
      (state.converged ? c.states : c.failures) += 1;
    return c;
  }



  unsigned int
  StateStore::append(const StateCache &cache, const StateGrid &grid)
  {
    Impl        &s = *impl;
    unsigned int n = 0;
    if (s.stopped)
      return 0;
    for (unsigned int p = 0; p < grid.size(); ++p)
      {
        if (s.stored.count(p) > 0)
          continue;
        const PointStatus status = cache.status(p);
        if (status == PointStatus::failed)
          {
            State failure;
            failure.converged = false;
            failure.status    = cache.failure_reason(p);
            append(p, failure);
            ++n;
          }
        else if (status == PointStatus::available)
          if (const auto state = cache.state(p))
            {
              append(p, *state);
              ++n;
            }
      }
    return n;
  }



  unsigned int
  StateStore::missing(const StateCache &cache, const StateGrid &grid) const
  {
    const Impl  &s = *impl;
    unsigned int n = 0;
    if (s.stopped)
      return 0;
    for (unsigned int p = 0; p < grid.size(); ++p)
      if (s.stored.count(p) == 0)
        {
          const PointStatus status = cache.status(p);
          n += status == PointStatus::failed ||
               (status == PointStatus::available && !cache.dropped(p));
        }
    return n;
  }



  unsigned int
  StateStore::size() const
  {
    return impl->rows;
  }



  const std::string &
  StateStore::file() const
  {
    return impl->file;
  }



  void
  StateStore::export_vtk(const StateGrid   &grid,
                         const std::string &filename) const
  {
    unsigned int               damaged = 0;
    const auto                 all     = read_all(damaged);
    const auto                 n       = grid.size();
    std::vector<const State *> at(n, nullptr);
    for (const auto &[point, state] : all)
      if (point < n)
        at[point] = &state;
    std::ofstream out(filename);
    if (!out)
      throw OutputError("cannot write '" + filename + "'");
    out.precision(9);
    const unsigned int side = 2 * grid.half_width() + 1;
    const double       h = grid.spacing(), o = -h * grid.half_width();
    out << "# vtk DataFile Version 3.0\npalpate state space of " << file()
        << "\nASCII\nDATASET STRUCTURED_POINTS\nDIMENSIONS " << side << ' '
        << side << ' ' << side << "\nORIGIN " << o << ' ' << o << ' ' << o
        << "\nSPACING " << h << ' ' << h << ' ' << h << "\nPOINT_DATA " << n
        << "\n";
    // VTK orders points x fastest: the grid's linear number may not, so go
    // by index.
    const auto point_at =
      [&](const unsigned int i, const unsigned int j, const unsigned int k) {
        const int w = grid.half_width();
        return grid.linear(GridIndex{{int(i) - w, int(j) - w, int(k) - w}});
      };
    const auto each = [&](const auto &write) {
      for (unsigned int k = 0; k < side; ++k)
        for (unsigned int j = 0; j < side; ++j)
          for (unsigned int i = 0; i < side; ++i)
            write(at[point_at(i, j, k)]);
    };
    out << "VECTORS force double\n";
    each([&](const State *s) {
      const bool f = s != nullptr && s->converged;
      out << (f ? s->force[0] : 0.) << ' ' << (f ? s->force[1] : 0.) << ' '
          << (f ? s->force[2] : 0.) << '\n';
    });
    out << "SCALARS force_magnitude double 1\nLOOKUP_TABLE default\n";
    each([&](const State *s) {
      out << (s != nullptr && s->converged ? Utilities::norm(s->force) : 0.)
          << '\n';
    });
    out << "SCALARS status int 1\nLOOKUP_TABLE default\n";
    each([&](const State *s) {
      out << (s == nullptr ? -1 :
              s->converged ? 0 :
                             1 + static_cast<int>(s->status))
          << '\n';
    });
    out << "TENSORS stiffness double\n";
    each([&](const State *s) {
      for (unsigned int r = 0; r < 3; ++r)
        out << (s != nullptr && s->has_stiffness ? s->stiffness[3 * r] : 0.)
            << ' '
            << (s != nullptr && s->has_stiffness ? s->stiffness[3 * r + 1] : 0.)
            << ' '
            << (s != nullptr && s->has_stiffness ? s->stiffness[3 * r + 2] : 0.)
            << '\n';
    });
    out.flush();
    if (!out)
      throw OutputError("writing '" + filename + "' failed (" +
                        std::strerror(errno) + ")");
  }
} // namespace palpate
