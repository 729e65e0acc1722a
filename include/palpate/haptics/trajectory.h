// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

#ifndef palpate_haptics_trajectory_h
#define palpate_haptics_trajectory_h

#include <palpate/base/plugins.h>
#include <palpate/base/utilities.h>

#include <memory>
#include <string>
#include <vector>

namespace palpate
{
  class Scene;

  /**
   * The motion of a simulated device: the HIP's displacement from the
   * active node's rest position (m) at time t (s) after the motion starts.
   * Every trajectory starts at the rest position. position() is cheap and
   * allocation-free: the haptic thread calls it every tick.
   *
   * Trajectories are plug-ins (doc/extending.md): `Haptics / Trajectory /
   * Type` chooses one from TrajectoryRegistry. A plug-in reads the shared
   * entries of `Haptics / Trajectory` (Speed, Duration, Direction, Radius,
   * Seed, File name) from the scene, and its own from its subsection
   * `Haptics / Trajectory / <its name>`; its file ends with
   *
   *     PALPATE_REGISTER_TRAJECTORY(Lissajous, "lissajous", "one line")
   *
   * where the class has `static void declare_parameters(ParameterHandler
   * &)` and `static std::unique_ptr<Trajectory> create(const
   * ParameterHandler &own, const Scene &scene)`, and optionally `static
   * void check_scene(const Scene &)`, which checks the shared entries it
   * reads when the scene is read (TrajectoryChecks has those of the
   * built-in ones: source/haptics/trajectories/, one file each).
   */
  class Trajectory
  {
  public:
    virtual ~Trajectory() = default;

    /** Position at time @p t >= 0 (m); constant after duration(). */
    virtual Utilities::Point3
    position(const double t) const noexcept = 0;

    /** Length of the motion (s). */
    virtual double
    duration() const noexcept = 0;

    /** One line for reports. */
    virtual std::string
    description() const = 0;

    /**
     * The trajectory of a scene's Haptics / Trajectory subsection. A replay
     * file that cannot be read is an InputError naming its line; a value a
     * plug-in refuses is one naming its entry.
     */
    static std::unique_ptr<Trajectory>
    create(const Scene &scene);
  };

  /**
   * For a trajectory plug-in that reads only the shared entries of
   * `Haptics / Trajectory`: its (empty) declaration of entries of its own.
   */
  struct SharedTrajectoryEntries
  {
    static void
    declare_parameters(dealii::ParameterHandler &)
    {}
  };

  /** The trajectories, by the names scenes give them. */
  using TrajectoryRegistry = Plugins::Registry<Trajectory, Scene>;
  extern template class Plugins::Registry<Trajectory, Scene>;

/** Register the trajectory @p classname as @p name (PALPATE_REGISTER_PLUGIN,
 * plus its declaration for the scene's Haptics / Trajectory subsection). */
#define PALPATE_REGISTER_TRAJECTORY(classname, name, description) \
  PALPATE_REGISTER_DECLARED_PLUGIN(                               \
    ::palpate::TrajectoryRegistry, "trajectory", classname, name, description)

  /** A straight line from the rest position at constant speed. */
  class StraightLine : public Trajectory
  {
  public:
    /** @p direction (any length), @p speed (m/s), @p duration (s). */
    StraightLine(const Utilities::Point3 &direction,
                 const double             speed,
                 const double             duration);

    Utilities::Point3
    position(const double t) const noexcept override;

    double
    duration() const noexcept override
    {
      return length;
    }

    std::string
    description() const override;

  private:
    Utilities::Point3 d;
    double            speed, length;
  };

  /**
   * A circle through the rest position, in the plane normal to
   * @p normal, of radius @p radius (m) at @p speed (m/s).
   */
  class Circle : public Trajectory
  {
  public:
    Circle(const Utilities::Point3 &normal,
           const double             radius,
           const double             speed,
           const double             duration);

    Utilities::Point3
    position(const double t) const noexcept override;

    double
    duration() const noexcept override
    {
      return length;
    }

    std::string
    description() const override;

  private:
    Utilities::Point3 e1, e2;
    double            radius, omega, length;
  };

  /**
   * A smooth random motion: per axis, a sum of three sinusoids with random
   * amplitudes, phases and frequencies (seeded), shifted to start at rest,
   * staying within @p radius of it, with root-mean-square speed @p speed
   * (over a long run; the speed itself varies smoothly).
   */
  class SmoothRandom : public Trajectory
  {
  public:
    SmoothRandom(const double       radius,
                 const double       speed,
                 const double       duration,
                 const unsigned int seed);

    Utilities::Point3
    position(const double t) const noexcept override;

    double
    duration() const noexcept override
    {
      return length;
    }

    std::string
    description() const override;

  private:
    double       amplitude[3][3], frequency[3][3], phase[3][3];
    double       length, radius, speed;
    unsigned int seed;
  };

  /**
   * Replay of timed positions from a CSV file (t, x, y, z), linear in
   * between. Times and positions count from the first row's, so the replay
   * starts at rest at t = 0 whatever the recording's clock and frame.
   */
  class Replay : public Trajectory
  {
  public:
    /** Read @p filename; errors name the file and line. */
    explicit Replay(const std::string &filename);

    Utilities::Point3
    position(const double t) const noexcept override;

    double
    duration() const noexcept override;

    std::string
    description() const override;

  private:
    std::string                    file;
    std::vector<double>            times;
    std::vector<Utilities::Point3> points;
  };
} // namespace palpate

#endif
