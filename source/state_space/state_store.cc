// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

// StateStore's own members: a store opened (its file checked, the writer's
// lock taken, the file made or its fingerprint compared with the scene's),
// loaded into the cache, and appended to from it. The jobs it drives each
// have a file of their own (state_store_impl.h says which).

#include <palpate/state_space/state_cache.h>
#include <palpate/state_space/state_grid.h>
#include <palpate/state_space/state_store_impl.h>

#include <algorithm>
#include <memory>

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
        if (stored != value && field == "contact patches")
          {
            if (stored == "kept" && value != "none")
              s.fail("the store's contact patches are of an older layout "
                     "(without their model's force at the neighbouring "
                     "states, which the blend corrects each corner by)",
                     "delete the store to compute its states again with "
                     "this palpate, or name another store file (State "
                     "space / Store).");
            s.fail(stored != "none" ?
                     "the store keeps contact patches (it was made with "
                     "State space / Interpolation = contact patch), and "
                     "this scene interpolates otherwise" :
                     "the store keeps no contact patches (it was made with "
                     "another State space / Interpolation), and contact "
                     "patch needs each state's",
                   "use another store file for this scene (State space / "
                   "Store), or the interpolation the store was made with.");
          }
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
            loaded.patches += copy.contact_patch != nullptr;
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
              const auto patch =
                state->contact_patch ? state->contact_patch : cache.patch(p);
              append(p, *state, patch.get());
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
} // namespace palpate
