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
  struct ContactPatch;
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
   * The right to write one state store: an exclusive lock (flock) on the
   * file `STORE.lock` beside it, which says who holds it (process id,
   * command line, since when). A second process that wants to write the
   * store is refused with an InputError that names the holder and the fix;
   * two writers would append to the same rows and damage each other's
   * records. The lock is the kernel's: it goes with the process that holds
   * it, so a writer that was killed (SIGKILL, a power cut) never blocks the
   * next one, whatever its lock file still says.
   *
   * Within one process the lock is shared: every StoreLock and every
   * StateStore opened for writing on the same file hold the same lock,
   * which is released (and its lock file removed) when the last of them
   * goes. `palpate precompute` holds one for its whole run, so that no
   * other process writes between the interaction that fills the store and
   * the count of what it kept.
   */
  class StoreLock
  {
  public:
    /**
     * Take the lock of the store @p store (the file need not exist yet).
     * Throws InputError (entry State space / Store) if another process
     * holds it, naming that process, or if the lock file cannot be made
     * (the directory missing or not writable).
     */
    explicit StoreLock(const std::string &store);
    ~StoreLock();

    /** The lock file, `STORE.lock` beside the store (symbolic links
     * resolved, so that two names of one store share one lock). */
    const std::string &
    lock_file() const;

    /**
     * Why appending to the store stopped in this process (a write failed:
     * the disk full), with what the store kept; "" while nothing failed.
     * Shared by every holder of the lock in this process.
     */
    std::string
    failure() const;

    /** The lock as this process holds it (its file descriptor, the
     * failure); defined in state_store_impl.h, private to the store's
     * sources. */
    struct Held;

  private:
    std::shared_ptr<Held> held;
    friend class StateStore;
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
   *
   * One writer: a store opened for writing holds its StoreLock, so a second
   * process is refused instead of damaging records. Readers need no lock:
   * they open the file in SWMR read mode and see only whole records (a
   * record's checksum is written last; a record still being written, or
   * cut short, has none and is skipped as incomplete, not as damaged).
   *
   * A write that fails (the disk full, a file size limit) stops the
   * appending: the store closes the file, reads back what it keeps, and
   * says exactly that; later appends do nothing.
   */
  class StateStore
  {
  public:
    /** How a store is opened. */
    enum class Access
    {
      /** Create it if it does not exist, load and append: takes the
       * StoreLock. */
      write,
      /** Read what it holds while a writer may append (SWMR read): no
       * lock; the file must exist. */
      read
    };

    /**
     * Open @p file, or create it if it does not exist (Access::write), for
     * a scene with @p fingerprint. Throws InputError (entry State space /
     * Store) naming the file, what is wrong and the fix: another process
     * writes it (Access::write), the path is refused or is a directory or
     * a device, permission is denied, it is not an HDF5 file or not a
     * palpate store, it is damaged (HDF5 cannot read its structure), or its
     * fingerprint differs (naming the field and both values).
     */
    StateStore(const std::string      &file,
               const StoreFingerprint &fingerprint,
               const Access            access = Access::write);
    ~StateStore();

    /** What load() or contents() found. */
    struct Loaded
    {
      /** Intact states and failure points. */
      unsigned int states = 0, failures = 0;
      /** The states with their contact patch (Interpolation = contact
       * patch). */
      unsigned int patches = 0;
      /** Records whose checksum does not match (changed on disk). */
      unsigned int damaged = 0;
      /** Records without a checksum: cut short by a writer that was
       * killed, or (to a reader) still being written. */
      unsigned int incomplete = 0;
    };

    /**
     * Publish every intact stored state (and failure point) into @p cache
     * for its current generation, before an engine starts, so that they
     * are not computed again.
     */
    Loaded
    load(StateCache &cache, const StateGrid &grid);

    /** Count what the store holds (intact states and failure points,
     * damaged and incomplete records), reading every record. */
    Loaded
    contents() const;

    /**
     * Append the states and failure points @p cache holds that the store
     * does not, each flushed before the next. States held elsewhere (MPI
     * servers) are asked for and appended by a later call. Returns the
     * number appended. If a write fails, throws OutputError saying what
     * the store kept (see stopped()).
     */
    unsigned int
    append(const StateCache &cache, const StateGrid &grid);

    /**
     * The number of points @p cache finished (states and failure points)
     * that the store does not hold yet and still can: a state the cache
     * dropped for its budget is not counted (nothing gives it back), nor
     * is anything once the store stopped().
     */
    unsigned int
    missing(const StateCache &cache, const StateGrid &grid) const;

    /**
     * Append one state (converged or not) at grid point @p point, flushed
     * before it returns. If a write fails, the store stops: it reads back
     * what the file keeps and throws OutputError saying so; after that,
     * appending does nothing.
     */
    void
    append(const unsigned int point, const State &state);

    /** The same, with the state's contact patch @p patch (kept with it; a
     * state of an MPI server comes without its patch, which the cache
     * holds). */
    void
    append(const unsigned int  point,
           const State        &state,
           const ContactPatch *patch);

    /**
     * The records this object appended that the file holds: those written
     * and flushed, or after a failed write, those read back intact.
     */
    unsigned int
    appended() const;

    /** Whether a write failed and appending stopped. */
    bool
    stopped() const;

    /** Read every intact state: (point, state); @p damaged counts those
     * whose checksum does not match, @p incomplete (if given) those
     * without a checksum (cut short, or being written). */
    std::vector<std::pair<unsigned int, State>>
    read_all(unsigned int &damaged, unsigned int *incomplete = nullptr) const;

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
