// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

#include <palpate/hyperelastic/mumps_library.h>

#include <dlfcn.h>
#include <mpi.h>

#include <atomic>
#include <string>
#include <vector>

namespace palpate
{
  struct MumpsLibrary::Copy
  {
    void (*dmumps)(DMUMPS_STRUC_C *) = nullptr;
    void (*smumps)(SMUMPS_STRUC_C *) = nullptr;
    std::mutex mutex;
    bool       is_private = false;
    bool       lent       = false;
  };



  namespace
  {
    /** The sequential library of the MUMPS version whose header palpate
     * is compiled with: the structures passed to it are that header's. */
    std::string
    sequential_library(const char *precision)
    {
      const std::string version = MUMPS_VERSION;
      const std::string major_minor =
        version.substr(0, version.find('.', version.find('.') + 1));
      return std::string("lib") + precision + "mumps_seq-" + major_minor +
             ".so";
    }

    struct Pool
    {
      std::mutex                                       mutex;
      std::vector<std::unique_ptr<MumpsLibrary::Copy>> copies;
      MumpsLibrary::Copy                               shared;
      /** Why the last copy could not be loaded; empty if none failed. */
      std::string               failure;
      std::atomic<unsigned int> limit{8};

      Pool()
      {
        shared.dmumps = dmumps_c;
        shared.smumps = smumps_c;
      }

      /** A new private copy, or nullptr (with failure set). */
      std::unique_ptr<MumpsLibrary::Copy>
      load()
      {
        const std::string dname = sequential_library("d"),
                          sname = sequential_library("s");
        void *d = dlmopen(LM_ID_NEWLM, dname.c_str(), RTLD_NOW | RTLD_LOCAL);
        if (d == nullptr)
          {
            failure = dlerror();
            return nullptr;
          }
        // Single precision in the same namespace: it shares the copy's
        // common module (mumps_common_seq), which one lease calls at a
        // time anyway.
        Lmid_t namespace_id;
        void  *s =
          dlinfo(d, RTLD_DI_LMID, &namespace_id) == 0 ?
             dlmopen(namespace_id, sname.c_str(), RTLD_NOW | RTLD_LOCAL) :
             nullptr;
        auto copy = std::make_unique<MumpsLibrary::Copy>();
        if (s != nullptr)
          {
            copy->dmumps = reinterpret_cast<void (*)(DMUMPS_STRUC_C *)>(
              dlsym(d, "dmumps_c"));
            copy->smumps = reinterpret_cast<void (*)(SMUMPS_STRUC_C *)>(
              dlsym(s, "smumps_c"));
          }
        if (copy->dmumps == nullptr || copy->smumps == nullptr)
          {
            failure = s == nullptr ? std::string(dlerror()) :
                                     "no dmumps_c or smumps_c in " + dname;
            // The namespace stays: glibc cannot always unload one.
            return nullptr;
          }
        // The copy's OpenBLAS read OPENBLAS_NUM_THREADS when it was loaded
        // (Environment sets 1); a process without an Environment would
        // otherwise give every copy a pool of BLAS threads competing with
        // palpate's own.
        using SetThreads = void (*)(int);
        if (const auto set = reinterpret_cast<SetThreads>(
              dlsym(d, "openblas_set_num_threads")))
          set(1);
        copy->is_private = true;
        return copy;
      }
    };

    Pool &
    pool()
    {
      static Pool p;
      return p;
    }
  } // namespace



  MumpsLibrary::Lease::Lease()
    : copy(&pool().shared)
  {}



  MumpsLibrary::Lease::~Lease()
  {
    if (copy != nullptr && copy->is_private)
      {
        std::lock_guard<std::mutex> guard(pool().mutex);
        copy->lent = false;
      }
  }



  MumpsLibrary::Lease::Lease(Lease &&other) noexcept
    : copy(other.copy)
  {
    other.copy = nullptr;
  }



  MumpsLibrary::Lease &
  MumpsLibrary::Lease::operator=(Lease &&other) noexcept
  {
    if (this != &other)
      {
        Lease old(std::move(*this));
        copy       = other.copy;
        other.copy = nullptr;
      }
    return *this;
  }



  std::unique_lock<std::mutex>
  MumpsLibrary::Lease::lock() const
  {
    return std::unique_lock<std::mutex>(copy->mutex);
  }



  void
  MumpsLibrary::Lease::call(DMUMPS_STRUC_C *id) const
  {
    copy->dmumps(id);
  }



  void
  MumpsLibrary::Lease::call(SMUMPS_STRUC_C *id) const
  {
    copy->smumps(id);
  }



  bool
  MumpsLibrary::Lease::is_private() const
  {
    return copy->is_private;
  }



  int
  MumpsLibrary::Lease::fortran_communicator() const
  {
    // The sequential library's MPI is a stub that ignores the
    // communicator; the linked (parallel) one runs on this process alone.
    return copy->is_private ? -987654 : MPI_Comm_c2f(MPI_COMM_SELF);
  }



  MumpsLibrary::Lease
  MumpsLibrary::acquire()
  {
    Pool                       &p = pool();
    std::lock_guard<std::mutex> guard(p.mutex);
    Lease                       lease;
    unsigned int                lent = 0;
    for (const auto &c : p.copies)
      lent += c->lent;
    if (lent >= p.limit)
      return lease;
    for (const auto &c : p.copies)
      if (!c->lent)
        {
          c->lent    = true;
          lease.copy = c.get();
          return lease;
        }
    if (p.copies.size() < p.limit && p.failure.empty())
      if (auto c = p.load())
        {
          c->lent    = true;
          lease.copy = c.get();
          p.copies.push_back(std::move(c));
        }
    return lease;
  }



  std::mutex &
  MumpsLibrary::shared_lock()
  {
    return pool().shared.mutex;
  }



  unsigned int
  MumpsLibrary::max_private_copies()
  {
    return pool().limit;
  }



  void
  MumpsLibrary::set_max_private_copies(const unsigned int n)
  {
    pool().limit = n;
  }



  std::string
  MumpsLibrary::description()
  {
    Pool                       &p = pool();
    std::lock_guard<std::mutex> guard(p.mutex);
    if (!p.failure.empty() && p.copies.empty())
      return "one MUMPS for the process, one call at a time (" +
             sequential_library("d") + " not loaded: " + p.failure + ")";
    if (p.limit == 0)
      return "one MUMPS for the process, one call at a time (private "
             "copies switched off)";
    return "a private MUMPS copy per solver, " +
           std::to_string(p.copies.size()) + " loaded, at most " +
           std::to_string(p.limit) + " (" + sequential_library("d") + ")";
  }
} // namespace palpate
