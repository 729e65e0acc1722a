// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

#ifndef palpate_engine_engine_h
#define palpate_engine_engine_h

#include <palpate/base/utilities.h>
#include <palpate/hyperelastic/state.h>

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

namespace palpate
{
  class HipChannel;
  class Mesh;
  class Scene;
  class StateCache;
  class StateGrid;
  struct NodeSelection;

  namespace Parameters
  {
    struct AllParameters;
  }

  /** What happened to one computed task. */
  struct TaskRecord
  {
    unsigned int target, source;
    /** Seconds since the engine started. */
    double       start, duration;
    bool         converged;
    SolveStatus  status;
    unsigned int newton_iterations;
    unsigned int worker;
  };

  /** The engine's counters at some moment. */
  struct EngineStatistics
  {
    unsigned int computed  = 0; // converged states published
    unsigned int failed    = 0; // failure points
    unsigned int dropped   = 0; // queued tasks that fell out of the cloud
    unsigned int cancelled = 0; // running states the HIP moved away from
    unsigned int preempted = 0; // running states given up for path corners
    unsigned int discarded = 0; // results for a generation that changed
    double       busy_time = 0; // seconds workers spent solving
    /** Solves that threw (out of memory, a library error): counted as
     * failure points too; the last message. */
    unsigned int            errors = 0;
    std::string             last_error;
    std::vector<TaskRecord> tasks;

    /** The MPI engine's traffic (zero for the threaded engine): messages
     * and bytes sent by all ranks. */
    std::uint64_t messages = 0, bytes = 0;
    /** Tasks whose source the chosen server already held (no transfer),
     * and tasks that fetched their source from another server. */
    unsigned int local_sources = 0, fetched_sources = 0;
    /** Whole states sent to the client (lazy transfer: only those its
     * shape output asked for), and seconds from "needed" to "arrived" of
     * each transfer (server-to-server and to the client). */
    unsigned int        states_to_client = 0;
    std::vector<double> transfer_seconds;
    /** Solver servers lost during the run, one sentence each (which, when,
     * why, what was re-planned). */
    std::vector<std::string> lost_servers;
  };

  /** What the engine is doing now, for a live view (cheap: no task log). */
  struct EngineLoad
  {
    /** Solver threads or servers, and how many are solving now. */
    unsigned int workers = 0, busy = 0;
    /** Tasks planned and waiting for a worker (the MPI engine dispatches
     * straight to free servers: 0). */
    unsigned int queued = 0;
    /** States and failure points so far, and the seconds workers spent
     * solving (for a rate and a busy fraction between two calls). */
    unsigned int computed = 0, failed = 0;
    double       busy_time = 0;
    /** The grid points being computed now. */
    std::vector<unsigned int> in_progress;
  };

  /**
   * The on-line precomputation engine as the haptic side sees it: it keeps
   * the cloud of states around the HIP computed and publishes them in the
   * StateCache. The threaded engine runs solver workers in this process; an
   * MPI engine with solver servers implements the same interface.
   */
  class PrecomputationEngine
  {
  public:
    virtual ~PrecomputationEngine() = default;

    /**
     * Start computing (attach): publish the rest state, then keep the cloud
     * around the HIP read from the channel computed.
     */
    virtual void
    start() = 0;

    /** Stop (detach): no new tasks; running ones finish. Blocks until then. */
    virtual void
    stop() = 0;

    /**
     * Give up the states being computed at their next Newton iteration,
     * so that the stop() after it returns within an iteration: on a stop
     * signal the user wants the run to end, not the states in flight (in
     * the graded liver's initial cloud, waiting for them takes seconds).
     * Nothing of them is kept. By default they finish.
     */
    virtual void
    abandon_running()
    {}

    /** Whether start() has been called without stop(). */
    virtual bool
    running() const = 0;

    /**
     * Use new parameters (material, fixed nodes, active node): only while
     * stopped. The cache is invalidated; nothing computed before is used.
     */
    virtual void
    change_parameters(const Parameters::AllParameters &parameters) = 0;

    /** Whether nothing is under way and nothing in the cloud is left to do. */
    virtual bool
    idle() const = 0;

    /** A copy of the counters and the task log. */
    virtual EngineStatistics
    statistics() const = 0;

    /** What it is doing now (for a non-real-time thread). */
    virtual EngineLoad
    load() const = 0;

    /** How many states can be computed at once (solver threads or
     * servers). */
    virtual unsigned int
    n_workers() const = 0;

    /**
     * Whether a worker is in trouble: a solver server has been silent for
     * longer than its heartbeats allow (0.3 s), or one was lost in the
     * last 3 s and its work is being re-planned. States missing then are
     * late for a reason that is not the hand's speed, and may stay missing
     * for the Server timeout: the haptic side holds the force from the
     * last complete cell instead of letting it fade (issue 26: a stopped
     * server let the force fade to zero for 10 s). Real-time safe (an
     * atomic read). The threaded engine's workers cannot vanish: false.
     */
    virtual bool
    degraded() const noexcept
    {
      return false;
    }

    /**
     * Whether every worker is gone: all solver servers were lost, so no
     * state the HIP needs will ever come. The interaction then ends
     * through its normal path (summary, outputs, exit status 5) instead of
     * moving on an empty or frozen cloud (issue 26: a 0.1 s Task timeout
     * lost both servers during the initial cloud and the motion started
     * anyway). Real-time safe. The threaded engine's workers cannot
     * vanish: false.
     */
    virtual bool
    lost_every_worker() const noexcept
    {
      return false;
    }

    /** A description, e.g. "2 solver threads". */
    virtual std::string
    description() const = 0;

    /**
     * The engine a scene asks for (Engine / Type). Throws
     * NotAvailableError for engines this version does not have.
     */
    static std::unique_ptr<PrecomputationEngine>
    create(const Scene         &scene,
           const Mesh          &mesh,
           const NodeSelection &nodes,
           const StateGrid     &grid,
           StateCache          &cache,
           const HipChannel    &hip);
  };
} // namespace palpate

#endif
