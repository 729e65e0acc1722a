// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

#ifndef palpate_haptics_device_h
#define palpate_haptics_device_h

#include <palpate/base/plugins.h>
#include <palpate/base/utilities.h>

#include <memory>
#include <string>

namespace palpate
{
  class Scene;

  /**
   * A haptic device as the haptic loop (HapticLoop) sees it: where the HIP
   * is, the force to render there, and whether the interaction is over.
   * The loop calls position(), render() and finished() once per tick from
   * its real-time thread: they must not block, allocate or throw.
   *
   * Devices are plug-ins (doc/extending.md): `Haptics / Device` chooses one
   * from DeviceRegistry; its own entries are in `Haptics / <its name>`. Its
   * file ends with
   *
   *     PALPATE_REGISTER_DEVICE(Phantom, "phantom", "one line")
   *
   * where the class has `static void declare_parameters(ParameterHandler
   * &)` and `static std::unique_ptr<Device> create(const ParameterHandler
   * &own, const Scene &scene)` (and, optionally, `static void
   * check_parameters(const ParameterHandler &own)`, run when the scene is
   * read). The loop records the force log, the statistics and the summary
   * for every device alike.
   */
  class Device
  {
  public:
    virtual ~Device() = default;

    /**
     * The HIP's position (m, relative to the active node's rest position).
     * @p t is the loop's motion clock: seconds since the motion started,
     * <= 0 before (a simulated device rests then); a physical device reads
     * where the hand is and may ignore it.
     */
    virtual Utilities::Point3
    position(const double t) noexcept = 0;

    /** Render @p force (N), clamped and rate-limited by the loop. */
    virtual void
    render(const Utilities::Point3 &force) noexcept = 0;

    /** Whether the interaction is over at motion time @p t (s): a
     * simulated device's trajectory has ended, a live device's user or host
     * program said so. */
    virtual bool
    finished(const double t) const noexcept = 0;

    /** The longest the motion may last (s): the loop preallocates its
     * statistics and force log for it (at most an hour). */
    virtual double
    max_duration() const = 0;

    /** How far the motion is planned to take the HIP from rest along any
     * axis (m), where that is known in advance (a trajectory); 0 if not.
     * The report warns when it leaves the state space. */
    virtual double
    planned_reach() const
    {
      return 0;
    }

    /** The planned displacement from rest farthest from it (m), where the
     * motion is known in advance (a trajectory); zero if not. A sphere's
     * set-up checks weigh the push this is. */
    virtual Utilities::Point3
    planned_farthest() const
    {
      return {{0, 0, 0}};
    }

    /** The planned displacement from rest that goes farthest against
     * @p outward (a unit normal: the deepest into the body), where the
     * motion is known in advance; zero if not. A circle's deepest point
     * need not be its farthest, so the sphere's checks ask both. */
    virtual Utilities::Point3
    planned_deepest(const Utilities::Point3 &outward) const
    {
      (void)outward;
      return {{0, 0, 0}};
    }

    /** One line for reports. */
    virtual std::string
    description() const = 0;

    /** The device of a scene's `Haptics / Device`. */
    static std::unique_ptr<Device>
    create(const Scene &scene);
  };

  /** The devices, by the names scenes give them. */
  using DeviceRegistry = Plugins::Registry<Device, Scene>;
  extern template class Plugins::Registry<Device, Scene>;
} // namespace palpate

/** Register the device @p classname as @p name (the registry, and its
 * declaration for the scene's Haptics subsection). */
#define PALPATE_REGISTER_DEVICE(classname, name, description) \
  PALPATE_REGISTER_DECLARED_PLUGIN(                           \
    ::palpate::DeviceRegistry, "device", classname, name, description)

#endif
