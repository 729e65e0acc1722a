// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

#include <palpate/base/environment.h>

#include <deal.II/base/multithread_info.h>

#include <dlfcn.h>
#include <mpi.h>

#include <atomic>
#include <cstdlib>

namespace palpate
{
  namespace
  {
    bool thread_multiple = false;
  }



  Environment::Environment(int &argc, char **&argv)
    : finalize_mpi(false)
  {
    // One thread per BLAS/OpenMP call: palpate decides how many threads run
    // (solver workers, assembly threads), and nested thread pools inside a
    // direct solver would only compete with them for the cores.
    setenv("OMP_NUM_THREADS", "1", 0);
    setenv("OPENBLAS_NUM_THREADS", "1", 0);
    // The variable is read when OpenBLAS is loaded, which happened before
    // main(): tell the library itself. One BLAS thread per caller is also
    // what makes OpenBLAS safe to call from two solver workers at once:
    // the pthread build is (with one thread per call), the serial build
    // is not (it computes wrong results), which is why palpate installs
    // libopenblas0-pthread. Looked up at run time: another BLAS may be in
    // use, and then there is nothing to set.
    using SetThreads = void (*)(int);
    if (const auto set = reinterpret_cast<SetThreads>(
          dlsym(RTLD_DEFAULT, "openblas_set_num_threads")))
      set(1);

    int initialized = 0;
    MPI_Initialized(&initialized);
    if (!initialized)
      {
        int provided = 0;
        MPI_Init_thread(&argc, &argv, MPI_THREAD_MULTIPLE, &provided);
        thread_multiple = (provided >= MPI_THREAD_MULTIPLE);
        finalize_mpi    = true;
      }
    else
      {
        int provided = 0;
        MPI_Query_thread(&provided);
        thread_multiple = (provided >= MPI_THREAD_MULTIPLE);
      }

    // deal.II's own task-based parallelism (used by a few library calls
    // during set-up) gets the cores too; palpate's assembly uses explicit
    // task arenas with the scene's thread count.
    dealii::MultithreadInfo::set_thread_limit();
  }



  namespace
  {
    std::atomic<bool> a_peer_was_lost{false};
  } // namespace



  void
  Environment::peer_lost() noexcept
  {
    a_peer_was_lost = true;
  }



  Environment::~Environment()
  {
    int finalized = 0;
    MPI_Finalized(&finalized);
    if (!finalize_mpi || finalized)
      return;
    if (a_peer_was_lost)
      // Looked up at run time: only Open MPI has it, and it needs no
      // link-time dependency on Open MPI's internals.
      if (auto *asynchronous =
            static_cast<bool *>(dlsym(RTLD_DEFAULT, "ompi_async_mpi_finalize")))
        *asynchronous = true;
    MPI_Finalize();
  }



  bool
  Environment::mpi_thread_multiple()
  {
    return thread_multiple;
  }
} // namespace palpate
