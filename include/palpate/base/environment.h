// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

#ifndef palpate_base_environment_h
#define palpate_base_environment_h

#include <string>

namespace palpate
{
  /**
   * Process-wide set-up that every palpate program (the application, the
   * tests, the benchmarks) creates first in main() and keeps alive until it
   * returns.
   *
   * It initialises MPI with MPI_THREAD_MULTIPLE (the direct solvers are MPI
   * libraries, and solver workers call them from several threads at once),
   * and it stops the BLAS and OpenMP libraries from starting threads of
   * their own, so that the number of threads palpate uses is the number the
   * scene asks for. MPI is finalised when the object is destroyed.
   */
  class Environment
  {
  public:
    /** Initialise MPI (if nobody did yet) and the thread settings. */
    Environment(int &argc, char **&argv);

    /** Finalise MPI if this object initialised it. */
    ~Environment();

    Environment(const Environment &) = delete;
    Environment &
    operator=(const Environment &) = delete;

    /** Whether MPI provides MPI_THREAD_MULTIPLE in this process. */
    static bool
    mpi_thread_multiple();

    /**
     * The BLAS in use and its kernels, e.g. "OpenBLAS, SkylakeX kernels";
     * empty for a BLAS other than OpenBLAS. Where OpenBLAS took a newer
     * processor than it knows for a Prescott (generic SSE3 kernels, 2.7x
     * slower factorisations), the constructor switched it to the kernels
     * the processor can run, and this says so.
     */
    static const std::string &
    blas();

    /**
     * A rank of MPI_COMM_WORLD died (a lost solver server): MPI_Finalize
     * must not wait for it. Open MPI's finalize ends with a fence over
     * every process, which a dead one never joins: the survivors of
     * `mpirun --enable-recovery` hung there, now and then, after the run
     * was over. With a peer lost, finalize is asynchronous (Open MPI's
     * ompi_async_mpi_finalize; a no-op elsewhere).
     */
    static void
    peer_lost() noexcept;

  private:
    bool finalize_mpi;
  };
} // namespace palpate

#endif
