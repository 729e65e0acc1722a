// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

#ifndef palpate_state_space_state_store_h
#define palpate_state_space_state_store_h

#include <palpate/hyperelastic/state.h>

#include <memory>
#include <string>
#include <utility>
#include <vector>

namespace palpate
{
  class Mesh;
  class NodeSelection;
  class Scene;
  class StateCache;
  class StateGrid;

  /**
   * What a stored state depends on: the physics and the grid. A store whose
   * fingerprint differs from the scene's in any field is refused, naming
   * the field: a stale state is never used.
   */
  struct StoreFingerprint
  {
    /** (field, value) pairs, e.g. ("material", "Mooney-Rivlin: C01 = ..."). */
    std::vector<std::pair<std::string, std::string>> fields;

    /** The fingerprint of @p scene on @p mesh with @p nodes: mesh hash,
     * material and its constants, fixed nodes, active node, element and
     * quadrature, grid, solver tolerances, load effects, palpate version. */
    static StoreFingerprint
    of(const Scene &scene, const Mesh &mesh, const NodeSelection &nodes);
  };

  /**
   * A persistent store of computed states in HDF5 (State space / Store,
   * palpate precompute): force, stiffness where available, displacement
   * field and multipliers of each state, failure points, and the scene's
   * fingerprint.
   *
   * Crash safety: the file is written in HDF5's single-writer /
   * multiple-reader mode (SWMR), whose ordered metadata flushes keep the
   * file readable if the writer is killed; every state carries a checksum of
   * its values, written last, so a state cut short or changed on disk (a
   * flipped bit) is detected, skipped and counted, and the intact ones are
   * used. Nothing is ever rewritten in place.
   */
  class StateStore
  {
  public:
    /**
     * Open @p file, or create it if it does not exist, for a scene with
     * @p fingerprint. Throws InputError (entry State space / Store) if the
     * file's fingerprint differs (naming the field and both values) or if
     * HDF5 cannot open it.
     */
    StateStore(const std::string &file, const StoreFingerprint &fingerprint);
    ~StateStore();

    /** What load() found. */
    struct Loaded
    {
      unsigned int states = 0, failures = 0, damaged = 0;
    };

    /**
     * Publish every intact stored state (and failure point) into @p cache
     * for its current generation, before an engine starts, so that they
     * are not computed again.
     */
    Loaded
    load(StateCache &cache, const StateGrid &grid);

    /**
     * Append the states and failure points @p cache holds that the store
     * does not, each flushed before the next. States held elsewhere (MPI
     * servers) are asked for and appended by a later call. Returns the
     * number appended.
     */
    unsigned int
    append(const StateCache &cache, const StateGrid &grid);

    /**
     * The number of points @p cache finished (states and failure points)
     * that the store does not hold yet and still can: a state the cache
     * dropped for its budget is not counted (nothing gives it back).
     */
    unsigned int
    missing(const StateCache &cache, const StateGrid &grid) const;

    /** Append one state (converged or not) at grid point @p point. */
    void
    append(const unsigned int point, const State &state);

    /** Read every intact state: (point, state); @p damaged counts those
     * whose checksum does not match. */
    std::vector<std::pair<unsigned int, State>>
    read_all(unsigned int &damaged) const;

    /**
     * Write the stored state space for ParaView as a legacy VTK
     * STRUCTURED_POINTS file on the grid (origin and spacing in metres):
     * per grid point the force (N, vector), its magnitude, the stiffness
     * (N/m, a tensor; zero where not computed) and the status (-1 not
     * computed, 0 an equilibrium, 1 + the SolveStatus of a failure point:
     * 2 max iterations, 3 inverted element, 4 not finite, 5 linear solver).
     */
    void
    export_vtk(const StateGrid &grid, const std::string &filename) const;

    /** Number of records (intact or not). */
    unsigned int
    size() const;

    /** The file name. */
    const std::string &
    file() const;

  private:
    struct Impl;
    std::unique_ptr<Impl> impl;
  };
} // namespace palpate

#endif
