// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

// The store's HDF5 file: how it is opened (SWMR, HDF5's own locking off),
// made whole under a temporary name, opened again after a writer was killed,
// and its fingerprint read; and what HDF5 said when it failed. Apart from
// the records so that the file's life can be read without the order of
// writes inside it, and the reverse.

#include <palpate/state_space/state_store_impl.h>

#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <filesystem>
#include <iterator>
#include <limits>
#include <string>
#include <vector>

namespace palpate
{
  using internal::dataset_names;
  using internal::file_access;
  using internal::first_format_datasets;
  using internal::hdf5_error;
  using internal::hdf5_system_error;
  using internal::n_datasets;
  using internal::record_datasets;
  using internal::WriteFailure;

  namespace internal
  {
    hid_t
    file_access()
    {
      const hid_t fapl = H5Pcreate(H5P_FILE_ACCESS);
      H5Pset_libver_bounds(fapl, H5F_LIBVER_LATEST, H5F_LIBVER_LATEST);
      H5Pset_file_locking(fapl, false, true);
      return fapl;
    }

    std::string
    hdf5_system_error()
    {
      std::string found;
      H5Ewalk2(
        H5E_DEFAULT,
        H5E_WALK_UPWARD,
        [](unsigned int, const H5E_error2_t *e, void *data) -> herr_t {
          auto &f = *static_cast<std::string *>(data);
          if (e->desc != nullptr && f.empty())
            {
              const std::string m  = e->desc;
              const auto        at = m.find("error message = '");
              if (at != std::string::npos)
                f = m.substr(at + 17, m.find('\'', at + 17) - at - 17);
            }
          return 0;
        },
        &found);
      return found;
    }

    std::string
    hdf5_error()
    {
      if (std::string system = hdf5_system_error(); !system.empty())
        return system;
      std::vector<std::string> messages;
      H5Ewalk2(
        H5E_DEFAULT,
        H5E_WALK_UPWARD,
        [](unsigned int, const H5E_error2_t *e, void *data) -> herr_t {
          if (e->desc != nullptr)
            static_cast<std::vector<std::string> *>(data)->push_back(e->desc);
          return 0;
        },
        &messages);
      return messages.empty() ? std::string() : messages.front();
    }
  } // namespace internal



  void
  StateStore::Impl::close_file()
  {
    for (unsigned int d = 0; d < n_datasets; ++d)
      if (datasets[d] >= 0)
        {
          H5Dclose(datasets[d]);
          datasets[d] = -1;
        }
    if (h5 >= 0)
      H5Fclose(h5);
    h5 = -1;
    if (reserve_fd >= 0)
      close(reserve_fd);
    reserve_fd = -1;
  }



  void
  StateStore::Impl::create(const StoreFingerprint &fingerprint,
                           const hsize_t           n_sol,
                           const hsize_t           n_mult)
  {
    n_solution       = n_sol;
    n_multipliers    = n_mult;
    const hid_t fapl = file_access();
    // Written to a temporary name and renamed when complete: a store
    // that exists has its fingerprint and datasets.
    const std::string tmp = file + ".creating";
    h5 = H5Fcreate(tmp.c_str(), H5F_ACC_TRUNC, H5P_DEFAULT, fapl);
    H5Pclose(fapl);
    if (h5 < 0)
      {
        const int         e      = errno;
        const std::string reason = hdf5_error();
        throw WriteFailure{std::strerror(e) +
                           (reason.empty() ? "" : "; HDF5: " + reason)};
      }
    bool ok = true;
    // The fingerprint: one string attribute per field, on the root.
    const hid_t space = H5Screate(H5S_SCALAR);
    for (const auto &[field, value] : fingerprint.fields)
      {
        const hid_t str = H5Tcopy(H5T_C_S1);
        H5Tset_size(str, value.size() + 1);
        const hid_t a =
          H5Acreate2(h5, field.c_str(), str, space, H5P_DEFAULT, H5P_DEFAULT);
        ok = ok && a >= 0 && H5Awrite(a, str, value.c_str()) >= 0;
        if (a >= 0)
          H5Aclose(a);
        H5Tclose(str);
      }
    H5Sclose(space);
    for (unsigned int d = 0; d < n_datasets; ++d)
      {
        const hsize_t dims[2] = {0, columns(d)};
        const hsize_t max[2]  = {H5S_UNLIMITED, columns(d)};
        // A field per chunk for the long rows (a state's field), 64 rows
        // of the short ones; patches' bytes in chunks of 64 KiB, a tenth
        // of a patch on the liver.
        const hsize_t chunk[2] = {d == 9           ? 65536u :
                                  d == 5 || d == 6 ? 1u :
                                                     64u,
                                  std::max<hsize_t>(columns(d), 1)};
        const hid_t s    = H5Screate_simple(2, dims, max);
        const hid_t dcpl = H5Pcreate(H5P_DATASET_CREATE);
        H5Pset_chunk(dcpl, 2, chunk);
        datasets[d] = H5Dcreate2(
          h5, dataset_names[d], type(d), s, H5P_DEFAULT, dcpl, H5P_DEFAULT);
        ok = ok && datasets[d] >= 0;
        H5Pclose(dcpl);
        H5Sclose(s);
      }
    for (unsigned int d = 0; d < n_datasets; ++d)
      if (datasets[d] >= 0)
        H5Dclose(datasets[d]);
    std::fill(std::begin(datasets), std::end(datasets), hid_t(-1));
    // Closing writes it: on a full disk, this is where it fails.
    ok = H5Fclose(h5) >= 0 && ok;
    h5 = -1;
    std::error_code error;
    if (ok)
      std::filesystem::rename(tmp, file, error);
    if (!ok || error)
      {
        const int         e      = errno;
        const std::string reason = error ? error.message() : hdf5_error();
        std::filesystem::remove(tmp, error);
        throw WriteFailure{reason.empty() ? std::strerror(e) : reason};
      }
    open();
    first_row = 0;
  }



  int
  StateStore::Impl::store_datasets(const hid_t f)
  {
    int found = 0;
    for (unsigned int d = 0; d < first_format_datasets; ++d)
      {
        const htri_t e = H5Lexists(f, dataset_names[d], H5P_DEFAULT);
        if (e < 0)
          return -1;
        found += e > 0;
      }
    return found;
  }



  void
  StateStore::Impl::not_a_store() const
  {
    fail("this is an HDF5 file, but not a palpate state store: it has "
         "none of a store's datasets (point, status, force, ...)",
         "name another store file (State space / Store); this one "
         "belongs to something else.");
  }



  // open(), a step: the mark "open for writing" that a killed writer left
  // cleared, and the file opened again with @p fapl and @p flags.
  void
  StateStore::Impl::reopen_after_dead_writer(const hid_t        fapl,
                                             const unsigned int flags)
  {
    // A writer that was killed leaves the superblock marked "open for
    // writing", and HDF5 refuses to open it again. We hold the
    // writer's lock, so no live writer has it open: the mark is a dead
    // one's. The file itself is consistent (SWMR flushes in order):
    // clear the mark, as HDF5's h5clear tool does, and open it again.
    hbool_t     clear = true;
    const hid_t fix   = H5Pcopy(fapl);
    if (H5Pset(fix, "clear_status_flags", &clear) >= 0)
      {
        const hid_t cleared = H5Fopen(file.c_str(), H5F_ACC_RDWR, fix);
        if (cleared >= 0)
          {
            // The killed writer's last chunks may lie beyond the end
            // of allocation its superblock last recorded: HDF5 would
            // then allocate new space over them, and its writes fail
            // ("addr overflow"). Move the end of allocation to the
            // file's end, as `h5clear --increment` does.
            H5Fincrement_filesize(cleared, 0);
            H5Fclose(cleared);
            recovered = true;
            h5        = H5Fopen(file.c_str(), flags, fapl);
          }
      }
    H5Pclose(fix);
  }



  // open(), a step: why HDF5 could not open the store, said as a system
  // error, a file of another program, or damage (HDF5's @p why).
  void
  StateStore::Impl::refuse_unopened(const std::string &why,
                                    const std::string &system) const
  {
    // A system call that failed (HDF5 found the file checked above and
    // could not read it) is not damage.
    if (!system.empty())
      fail("HDF5 cannot open the store: " + system +
             ". The file itself may be fine",
           "check what else has it open and its permissions, then run "
           "again; do not delete it for this.");
    // HDF5 opens for SWMR only files of the latest format: a file of
    // another program (older format) fails here, but is not damaged.
    // Opened plainly, it shows what it is.
    const hid_t plain = H5Pcreate(H5P_FILE_ACCESS);
    H5Pset_file_locking(plain, false, true);
    const hid_t probe = H5Fopen(file.c_str(), H5F_ACC_RDONLY, plain);
    H5Pclose(plain);
    if (probe >= 0)
      {
        const int found = store_datasets(probe);
        H5Fclose(probe);
        if (found == 0)
          not_a_store();
      }
    fail("the store is damaged: it is an HDF5 file, but HDF5 cannot "
         "read its structure (" +
           (why.empty() ? std::string("no detail") : why) +
           "); it was truncated or overwritten",
         "move it away or delete it: palpate then starts a new store "
         "(the states in it are lost).");
  }



  // open(), a step: the opened file's datasets checked and opened, with the
  // record sizes and the rows every dataset holds.
  void
  StateStore::Impl::open_datasets()
  {
    if (store_datasets(h5) == 0)
      not_a_store();
    // A store of the first format (before contact patches were kept) has
    // its states, but the scene's contact patches would be missing from
    // every one of them: refused as such, not as damage.
    if (H5Lexists(h5, dataset_names[8], H5P_DEFAULT) == 0 &&
        H5Lexists(h5, dataset_names[9], H5P_DEFAULT) == 0 &&
        store_datasets(h5) == int(first_format_datasets))
      fail("the store was written by an older palpate, whose stores keep "
           "no contact patches (it has no datasets 'patch' and "
           "'patch_bytes')",
           "name a new store file (State space / Store), or delete this one: "
           "palpate computes its states again and keeps them with their "
           "patches.");
    for (unsigned int d = 0; d < n_datasets; ++d)
      {
        datasets[d] = H5Dopen2(h5, dataset_names[d], H5P_DEFAULT);
        if (datasets[d] < 0)
          fail(std::string("the store is damaged: its dataset '") +
                 dataset_names[d] + "' is missing or unreadable",
               "move it away or delete it: palpate then starts a new "
               "store (the states in it are lost).");
      }
    hsize_t     dims[2];
    const hid_t s = H5Dget_space(datasets[5]);
    H5Sget_simple_extent_dims(s, dims, nullptr);
    H5Sclose(s);
    n_solution    = dims[1];
    const hid_t m = H5Dget_space(datasets[6]);
    H5Sget_simple_extent_dims(m, dims, nullptr);
    H5Sclose(m);
    n_multipliers = dims[1];
    // The rows: the fewest any dataset has (a record cut short by a
    // crash, or being written, has some datasets extended, not all).
    rows = std::numeric_limits<hsize_t>::max();
    for (unsigned int d = 0; d < record_datasets; ++d)
      {
        const hid_t sp = H5Dget_space(datasets[d]);
        H5Sget_simple_extent_dims(sp, dims, nullptr);
        H5Sclose(sp);
        rows = std::min(rows, dims[0]);
      }
    first_row = rows;
  }



  void
  StateStore::Impl::open()
  {
    const bool  writing = access == Access::write;
    const hid_t fapl    = file_access();
    // A damaged file is damaged on every read: a writer does not retry
    // (SWMR retries metadata reads 100 times with growing pauses,
    // minutes). A reader may catch a piece of metadata while the writer
    // rewrites it, and has its checksum fail: it tries again, a few times.
    H5Pset_metadata_read_attempts(fapl, writing ? 1 : 12);
    const unsigned int flags = writing ? H5F_ACC_RDWR | H5F_ACC_SWMR_WRITE :
                                         H5F_ACC_RDONLY | H5F_ACC_SWMR_READ;
    h5                       = H5Fopen(file.c_str(), flags, fapl);
    std::string why          = h5 < 0 ? hdf5_error() : "";
    std::string system       = h5 < 0 ? hdf5_system_error() : "";
    if (h5 < 0 && writing && lock)
      reopen_after_dead_writer(fapl, flags);
    H5Pclose(fapl);
    if (h5 < 0)
      refuse_unopened(why, system);
    open_datasets();
  }



  std::string
  StateStore::Impl::attribute(const std::string &name) const
  {
    const htri_t exists = H5Aexists(h5, name.c_str());
    if (exists < 0)
      fail("the store is damaged: HDF5 cannot read its fingerprint (" +
             hdf5_error() + ")",
           "move it away or delete it: palpate then starts a new store "
           "(the states in it are lost).");
    if (exists == 0)
      return "(not recorded)";
    const hid_t a    = H5Aopen(h5, name.c_str(), H5P_DEFAULT);
    const hid_t t    = H5Aget_type(a);
    const auto  size = H5Tget_size(t);
    std::string value(size, '\0');
    const hid_t str = H5Tcopy(H5T_C_S1);
    H5Tset_size(str, size);
    H5Aread(a, str, value.data());
    H5Tclose(str);
    H5Tclose(t);
    H5Aclose(a);
    return value.c_str();
  }
} // namespace palpate
