// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

#ifndef palpate_engine_mpi_engine_h
#define palpate_engine_mpi_engine_h

#include <palpate/engine/engine.h>
#include <palpate/scene/parameters.h>

#include <memory>

namespace palpate
{
  /**
   * The paper's distributed engine: `mpirun -np N palpate scene.prm` with
   * Engine / Type = mpi. Rank 0, the client, runs the haptic side and this
   * engine; ranks 1..N-1 are solver servers (run_solver_server()), each a
   * solver thread with its own StateSolver (and so its own MUMPS, which is
   * why processes scale where threads cannot) plus a communicator.
   *
   * On the client one communicator thread does all of the engine's MPI
   * traffic and its scheduling: it receives results as they come and
   * plans again at once (and at Scheduler / Rate otherwise), gives each
   * free server one task at a time, preferring a server that already
   * holds the task's source, and tells it which server holds the source
   * when it does not.
   *
   * Lazy state transfer: a result carries the force only; it goes into
   * the cache at once (the haptic side never waits for a vector). Whole
   * states stay on the server that computed them (within Engine / Memory
   * budget per server; a server that drops one says so) and travel only
   * when needed: to another server whose task starts from it, or to the
   * client when its shape output asks the cache for it.
   *
   * A server that stops sending (heartbeats every 0.1 s) for Engine /
   * Server timeout seconds, or whose task runs past Engine / Task
   * timeout, is declared lost: no more work goes to it, its task is
   * planned again, the states only it held are recomputed when needed,
   * and statistics() says which server was lost and why.
   */
  class MpiEngine : public PrecomputationEngine
  {
  public:
    /** Wait for every server to report ready (throws if one cannot set
     * up, or there are no servers). */
    MpiEngine(const Parameters::AllParameters &parameters,
              const StateGrid                 &grid,
              StateCache                      &cache,
              const HipChannel                &hip);

    /** Stops, and shuts the servers down. */
    ~MpiEngine() override;

    void
    start() override;

    void
    stop() override;

    /** Cancels every task on the servers (Kind::cancel): a server gives a
     * running solve up at its next Newton iteration. */
    void
    abandon_running() override;

    bool
    running() const override;

    /** Not available yet under MPI (throws NotAvailableError). */
    void
    change_parameters(const Parameters::AllParameters &parameters) override;

    bool
    idle() const override;

    EngineStatistics
    statistics() const override;

    EngineLoad
    load() const override;

    unsigned int
    n_workers() const override;

    bool
    degraded() const noexcept override;

    bool
    lost_every_worker() const noexcept override;

    std::string
    description() const override;

  private:
    struct Impl;
    std::unique_ptr<Impl> impl;
  };

  /**
   * Test hooks of a solver server (fault injection).
   */
  struct ServerFaults
  {
    /** After this many tasks received, the server kills its own process
     * (SIGKILL) as a crashed machine would; 0: never. */
    unsigned int die_after_tasks = 0;
    /** After this many tasks received, the server stops its own process
     * (SIGSTOP) as a frozen machine would, and a child process resumes it
     * (SIGCONT) @p pause_seconds later; 0: never. With pause_seconds = 0
     * it stays stopped until another process sends it SIGCONT. */
    unsigned int pause_after_tasks = 0;
    double       pause_seconds     = 0;
  };

  /**
   * A solver server (ranks 1..N-1 of an MPI run): set up the solver for
   * @p scene, then compute what the client asks until it says shutdown.
   * Returns 0; 1 if the solver could not be set up (the client reports
   * why); 2 if the client was lost: it sent nothing (it sends a heartbeat
   * every 0.1 s) for Engine / Server timeout, or nothing at all within
   * 600 s of this server's "ready" (a client still setting up). The server
   * then says so on standard error and ends: a killed client must not
   * leave its servers computing for ever under mpirun --enable-recovery.
   */
  int
  run_solver_server(const Scene         &scene,
                    const Mesh          &mesh,
                    const NodeSelection &nodes,
                    const ServerFaults  &faults = ServerFaults());

  /**
   * On the client: tell every server to end, if no MpiEngine did (an
   * error before the engine was built). Harmless when there are none.
   */
  void
  release_solver_servers();

  /** The rank of this process and the number of ranks (0 and 1 without
   * mpirun). */
  int
  mpi_rank();
  int
  mpi_size();
} // namespace palpate

#endif
