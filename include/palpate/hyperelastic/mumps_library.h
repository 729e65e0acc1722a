// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

#ifndef palpate_hyperelastic_mumps_library_h
#define palpate_hyperelastic_mumps_library_h

#include <dmumps_c.h>
#include <smumps_c.h>

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
