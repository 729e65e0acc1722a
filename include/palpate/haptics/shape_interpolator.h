// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

#ifndef palpate_haptics_shape_interpolator_h
#define palpate_haptics_shape_interpolator_h

#include <memory>
#include <string>

namespace palpate
{
  class Interaction;

  /**
   * The shape interpolator: at Effects / Shape output rate (about 30 Hz),
   * the whole displacement field at the HIP's position, interpolated
   * trilinearly from the states at the 8 corners of its cell, written as a
   * VTU frame, with a PVD file that ParaView opens as a time series. It
   * exists only when the scene switches shape output on. Frames whose cell
   * is not complete are skipped (and counted).
   */
  class ShapeInterpolator
  {
  public:
    /** Frames go to @p directory as STEM-shape-NNNNN.vtu and STEM-shape.pvd. */
    ShapeInterpolator(const Interaction &interaction,
                      const double       rate,
                      const std::string &directory,
                      const std::string &stem);

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

    /**
     * After stop(): why the shape output stopped early (a frame or the PVD
     * file could not be written), or empty if it did not.
     */
    const std::string &
    failure() const;

  private:
    struct Impl;
    std::unique_ptr<Impl> impl;
  };
} // namespace palpate

#endif
