// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

#include <palpate/base/exceptions.h>
#include <palpate/haptics/device.h>
#include <palpate/haptics/trajectory.h>
#include <palpate/scene/scene.h>

#include <deal.II/base/parameter_handler.h>

#include <algorithm>
#include <cmath>
#include <vector>

namespace palpate
{
  namespace
  {
    /**
     * The paper's simulated device: the HIP follows the scene's trajectory
     * (Haptics / Trajectory) from the motion's start, and the forces go
     * nowhere (the loop's force log keeps them). The interaction is over
     * when the trajectory is.
     */
    class SimulatedDevice : public Device
    {
    public:
      explicit SimulatedDevice(std::unique_ptr<Trajectory> trajectory)
        : trajectory(std::move(trajectory))
      {
        // How far it goes from rest along any axis, for the report, and
        // its farthest point.
        const double T = this->trajectory->duration();
        planned.reserve(1001);
        for (unsigned int k = 0; k <= 1000; ++k)
          {
            const auto x = this->trajectory->position(T * k / 1000);
            planned.push_back(x);
            for (const double c : x)
              reach = std::max(reach, std::abs(c));
            if (Utilities::norm(x) > Utilities::norm(farthest))
              farthest = x;
          }
      }

      /** No entries of its own: the trajectory has them. */
      static void
      declare_parameters(dealii::ParameterHandler &)
      {}

      static std::unique_ptr<Device>
      create(const dealii::ParameterHandler &, const Scene &scene)
      {
        auto         trajectory = Trajectory::create(scene);
        const double duration   = trajectory->duration();
        // A scene's Duration is bounded when it is read; a recording's
        // length is known only now.
        if (duration > Limits::max_motion_duration)
          throw InputError(
            scene.resolve_path(scene.parameters.haptics.trajectory.file_name),
            0,
            "trajectory replay (Haptics / Trajectory / File name)",
            "the recording lasts " + Utilities::to_string(duration, 4) +
              " s; at most " +
              Utilities::to_string(Limits::max_motion_duration, 4) +
              " s (one hour) are allowed: the haptic loop preallocates its "
              "statistics and force log for every tick of the run",
            "check the time column (seconds, not milliseconds), or split "
            "the recording.");
        return std::make_unique<SimulatedDevice>(std::move(trajectory));
      }

      Utilities::Point3
      position(const double t) noexcept override
      {
        return t > 0 ? trajectory->position(t) : Utilities::Point3{{0, 0, 0}};
      }

      void
      render(const Utilities::Point3 &) noexcept override
      {}

      bool
      finished(const double t) const noexcept override
      {
        return t > trajectory->duration();
      }

      double
      max_duration() const override
      {
        return trajectory->duration();
      }

      double
      planned_reach() const override
      {
        return reach;
      }

      Utilities::Point3
      planned_farthest() const override
      {
        return farthest;
      }

      Utilities::Point3
      planned_deepest(const Utilities::Point3 &outward) const override
      {
        Utilities::Point3 deepest = {{0, 0, 0}};
        for (const auto &x : planned)
          if (Utilities::dot(x, outward) < Utilities::dot(deepest, outward))
            deepest = x;
        return deepest;
      }

      std::string
      description() const override
      {
        return "simulated device, " + trajectory->description();
      }

    private:
      std::unique_ptr<Trajectory> trajectory;
      double                      reach    = 0;
      Utilities::Point3           farthest = {{0, 0, 0}};
      /** The motion, sampled at 1,001 times (set-up only). */
      std::vector<Utilities::Point3> planned;
    };
  } // namespace

  PALPATE_REGISTER_DEVICE(SimulatedDevice,
                          "simulated",
                          "the HIP follows Haptics / Trajectory (the paper's "
                          "simulated device)")
} // namespace palpate
