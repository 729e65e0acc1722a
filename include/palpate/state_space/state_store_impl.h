// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

#ifndef palpate_state_space_state_store_impl_h
#define palpate_state_space_state_store_impl_h

// Not an interface: the state store's implementation, shared by its source
// files, one job each:
//   state_store.cc              StateStore's own members: open, load, append
//                               what the cache holds
//   state_store_lock.cc         the writer's lock (StoreLock)
//   state_store_checks.cc       what a file is before HDF5 sees it
//   state_store_hdf5.cc         the HDF5 file: made, opened, its fingerprint
//   state_store_records.cc      records appended and read back, checksummed
//   state_store_fingerprint.cc  what a stored state depends on
//   state_store_export.cc       the ParaView export
// Users of the store include state_store.h, never this header: it brings in
// HDF5's.

#include <palpate/state_space/state_store.h>

#include <hdf5.h>
#include <sys/types.h>

#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <iterator>
#include <memory>
#include <mutex>
#include <set>
#include <string>
#include <utility>
#include <vector>

namespace palpate
{
  namespace internal
  {
    /** FNV-1a over bytes: the checksum of a record, and content hashes. */
    class Hash
    {
    public:
      void
      add(const void *data, const std::size_t n)
      {
        const auto *b = static_cast<const unsigned char *>(data);
        for (std::size_t i = 0; i < n; ++i)
          h = (h ^ b[i]) * 1099511628211ull;
      }

      template <typename T>
      void
      add(const std::vector<T> &v)
      {
        add(v.data(), v.size() * sizeof(T));
      }

      std::uint64_t
      value() const
      {
        return h;
      }

      std::string
      hex() const
      {
        char s[17];
        std::snprintf(s, sizeof(s), "%016llx", (unsigned long long)h);
        return s;
      }

    private:
      std::uint64_t h = 1469598103934665603ull;
    };

    /** One record's values, in the order the checksum covers them. */
    struct Record
    {
      std::int32_t        point    = 0;
      std::int32_t        status   = 0; // SolveStatus, as a number
      double              force[3] = {0, 0, 0};
      double              stiffness[9];
      double              wall_time = 0;
      std::vector<double> solution, multipliers;
      /** The state's contact patch as bytes (patch_bytes()); none if the
       * state has no patch. */
      std::vector<char> patch;

      std::uint64_t
      checksum() const
      {
        Hash h;
        h.add(&point, sizeof(point));
        h.add(&status, sizeof(status));
        h.add(force, sizeof(force));
        h.add(stiffness, sizeof(stiffness));
        h.add(&wall_time, sizeof(wall_time));
        h.add(solution);
        h.add(multipliers);
        h.add(patch);
        return h.value();
      }
    };

    /** The store's datasets, one per field of a Record, in its order: a
     * record is row r of each of the first eight and of "patch" (where its
     * patch's bytes start in "patch_bytes", and how many), written before
     * the checksum. "patch_bytes" is one column of bytes, the patches one
     * after the other. */
    inline const char *const dataset_names[] = {"point",
                                                "status",
                                                "force",
                                                "stiffness",
                                                "wall_time",
                                                "solution",
                                                "multipliers",
                                                "checksum",
                                                "patch",
                                                "patch_bytes"};
    /** The datasets of a record's rows, and all of them. */
    constexpr unsigned int record_datasets = 9, n_datasets = 10;
    /** The datasets of a store that palpate wrote before patches were
     * stored: any of them makes a file a store. */
    constexpr unsigned int first_format_datasets = 8;

    /** Refuse the store @p store: throws InputError (entry State space /
     * Store) with @p problem and @p fix. */
    [[noreturn]] void
    store_error(const std::string &store,
                const std::string &problem,
                const std::string &fix);

    /**
     * Before HDF5 sees @p file: what keeps it from being a store this
     * process can open for @p writing (or reading), said as such, so that
     * a file that is fine but not writable is never called damaged.
     * Returns whether the file exists (a new one is created).
     */
    bool
    check_store_file(const std::string &file, const bool writing);

    /**
     * This process's hold on the lock of @p store (state_store_lock.cc):
     * the one it holds already, else a new one taken. Throws InputError if
     * the store has more than one name (hard links), another process
     * holds the lock, or the lock file cannot be made or locked.
     */
    std::shared_ptr<StoreLock::Held>
    acquire_lock(const std::string &store);

    /**
     * The file access properties of every store file: the latest format
     * (SWMR needs it), and HDF5's own file locking off. That lock cannot
     * serve: a SWMR writer drops it once the file is open, while a reader
     * holds its shared lock for as long as it has the file open, so that a
     * writer opening the store while a reader reads it would fail with
     * "Resource temporarily unavailable". One writer per store is the
     * StoreLock's job; readers need no lock (SWMR).
     */
    hid_t
    file_access();

    /** The system's error message if HDF5 failed in a system call (the
     * sec2 driver's "error message = '...'"), else "". */
    std::string
    hdf5_system_error();

    /**
     * What HDF5 said last, from its error stack: the system's error message
     * if a system call failed (for a failed write, "No space left on
     * device"), else the message at the stack's bottom, where the cause is;
     * "" if the stack is empty.
     */
    std::string
    hdf5_error();

    /** A write to the store failed: why. */
    struct WriteFailure
    {
      std::string reason;
    };
  } // namespace internal



  /** The lock as this process holds it: one per lock file, shared by
   * every StoreLock and writing StateStore of that store in the process. */
  struct StoreLock::Held
  {
    std::string        store, lock_file;
    int                fd  = -1;
    pid_t              pid = 0;
    mutable std::mutex mutex;
    std::string        failure;

    /** Remove the lock file (in the process that made it) and release the
     * lock. */
    ~Held();
  };



  struct StateStore::Impl
  {
    std::string            file;
    Access                 access = Access::write;
    hid_t                  h5     = -1;
    hid_t                  datasets[internal::n_datasets];
    hsize_t                n_solution = 0, n_multipliers = 0;
    hsize_t                rows = 0;
    std::set<unsigned int> stored; // points with an intact record
    // Whether the file was left open by a writer that did not finish.
    bool recovered = false;
    // Failure points that came before the first converged state, which
    // fixes the record sizes.
    std::vector<std::pair<unsigned int, State>> pending;
    // The writer's lock (Access::write).
    std::shared_ptr<StoreLock::Held> lock;
    // The first row this object appended; a failed write stops appending,
    // and `kept` is then what the file was read back to hold of ours.
    hsize_t      first_row = 0;
    bool         stopped   = false;
    unsigned int kept      = 0;
    // The descriptor reserve() takes room through.
    int reserve_fd = -1;

    /** No file open yet. */
    Impl()
    {
      std::fill(std::begin(datasets), std::end(datasets), hid_t(-1));
    }

    // Also when the constructor throws (a refused store): no HDF5 handle
    // stays open.
    ~Impl()
    {
      close_file();
    }

    /** Refuse this store: InputError with @p problem and @p fix. */
    [[noreturn]] void
    fail(const std::string &problem, const std::string &fix) const
    {
      internal::store_error(file, problem, fix);
    }

    /** The columns of dataset @p d (1 for scalars). */
    hsize_t
    columns(const unsigned int d) const
    {
      switch (d)
        {
          case 2:
            return 3;
          case 3:
            return 9;
          case 5:
            return n_solution;
          case 6:
            return n_multipliers;
          case 8:
            return 2;
          default:
            return 1;
        }
    }

    /** The HDF5 type of dataset @p d's values. */
    hid_t
    type(const unsigned int d) const
    {
      return d <= 1           ? H5T_NATIVE_INT32 :
             d == 7 || d == 8 ? H5T_NATIVE_UINT64 :
             d == 9           ? H5T_NATIVE_CHAR :
                                H5T_NATIVE_DOUBLE;
    }

    /** Close the file (errors ignored: after a failed write HDF5 may not
     * manage to flush what it still holds; what lands is read back). */
    void
    close_file();

    /**
     * Make the store with @p fingerprint and record sizes @p n_sol and
     * @p n_mult. Throws WriteFailure if the file system refuses.
     */
    void
    create(const StoreFingerprint &fingerprint,
           const hsize_t           n_sol,
           const hsize_t           n_mult);

    /** How many of a store's datasets the file @p f has; -1 if HDF5
     * cannot even look (its root group is damaged). */
    static int
    store_datasets(const hid_t f);

    /** Refuse an HDF5 file that has none of a store's datasets. */
    [[noreturn]] void
    not_a_store() const;

    /** Open the existing store as access says; InputError if HDF5 cannot
     * (the file was checked before: then it is damaged). */
    void
    open();

    /** open(): clear the mark "open for writing" that a killed writer left,
     * and open the file again with @p fapl and @p flags (h5 >= 0 if that
     * worked). */
    void
    reopen_after_dead_writer(const hid_t fapl, const unsigned int flags);

    /** open(): refuse the store HDF5 could not open: InputError saying a
     * system call failed (@p system), the file is not a store, or it is
     * damaged (HDF5's words: @p why). */
    [[noreturn]] void
    refuse_unopened(const std::string &why, const std::string &system) const;

    /** open(): open the datasets of the opened file, and read the record
     * sizes and the rows every dataset holds. */
    void
    open_datasets();

    /** The fingerprint's field @p name as the store recorded it, or "(not
     * recorded)"; InputError if HDF5 cannot read it. */
    std::string
    attribute(const std::string &name) const;

    /** Read row @p row of dataset @p d into @p data. */
    void
    read_row(const hsize_t row, const unsigned int d, void *data) const;

    /** Write row @p row of dataset @p d and flush it; false if HDF5 (the
     * file system) refused. */
    bool
    write_row(const hsize_t row, const unsigned int d, const void *data);

    /**
     * Make sure the file's blocks reach past HDF5's end of allocation by
     * four records (of @p patch_bytes of patch each) and 128 KiB: what one
     * more record allocates (its rows,
     * and the chunk index and metadata they add: pages of at most 1024
     * addresses, 8 KiB, for each of the 8 datasets) with a margin. Returns ""
     * on success, else why not. The blocks beyond the end of allocation stay as
     * zeros at the end of the file (HDF5 allows a file longer than it uses) and
     * are used by the next records.
     */
    std::string
    reserve(const std::size_t patch_bytes);

    /** Append @p bytes to "patch_bytes" (flushed); where they start, or
     * false if HDF5 (the file system) refused. */
    bool
    write_patch(const std::vector<char> &bytes, hsize_t &offset);

    /** Read @p size patch bytes from @p offset into @p bytes; false if the
     * file does not hold them (a record cut short). */
    bool
    read_patch(const hsize_t      offset,
               const hsize_t      size,
               std::vector<char> &bytes) const;

    /** The result of reading one record. */
    enum class Read
    {
      intact,
      damaged,
      incomplete
    };

    /** Read the record in row @p row into @p r, and check it. */
    Read
    read_record(const hsize_t row, internal::Record &r) const;

    /**
     * A write failed: stop appending. Close the file, open it again for
     * reading, and count what it keeps of this object's records; record
     * the failure with the lock and throw OutputError saying all that.
     */
    [[noreturn]] void
    stop(std::string reason);

    /** append(): the first converged state fixes the record sizes: close
     * the file and make the datasets again with @p n_sol and @p n_mult,
     * keeping the fingerprint (no row is in the file yet). */
    void
    make_record_datasets(const hsize_t n_sol, const hsize_t n_mult);

    // The first row of this object's records when the write failed (open()
    // in stop() moves first_row to the end).
    hsize_t first_row_before_stop = 0;
  };
} // namespace palpate

#endif
