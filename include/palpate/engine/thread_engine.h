// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

#ifndef palpate_engine_thread_engine_h
#define palpate_engine_thread_engine_h

#include <palpate/engine/engine.h>
#include <palpate/scene/parameters.h>

#include <memory>

namespace palpate
{
  /**
   * Faults a test can inject into a ThreadEngine, to check that each thread
   * reports what goes wrong and shuts down cleanly instead of taking the
   * process down. The default injects nothing.
   */
  struct EngineFaults
  {
    /** The scheduler throws at this plan (counting from 1); 0: never. */
    unsigned int scheduler_throws_at_plan = 0;
    /** Every worker throws in every task (as if out of memory). */
    bool workers_throw = false;
  };

  /**
   * The precomputation engine on one machine: a scheduler thread (at
   * Scheduler / Rate) plans tasks with the Scheduler policy into a small
   * queue, rebuilt at every tick (tasks that left the cloud are dropped);
   * solver workers, each with its own StateSolver, take tasks from the
   * queue, compute the state from its source, and publish it (or the
   * failure point) in the cache. Workers run at a lower scheduling
   * priority (nice 10) than the haptic thread.
   */
  class ThreadEngine : public PrecomputationEngine
  {
  public:
    ThreadEngine(const Mesh                      &mesh,
                 const NodeSelection             &nodes,
                 const Parameters::AllParameters &parameters,
                 const StateGrid                 &grid,
                 StateCache                      &cache,
                 const HipChannel                &hip,
                 const EngineFaults              &faults = EngineFaults());

    ~ThreadEngine() override;

    void
    start() override;

    void
    stop() override;

    void
    abandon_running() override;

    bool
    running() const override;

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

    std::string
    description() const override;

  private:
    struct Impl;
    std::unique_ptr<Impl> impl;
  };
} // namespace palpate

#endif
