// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

// The records: one state appended (room taken first, every row flushed, the
// checksum last), the records read back and checked, and appending stopped
// cleanly when a write fails. Apart from the rest because the store's crash
// safety is the order of these writes: a killed writer loses at most the
// record it was writing, and a reader never takes a record cut short.

#include <palpate/base/exceptions.h>
#include <palpate/hyperelastic/contact_patch.h>
#include <palpate/state_space/state_store_impl.h>

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <mutex>
#include <stdexcept>

namespace palpate
{
  using internal::hdf5_error;
  using internal::Record;
  using internal::WriteFailure;


  void
  StateStore::Impl::read_row(const hsize_t      row,
                             const unsigned int d,
                             void              *data) const
  {
    const hsize_t start[2] = {row, 0}, count[2] = {1, columns(d)};
    if (count[1] == 0)
      return;
    const hid_t file_space = H5Dget_space(datasets[d]);
    H5Sselect_hyperslab(
      file_space, H5S_SELECT_SET, start, nullptr, count, nullptr);
    const hid_t memory = H5Screate_simple(2, count, nullptr);
    H5Dread(datasets[d], type(d), memory, file_space, H5P_DEFAULT, data);
    H5Sclose(memory);
    H5Sclose(file_space);
  }



  bool
  StateStore::Impl::write_row(const hsize_t      row,
                              const unsigned int d,
                              const void        *data)
  {
    const hsize_t extent[2] = {row + 1, columns(d)};
    if (H5Dset_extent(datasets[d], extent) < 0)
      return false;
    if (columns(d) > 0)
      {
        const hsize_t start[2] = {row, 0}, count[2] = {1, columns(d)};
        const hid_t   file_space = H5Dget_space(datasets[d]);
        H5Sselect_hyperslab(
          file_space, H5S_SELECT_SET, start, nullptr, count, nullptr);
        const hid_t  memory = H5Screate_simple(2, count, nullptr);
        const herr_t written =
          H5Dwrite(datasets[d], type(d), memory, file_space, H5P_DEFAULT, data);
        H5Sclose(memory);
        H5Sclose(file_space);
        if (written < 0)
          return false;
      }
    // The chunk cache holds the row until it is flushed: only the flush
    // meets a full disk, so its result is what says the row is written.
    return H5Dflush(datasets[d]) >= 0;
  }



  bool
  StateStore::Impl::write_patch(const std::vector<char> &bytes, hsize_t &offset)
  {
    hsize_t     dims[2];
    const hid_t space = H5Dget_space(datasets[9]);
    H5Sget_simple_extent_dims(space, dims, nullptr);
    H5Sclose(space);
    offset = dims[0];
    if (bytes.empty())
      return true;
    const hsize_t extent[2] = {offset + bytes.size(), 1};
    if (H5Dset_extent(datasets[9], extent) < 0)
      return false;
    const hsize_t start[2] = {offset, 0}, count[2] = {bytes.size(), 1};
    const hid_t   file_space = H5Dget_space(datasets[9]);
    H5Sselect_hyperslab(
      file_space, H5S_SELECT_SET, start, nullptr, count, nullptr);
    const hid_t  memory  = H5Screate_simple(2, count, nullptr);
    const herr_t written = H5Dwrite(
      datasets[9], type(9), memory, file_space, H5P_DEFAULT, bytes.data());
    H5Sclose(memory);
    H5Sclose(file_space);
    return written >= 0 && H5Dflush(datasets[9]) >= 0;
  }



  bool
  StateStore::Impl::read_patch(const hsize_t      offset,
                               const hsize_t      size,
                               std::vector<char> &bytes) const
  {
    bytes.clear();
    if (size == 0)
      return true;
    hsize_t     dims[2];
    const hid_t file_space = H5Dget_space(datasets[9]);
    H5Sget_simple_extent_dims(file_space, dims, nullptr);
    if (offset > dims[0] || size > dims[0] - offset)
      {
        H5Sclose(file_space);
        return false;
      }
    bytes.resize(size);
    const hsize_t start[2] = {offset, 0}, count[2] = {size, 1};
    H5Sselect_hyperslab(
      file_space, H5S_SELECT_SET, start, nullptr, count, nullptr);
    const hid_t  memory = H5Screate_simple(2, count, nullptr);
    const herr_t read   = H5Dread(
      datasets[9], type(9), memory, file_space, H5P_DEFAULT, bytes.data());
    H5Sclose(memory);
    H5Sclose(file_space);
    return read >= 0;
  }



  std::string
  StateStore::Impl::reserve(const std::size_t patch_bytes)
  {
    haddr_t eoa = 0;
    if (H5Fget_eoa(h5, &eoa) < 0)
      return "";
    const off_t record =
      (13 + n_solution + n_multipliers) * sizeof(double) + 32 + patch_bytes;
    const off_t target = eoa + 4 * record + 128 * 1024;
    // A descriptor of our own, kept while the file is open (close_file()
    // closes it: create() renames a new file into place).
    if (reserve_fd < 0)
      reserve_fd = ::open(file.c_str(), O_WRONLY | O_CLOEXEC);
    if (reserve_fd < 0)
      return std::strerror(errno);
    // The size each time: HDF5 may have cut the file back to its end of
    // allocation when it flushed.
    struct stat st
    {};
    int error = fstat(reserve_fd, &st) == 0 ? 0 : errno;
    // posix_fallocate returns the error; glibc writes zeros where the
    // file system cannot allocate.
    if (error == 0 &&
        static_cast<std::uint64_t>(st.st_size) < eoa + 2 * record + 64 * 1024)
      error = posix_fallocate(reserve_fd, 0, target);
    return error == 0 ? "" : std::strerror(error);
  }



  StateStore::Impl::Read
  StateStore::Impl::read_record(const hsize_t row, Record &r) const
  {
    r.solution.resize(n_solution);
    r.multipliers.resize(n_multipliers);
    std::uint64_t checksum = 0;
    read_row(row, 0, &r.point);
    read_row(row, 1, &r.status);
    read_row(row, 2, r.force);
    read_row(row, 3, r.stiffness);
    read_row(row, 4, &r.wall_time);
    read_row(row, 5, r.solution.data());
    read_row(row, 6, r.multipliers.data());
    read_row(row, 7, &checksum);
    // The checksum is written last: none (HDF5's fill value, 0) means
    // the writer never got there, it was killed or is writing it now.
    if (checksum == 0)
      return Read::incomplete;
    hsize_t patch[2] = {0, 0}; // offset and size in patch_bytes
    read_row(row, 8, patch);
    if (!read_patch(patch[0], patch[1], r.patch))
      return Read::damaged;
    return checksum == r.checksum() && r.point >= 0 ? Read::intact :
                                                      Read::damaged;
  }



  void
  StateStore::Impl::stop(std::string reason)
  {
    if (reason.empty())
      reason = "the file system refused a write";
    stopped = true;
    close_file();
    pending.clear();
    unsigned int states = 0, failures = 0, damaged = 0, incomplete = 0;
    kept = 0;
    std::string unreadable;
    access = Access::read;
    try
      {
        open();
        for (hsize_t row = 0; row < rows; ++row)
          {
            Record     r;
            const Read read = read_record(row, r);
            damaged += read == Read::damaged;
            incomplete += read == Read::incomplete;
            if (read == Read::intact)
              {
                (r.status == 0 ? states : failures) += 1;
                kept += row >= first_row_before_stop;
              }
          }
      }
    catch (const InputError &e)
      {
        unreadable = e.problem();
        close_file();
      }
    const std::string what =
      unreadable.empty() ?
        "it keeps " + std::to_string(states) + " states and " +
          std::to_string(failures) + " failure points (read back), " +
          std::to_string(kept) + " of them appended by this run" +
          (damaged + incomplete > 0 ?
             "; " + std::to_string(damaged + incomplete) +
               " records cut short or damaged are skipped" :
             std::string()) :
        "reading it back failed: " + unreadable;
    const std::string message =
      "writing the state store '" + file + "' failed (" + reason +
      "); appending stopped: " + what +
      ". Make room (or move the store to a disk with room) and run "
      "again: the states kept are not computed again";
    if (lock)
      {
        std::lock_guard<std::mutex> guard(lock->mutex);
        if (lock->failure.empty())
          lock->failure = message;
      }
    throw OutputError(message);
  }



  // append(), a step: the datasets made again with the record sizes the
  // first converged state fixes, the fingerprint kept.
  void
  StateStore::Impl::make_record_datasets(const hsize_t n_sol,
                                         const hsize_t n_mult)
  {
    // The first state fixes the record sizes: make the datasets again
    // with them (no row is in the file yet).
    StoreFingerprint keep;
    for (const char *const field : {"mesh",
                                    "material",
                                    "fixed nodes",
                                    "active node",
                                    "element",
                                    "grid",
                                    "tolerances",
                                    "load effects",
                                    "contact patches",
                                    "palpate version"})
      keep.fields.emplace_back(field, attribute(field));
    close_file();
    try
      {
        create(keep, n_sol, n_mult);
      }
    catch (const WriteFailure &f)
      {
        first_row_before_stop = 0;
        stop(f.reason);
      }
    first_row_before_stop = first_row;
  }



  void
  StateStore::append(const unsigned int point, const State &state)
  {
    append(point, state, state.contact_patch.get());
  }



  void
  StateStore::append(const unsigned int  point,
                     const State        &state,
                     const ContactPatch *patch)
  {
    Impl &s = *impl;
    if (s.stopped)
      return;
    if (s.access != Access::write)
      throw std::logic_error("StateStore::append on a store opened for "
                             "reading");
    if (s.n_solution == 0 && !state.converged)
      {
        s.pending.emplace_back(point, state);
        s.stored.insert(point);
        return;
      }
    Record r;
    r.point  = point;
    r.status = state.converged ? 0 : 1 + static_cast<int>(state.status);
    for (unsigned int d = 0; d < 3; ++d)
      r.force[d] = state.force[d];
    for (unsigned int k = 0; k < 9; ++k)
      r.stiffness[k] = state.has_stiffness ?
                         state.stiffness[k] :
                         std::numeric_limits<double>::quiet_NaN();
    r.wall_time = state.wall_time;
    if (state.converged)
      {
        r.solution    = state.solution;
        r.multipliers = state.multipliers;
      }
    s.first_row_before_stop = s.first_row;
    if (s.rows == 0 && s.n_solution == 0 && state.converged)
      s.make_record_datasets(state.solution.size(), state.multipliers.size());
    r.solution.resize(s.n_solution, 0.0);
    r.multipliers.resize(s.n_multipliers, 0.0);
    if (state.converged && patch != nullptr)
      r.patch = patch_bytes(*patch);
    const std::uint64_t checksum = r.checksum();
    // Room first: a write that fails half-way leaves HDF5's superblock
    // promising space the file never got (it is then "truncated" to HDF5,
    // and no record in it can be read). So the space for this record, and
    // more, is taken from the file system before HDF5 writes anything; if
    // it cannot be had (the disk full, a file size limit), appending stops
    // here and the file is as the last record left it.
    if (const std::string refused = s.reserve(r.patch.size()); !refused.empty())
      s.stop(refused);
    // The checksum goes last: a record cut short has none and is skipped.
    // Each row is flushed as it is written, and the whole file's buffers
    // after the record, so that a killed writer loses at most the record
    // being written and a reader never sees a checksum before its record.
    const hsize_t row   = s.rows;
    errno               = 0;
    hsize_t    where[2] = {0, r.patch.size()};
    const bool written =
      s.write_patch(r.patch, where[0]) && s.write_row(row, 8, where) &&
      s.write_row(row, 0, &r.point) && s.write_row(row, 1, &r.status) &&
      s.write_row(row, 2, r.force) && s.write_row(row, 3, r.stiffness) &&
      s.write_row(row, 4, &r.wall_time) &&
      s.write_row(row, 5, r.solution.data()) &&
      s.write_row(row, 6, r.multipliers.data()) &&
      s.write_row(row, 7, &checksum) && H5Fflush(s.h5, H5F_SCOPE_LOCAL) >= 0;
    if (!written)
      {
        const int         e      = errno;
        const std::string reason = hdf5_error();
        s.stop(!reason.empty() ? reason :
               e != 0          ? std::string(std::strerror(e)) :
                                 std::string());
      }
    ++s.rows;
    s.stored.insert(point);
    if (!s.pending.empty() && s.n_solution > 0)
      {
        const auto pending = std::move(s.pending);
        s.pending.clear();
        for (const auto &[p, failure] : pending)
          append(p, failure);
      }
  }



  std::vector<std::pair<unsigned int, State>>
  StateStore::read_all(unsigned int &damaged, unsigned int *incomplete) const
  {
    const Impl                                 &s = *impl;
    std::vector<std::pair<unsigned int, State>> states;
    damaged = 0;
    if (incomplete != nullptr)
      *incomplete = 0;
    if (s.h5 < 0)
      return states;
    for (hsize_t row = 0; row < s.rows; ++row)
      {
        Record           r;
        const Impl::Read read = s.read_record(row, r);
        if (read == Impl::Read::damaged)
          ++damaged;
        if (read == Impl::Read::incomplete && incomplete != nullptr)
          ++*incomplete;
        if (read != Impl::Read::intact)
          continue;
        State state;
        state.converged = r.status == 0;
        state.status    = r.status == 0 ? SolveStatus::converged :
                                          static_cast<SolveStatus>(r.status - 1);
        for (unsigned int d = 0; d < 3; ++d)
          state.force[d] = r.force[d];
        state.has_stiffness = !std::isnan(r.stiffness[0]);
        for (unsigned int k = 0; k < 9; ++k)
          state.stiffness[k] = state.has_stiffness ? r.stiffness[k] : 0;
        state.wall_time = r.wall_time;
        if (state.converged)
          {
            state.solution    = std::move(r.solution);
            state.multipliers = std::move(r.multipliers);
            if (!r.patch.empty())
              try
                {
                  state.contact_patch =
                    patch_from_bytes(r.patch.data(), r.patch.size());
                }
              catch (const std::runtime_error &)
                {
                  // Checksummed bytes that are not a patch: written by a
                  // palpate that lays patches out otherwise.
                  ++damaged;
                  continue;
                }
          }
        else
          state.message =
            "a failure point (" + to_string(state.status) + ", from the store)";
        states.emplace_back(r.point, std::move(state));
      }
    return states;
  }
} // namespace palpate
