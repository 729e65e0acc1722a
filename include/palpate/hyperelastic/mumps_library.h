// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

#ifndef palpate_hyperelastic_mumps_library_h
#define palpate_hyperelastic_mumps_library_h

#include <dmumps_c.h>
#include <smumps_c.h>

#include <algorithm>
#include <memory>
#include <mutex>
#include <string>

namespace palpate
{
  /**
   * A copy of the MUMPS library for one solver at a time.
   *
   * MUMPS keeps state during a call in Fortran module variables, shared
   * by every instance in the library: the load-balancing module of a
   * factorisation (DMUMPS_LOAD_INIT), the communication buffers of a
   * solve (DMUMPS_BUF_ALLOC_CB in the solve driver), the pointers to the
   * front data. Two threads that call one copy of the library at the same
   * time corrupt each other even with separate instances, so one copy
   * serves one call at a time.
   *
   * A private lease is a copy of Debian's sequential MUMPS
   * (libmumps-seq) loaded into a link-map namespace of its own (dlmopen):
   * its module variables, BLAS and C runtime are its own, so solvers
   * holding different private leases factorise and solve at the same
   * time. Only the calls go through it; matrices and vectors stay the
   * caller's (MUMPS frees nothing of ours, we free nothing of its).
   *
   * Where no copy can be loaded (the sequential library is not installed,
   * or the C library has no namespace or static TLS left for another),
   * the lease is the MUMPS linked into palpate, shared by every such
   * lease under one lock: correct, but one call at a time in the process.
   * Private copies are loaded when first wanted, at most
   * max_private_copies(), and a released one is lent again.
   */
  class MumpsLibrary
  {
  public:
    struct Copy;

    /** A copy of the library, held until destroyed. Move-only. */
    class Lease
    {
    public:
      Lease();
      ~Lease();
      Lease(Lease &&other) noexcept;
      Lease &
      operator=(Lease &&other) noexcept;

      /** Hold while calling: uncontended for a private copy. */
      std::unique_lock<std::mutex>
      lock() const;

      void
      call(DMUMPS_STRUC_C *id) const;
      void
      call(SMUMPS_STRUC_C *id) const;

      /** Whether the copy is this lease's alone. */
      bool
      is_private() const;

      /** MUMPS's COMM_FORTRAN for an instance made through this lease. */
      int
      fortran_communicator() const;

      /**
       * A new symmetric (LDL^T, SYM = 2) instance in @p id (JOB = -1), on
       * this process alone, printing nothing. MUMPS reports a failure
       * here (-13: no workspace; a communicator it cannot use) only in
       * INFOG(1) and INFO(1), and everything after would work on a broken
       * instance: false, and @p id's codes say why. The caller holds
       * lock().
       */
      template <typename Struct>
      bool
      initialize(Struct &id) const
      {
        id.job          = -1;
        id.par          = 1;
        id.sym          = 2;
        id.comm_fortran = fortran_communicator();
        call(&id);
        if (std::min(id.infog[0], id.info[0]) < 0)
          return false;
        id.icntl[0]  = -1; // no error messages on a stream
        id.icntl[1]  = -1; // no diagnostics
        id.icntl[2]  = -1; // no global information
        id.icntl[3]  = 0;  // print nothing
        id.icntl[13] = 40; // ICNTL(14): workspace margin, %
        return true;
      }

      /**
       * The numerical factorisation (JOB = 2) of @p id, retried with the
       * workspace margin ICNTL(14) doubled, at most five times, where a
       * workspace was too small (INFOG(1) = -8, -9, -17, -20: many delayed
       * pivots). Whether INFOG(1) >= 0 after it. The caller holds lock().
       */
      template <typename Struct>
      bool
      factorize(Struct &id) const
      {
        const auto margin = id.icntl[13];
        for (unsigned int attempt = 0; attempt < 5; ++attempt)
          {
            id.job = 2;
            call(&id);
            const int e = id.infog[0];
            if (e != -8 && e != -9 && e != -17 && e != -20)
              break;
            id.icntl[13] *= 2;
          }
        id.icntl[13] = margin;
        return id.infog[0] >= 0;
      }

    private:
      friend class MumpsLibrary;
      Copy *copy;
    };

    /** A private copy if one is free or can be loaded, else the shared
     * one. Thread-safe. */
    static Lease
    acquire();

    /** The lock of the shared (linked) copy, for code that calls MUMPS
     * other than through a Lease (Trilinos' Amesos_Mumps). */
    static std::mutex &
    shared_lock();

    /** The most private copies a process loads (each takes a namespace,
     * of which glibc has 16, and static TLS). */
    static unsigned int
    max_private_copies();

    /** Change that limit for leases acquired from now on (0: every lease
     * the shared copy, as a reference to measure against). */
    static void
    set_max_private_copies(unsigned int n);

    /** What the process uses, for a run's report: "N private copies
     * (libmumps-seq)" or why the shared one. */
    static std::string
    description();
  };
} // namespace palpate

#endif
