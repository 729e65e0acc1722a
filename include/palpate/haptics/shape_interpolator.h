// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

#ifndef palpate_haptics_shape_interpolator_h
#define palpate_haptics_shape_interpolator_h

#include <array>
#include <functional>
#include <memory>
#include <string>
#include <vector>

namespace palpate
{
  class Interaction;
  struct State;
  class Mesh;
  class HyperelasticSystem;
  struct NodeSelection;

  /**
   * A PVD index that is whole at every moment. Each frame's entry is
   * written over the closing tags, with new closing tags after it, in one
   * write where they began: a run killed between frames (SIGKILL, a crash,
   * mpirun ending a lost MPI client) leaves every frame indexed but the one
   * being written. (Rewriting the whole index every 5 s lost the frames of
   * the last few seconds: 93 of 97 indexed when an MPI client was killed;
   * palpate solve wrote it only at the end.) A write that fails (a full
   * disk) puts the closing tags back where they were, in room the file
   * already has, and cuts what came after them.
   */
  class PvdIndex
  {
  public:
    PvdIndex()                 = default;
    PvdIndex(const PvdIndex &) = delete;
    PvdIndex &
    operator=(const PvdIndex &) = delete;
    ~PvdIndex();

    /** Create @p name with no entries; "" or why it could not be. */
    std::string
    open(const std::string &name);

    /** Add the frame @p name at @p time; "" or why it could not be. */
    std::string
    append(const double time, const std::string &name);

  private:
    bool
    write_at(const std::string &text, long at) const;

    std::string
    failed(const int error) const;

    const std::string closing = "  </Collection>\n</VTKFile>\n";
    std::string       file;
    int               fd   = -1;
    long              tail = 0;
  };



  /**
   * Writes shape frames: the body's displacement as a VTU file for
   * ParaView (warp by 'displacement'), with the fixed and active nodes
   * flagged and the force on the probe as field data. What every frame
   * shares - the reference mesh (points, tetrahedra), the flags, which
   * DoFs hold each vertex's displacement - is written to text once, so a
   * frame writes only the displacement: a fraction of a millisecond, where
   * a full state's VTU (reactions by an assembly, DataOut's patches) takes
   * several.
   */
  class ShapeFrames
  {
  public:
    ShapeFrames(const Mesh               &mesh,
                const NodeSelection      &nodes,
                const HyperelasticSystem &system);

    /** Write the frame of @p solution (a state's) and @p force (N) to
     * @p file; returns its size (bytes). Throws if it cannot be written. */
    double
    write(const std::vector<double>   &solution,
          const std::array<double, 3> &force,
          const std::string           &file) const;

    /** The DoFs of each mesh vertex's displacement (x, y, z). */
    const std::vector<std::array<unsigned int, 3>> &
    dofs_of_vertices() const
    {
      return vertex_dofs;
    }

  private:
    std::vector<std::array<unsigned int, 3>> vertex_dofs;
    std::string                              flags, geometry;
    unsigned int                             n_cells;
  };

  /**
   * The body's state at the HIP displacement @p x (m): the solutions,
   * multipliers and forces of the 8 corners of its cell, blended
   * trilinearly, into @p blend. False (and @p blend unchanged) if @p x is
   * outside the state space or a corner's whole state is not in the cache.
   * Allocates: for the shape interpolator and the live view, never the
   * real-time thread.
   */
  bool
  blend_shape(const Interaction       &interaction,
              const Utilities::Point3 &x,
              State                   &blend);

  /**
   * The shape interpolator: at Effects / Shape output rate (about 30 Hz),
   * the whole displacement field at the HIP's position, interpolated
   * trilinearly from the states at the 8 corners of its cell, written as a
   * VTU frame, with a PVD file that ParaView opens as a time series. It
   * exists only when the scene switches shape output on. Frames whose cell
   * is not complete are skipped (and counted).
   *
   * It writes only what changes and never competes with the solvers: a
   * frame is written only while the probe moves (the HIP moved since the
   * last frame; with a clock, also only once the motion started), its
   * thread runs at nice 19, and when writing falls behind (a busy
   * machine) the frames it missed are skipped and counted, not written in
   * a burst. With @p clock (the haptic loop's motion_time()) the frames'
   * times are the force log's. Once the frames written reach @p max_bytes
   * no more are written (they are counted): a long run cannot fill the
   * disk.
   */
  class ShapeInterpolator
  {
  public:
    /** Frames go to @p directory as STEM-shape-NNNNN.vtu and STEM-shape.pvd. */
    ShapeInterpolator(const Interaction             &interaction,
                      const double                   rate,
                      const std::string             &directory,
                      const std::string             &stem,
                      const std::function<double()> &clock     = nullptr,
                      const double                   max_bytes = 1e300);

    ~ShapeInterpolator();

    /** Start the thread. */
    void
    start();

    /** Stop the thread and write the PVD file. */
    void
    stop();

    /** Frames written, and frames skipped for missing states. */
    std::pair<unsigned int, unsigned int>
    frames() const;

    /** Frames skipped because writing fell behind (a busy machine). */
    unsigned int
    frames_skipped_busy() const;

    /** Frames thinned out to stay under @p max_bytes: past half of it
     * every 2nd frame is written, past 3/4 every 4th, and so on. */
    unsigned int
    frames_decimated() const;

    /** Frames left out because the frames reached @p max_bytes. */
    unsigned int
    frames_over_limit() const;

    /**
     * After stop(): why the shape output stopped early (a frame or the PVD
     * file could not be written), or empty if it did not.
     */
    const std::string &
    failure() const;

    /**
     * Whether the shape output stopped early (failure() says why): safe to
     * call while the thread runs, and once true no more frames are
     * written, so that a caller can wait for it instead of for a time.
     */
    bool
    failed() const noexcept;

  private:
    struct Impl;
    std::unique_ptr<Impl> impl;
  };
} // namespace palpate

#endif
