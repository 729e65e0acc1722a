// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

#ifndef palpate_haptics_interaction_h
#define palpate_haptics_interaction_h

#include <palpate/base/utilities.h>
#include <palpate/haptics/force_interpolation.h>
#include <palpate/haptics/run_summary.h>

#include <array>
#include <iosfwd>
#include <memory>
#include <vector>

namespace palpate
{
  class HipChannel;
  class Mesh;
  class Scene;
  class StateCache;
  class StateGrid;
  struct EngineLoad;
  struct NodeSelection;

  namespace Parameters
  {
    struct AllParameters;
  }

  /**
   * palpate as a library for a haptics application that owns its device
   * loop (CHAI3D, OpenHaptics, a robot controller):
   *
   *   palpate::Interaction interaction(palpate::Scene::read("liver.prm"));
   *   interaction.attach();                          // start computing
   *   // in the device's 1 kHz callback:
   *   const auto f = interaction.force(position);    // never blocks
   *   ...
   *   interaction.detach();
   *
   * Positions are displacements of the active node from its rest position
   * (m, in the mesh's frame; a host maps its device frame onto it); forces
   * are what the device should render (N): the interpolation (State space
   * / Interpolation, a plug-in: haptics/interpolation.h) of the states at
   * the corners of the position's grid cell, clamped to
   * Haptics / Force limit and changing by at most Haptics / Maximum force
   * change per call. Where a corner is missing (not computed yet, a failure
   * point, outside the grid, detached) the force fades to zero at that
   * rate, or is held (a failure region, outside the grid: ForceHold), and
   * the event is counted and reported (poll_events(), summary()). An
   * interpolation that keeps the last complete cell's data answers
   * instead, wherever data are missing while in contact (contact patch:
   * the sphere against the surface and compliance last known there, zero
   * off it).
   *
   * force() may be called from exactly one thread at a time. It never
   * blocks, never allocates and never returns NaN. Everything else is for
   * the host's other threads; attach(), detach() and change_parameters()
   * may come from several of them (a live view's requests): they take
   * turns.
   */
  class Interaction
  {
  public:
    /** Set up the scene: mesh, nodes, state grid, cache, engine (which
     * builds its solvers). No thread runs yet. */
    explicit Interaction(const Scene &scene);

    ~Interaction();

    /** Contact: start computing the cloud around the HIP, where force()
     * last saw it (the rest position if force() was never called). */
    void
    attach();

    /** No contact: stop computing (running tasks finish); force() fades
     * to zero. Cached states stay. */
    void
    detach();

    /** Before a detach() on a stop signal: the running tasks give up at
     * their next Newton iteration instead of finishing
     * (PrecomputationEngine::abandon_running()). */
    void
    abandon_running();

    /** Whether the HIP is attached. */
    bool
    attached() const noexcept;

    /**
     * The force to render for the HIP at @p position (m, relative to the
     * active node's rest position). Real-time safe.
     */
    Utilities::Point3
    force(const Utilities::Point3 &position) noexcept;

    /**
     * The stiffness K = -df/dx (N/m, row-major: K[3 i + j] = -d f_i /
     * d x_j) of the force field at the last force() call's position:
     * the interpolated field's (continuous across cells with tricubic
     * Hermite interpolation), the held spring's where a force is held,
     * the last patches' where they answer, zero where none is rendered. For a
     * device that renders a local model f + K (x - x_last) between ticks. Call
     * from the thread that calls force(); real-time safe. (Not limited like the
     * force: a device that uses it must apply its own stiffness limit.)
     */
    const std::array<double, 9> &
    stiffness() const noexcept;

    /** The grid points whose states the haptic loop interpolated from
     * (the corners of the complete cells it visited), in grid order. Not
     * for the real-time side. */
    std::vector<unsigned int>
    used_points() const;

    /** Whether the last force() call found all 8 corners of its cell. */
    bool
    data_complete() const noexcept;

    /**
     * Why the last force() call found no force (MissingCause::none if it
     * did): not computed yet (the force fades to zero), a failure region
     * or outside the state space (the force is held, see ForceHold).
     */
    MissingCause
    missing_cause() const noexcept;

    /** With State space / Store: what was loaded from the store and
     * appended to it, in one line; "" without a store. */
    std::string
    store_report() const;

    /** With a store: whether a write to it failed (a full disk; the store
     * kept what store_report() says). */
    bool
    store_write_failed() const;

    /** With a store: the grid points it holds (loaded and appended). */
    unsigned int
    stored_points() const;

    /** Whether the cloud around the attach position has been computed
     * (latched: stays true once it was). */
    bool
    initial_cloud_complete() const;

    /** How many of the 27 grid points around the rest position (the
     * corners of every cell that touches it) are neither computed nor
     * failure points yet (Haptics / Trajectory / Start = after rest
     * neighbourhood waits for 0). */
    unsigned int
    rest_neighbourhood_missing() const;

    /** The number of grid points in the cloud around the rest position:
     * the states computed before the motion starts. */
    unsigned int
    initial_cloud_size() const noexcept;

    /** The number of those grid points that are neither computed nor
     * failure points now: once the engine is idle, the points it could
     * not reach (every way to them from rest passes failure points). */
    unsigned int
    initial_cloud_missing() const;

    /**
     * Change the material, the fixed nodes, the active node, the effects or
     * the solver settings: only while detached (std::logic_error
     * otherwise). Every cached state becomes invalid; none is interpolated
     * again. The mesh, state space, engine, scheduler and force filter
     * cannot change (std::invalid_argument naming the subsection); bad
     * parameters (an InputError, e.g. a region that selects no fixed node)
     * leave the interaction as it was.
     */
    void
    change_parameters(const Parameters::AllParameters &parameters);

    /**
     * The checks change_parameters() makes, changing nothing, while
     * attached too (not while change_parameters() runs): throws what it
     * would. A host checks first so that its view goes on meanwhile: a
     * sphere whose radius is refused tries the radius it offers by static
     * solves, seconds to minutes (the live view froze 12.8 s so).
     */
    void
    check_parameters(const Parameters::AllParameters &parameters) const;

    /** Print one line per missing-data event since the last call; returns
     * how many. For a non-real-time thread. */
    unsigned int
    poll_events(std::ostream &log);

    /** What the engine is doing now: workers busy, tasks queued, the points
     * being computed. For a non-real-time thread (a live view). */
    EngineLoad
    engine_load() const;

    /** Whether the engine has no worker left (every solver server lost):
     * no state will come any more. Real-time safe. */
    bool
    engine_lost() const noexcept;

    /** What happened so far (engine and haptic side; no loop timing). */
    RunSummary
    summary() const;

    /** The scene, mesh, nodes, grid, cache and HIP channel in use. */
    const Scene &
    scene() const;
    const Mesh &
    mesh() const;
    const NodeSelection &
    nodes() const;
    const StateGrid &
    grid() const;
    const StateCache &
    cache() const;
    const HipChannel &
    hip() const;

  private:
    struct Impl;
    std::unique_ptr<Impl> impl;
  };
} // namespace palpate

#endif
