// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

#include <palpate/base/environment.h>

#include <deal.II/base/multithread_info.h>

#include <dlfcn.h>
#include <mpi.h>
#include <pthread.h>
#include <signal.h>

#include <atomic>
#include <cstdlib>
#include <string>

namespace palpate
{
  namespace
  {
    bool        thread_multiple = false;
    std::string blas_kernels;

    /**
     * OpenBLAS picks its kernels by the processor's model number when it is
     * loaded. A processor newer than the library (Debian 12's OpenBLAS
     * 0.3.21 on a Sapphire Rapids, this project's CI machine) is unknown to
     * it and gets the generic Prescott (SSE3) kernels: every MUMPS
     * factorisation of a liver then runs 2.7x slower (1,607 nodes: 113 ms
     * instead of 42; doc/benchmarks/organ-speed.md), the dense kernels of
     * the fronts being most of it. Where the library fell back so and the
     * processor has AVX-512 (or AVX2 with FMA), switch to the SkylakeX (or
     * Haswell) kernels, as OPENBLAS_CORETYPE would at start-up: the
     * library's own dynamic dispatch runs again with that variable set.
     * This happens before anything calls the BLAS (no thread of palpate's
     * exists yet). A user's own OPENBLAS_CORETYPE is always kept, and a
     * BLAS other than OpenBLAS is left alone (the symbols are looked up
     * at run time).
     */
    void
    select_blas_kernels()
    {
      using Name = char *(*)();
      using Call = void (*)();
      const auto corename =
        reinterpret_cast<Name>(dlsym(RTLD_DEFAULT, "openblas_get_corename"));
      if (corename == nullptr)
        return; // not OpenBLAS
      blas_kernels = std::string("OpenBLAS, ") + corename() + " kernels";
      if (std::getenv("OPENBLAS_CORETYPE") != nullptr)
        {
          blas_kernels += " (OPENBLAS_CORETYPE)";
          return;
        }
      const auto quit =
        reinterpret_cast<Call>(dlsym(RTLD_DEFAULT, "gotoblas_dynamic_quit"));
      const auto init =
        reinterpret_cast<Call>(dlsym(RTLD_DEFAULT, "gotoblas_dynamic_init"));
      if (quit == nullptr || init == nullptr ||
          std::string(corename()) != "Prescott")
        return; // a build without dynamic dispatch, or a known processor
      __builtin_cpu_init();
      const char *better =
        __builtin_cpu_supports("avx512f") &&
            __builtin_cpu_supports("avx512dq") ?
          "SkylakeX" :
        __builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma") ?
          "Haswell" :
          nullptr;
      if (better == nullptr)
        return; // a processor for which Prescott is right
      setenv("OPENBLAS_CORETYPE", better, 1);
      quit();
      init();
      blas_kernels = std::string("OpenBLAS, ") + corename() +
                     " kernels (chosen by palpate: the library took this "
                     "processor for a Prescott)";
    }
  } // namespace



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
    select_blas_kernels();
    using SetThreads = void (*)(int);
    if (const auto set = reinterpret_cast<SetThreads>(
          dlsym(RTLD_DEFAULT, "openblas_set_num_threads")))
      set(1);

    int initialized = 0;
    MPI_Initialized(&initialized);
    if (!initialized)
      {
        // A stop signal during MPI's start-up (a singleton starts Open
        // MPI's orted and talks to it) would kill palpate in the middle of
        // that talk, and orted would print "ORTE_ERROR_LOG: Broken pipe".
        // Held until the start-up is done, the signal then ends palpate,
        // with orted no longer waiting for it.
        sigset_t stops, before;
        sigemptyset(&stops);
        sigaddset(&stops, SIGINT);
        sigaddset(&stops, SIGTERM);
        sigaddset(&stops, SIGHUP);
        pthread_sigmask(SIG_BLOCK, &stops, &before);
        int provided = 0;
        MPI_Init_thread(&argc, &argv, MPI_THREAD_MULTIPLE, &provided);
        pthread_sigmask(SIG_SETMASK, &before, nullptr);
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



  const std::string &
  Environment::blas()
  {
    return blas_kernels;
  }



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
