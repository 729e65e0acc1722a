// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

// The parameters of the interaction and what it writes (parameters.h): the
// subsections Haptics (the real-time loop and the device plug-ins),
// Haptics / Trajectory (the simulated device's path, the trajectory
// plug-ins) and Output, each declared with its help text and read back into
// its struct.

#include <palpate/scene/parameters_impl.h>

namespace palpate
{
  namespace Parameters
  {
    using namespace dealii;



    void
    Trajectory::declare_parameters(ParameterHandler &prm)
    {
      prm.enter_subsection("Trajectory");
      {
        // The trajectories are plug-ins (haptics/trajectory.h): the
        // choice and each one's own subsection come from their
        // declarations, the entries below are shared.
        internal::declare_plugin_choice(
          prm,
          "trajectory",
          "Type",
          "straight line",
          "Motion of the simulated device's HIP, "
          "relative to the active node's rest position:",
          "");
        prm.declare_entry("Direction",
                          "0, 0, -1",
                          internal::point_pattern(),
                          "Direction of the straight line; the circle lies "
                          "in the plane normal to it (dimensionless).");
        prm.declare_entry("Speed",
                          "0.01",
                          Patterns::Double(0.),
                          "Speed of the HIP (m/s): constant along the "
                          "straight line and the circle, the root-mean-square "
                          "speed of the smooth random walk.");
        prm.declare_entry("Duration",
                          "2",
                          Patterns::Double(0.),
                          "Duration of the motion (s).");
        prm.declare_entry("Radius",
                          "0.01",
                          Patterns::Double(0.),
                          "Radius of the circle, and the bound of the smooth "
                          "random walk (m).");
        prm.declare_entry("Seed",
                          "1",
                          Patterns::Integer(0, 2147483647),
                          "Seed of the smooth random walk (dimensionless).");
        prm.declare_entry("File name",
                          "",
                          Patterns::FileName(),
                          "CSV file of timed positions for Type = replay: "
                          "columns t (s), x, y, z (m); a header line and "
                          "lines starting with # are skipped. Times and "
                          "positions count from the first row, so a "
                          "recording in any device clock and frame replays "
                          "from the rest position at t = 0. Relative to the "
                          "scene file's directory.");
        prm.declare_entry("Start",
                          "after initial cloud",
                          Patterns::Selection("after initial cloud|after rest "
                                              "neighbourhood|immediately"),
                          "When the motion starts: once the initial cloud "
                          "around the rest position is computed (the "
                          "paper's protocol); once the 27 grid points "
                          "around it are (every cell that touches the rest "
                          "position: the hand can move a grid spacing in any "
                          "direction on complete data, and the rest of the "
                          "cloud is computed during the motion; on a big "
                          "organ, where a state takes seconds, a twentieth "
                          "of the wait); or at once.");
        prm.declare_entry(
          "Initial cloud time limit",
          "120",
          Patterns::Double(0, 3600),
          "With Start = after initial cloud (or after rest neighbourhood): "
          "the longest the motion waits for the initial cloud (or the rest "
          "neighbourhood) (s); then it starts anyway, and the run "
          "says so. Every state of the cloud (Scheduler / Cloud radius) "
          "around the rest position, at the scene's cost per state, divided "
          "by the workers: a large organ or cloud needs more than the "
          "default. States kept in a store (State space / Store) are not "
          "computed again.");
      }
      prm.leave_subsection();
    }



    void
    Trajectory::parse_parameters(ParameterHandler &prm)
    {
      prm.enter_subsection("Trajectory");
      {
        type                     = prm.get("Type");
        own                      = internal::own_entries(prm, "trajectory");
        direction                = internal::get_point(prm, "Direction");
        speed                    = prm.get_double("Speed");
        duration                 = prm.get_double("Duration");
        radius                   = prm.get_double("Radius");
        seed                     = prm.get_integer("Seed");
        file_name                = prm.get("File name");
        start                    = prm.get("Start");
        initial_cloud_time_limit = prm.get_double("Initial cloud time limit");
      }
      prm.leave_subsection();
    }



    void
    Haptics::declare_parameters(ParameterHandler &prm)
    {
      prm.enter_subsection("Haptics");
      {
        prm.declare_entry("Loop rate",
                          "1000",
                          Patterns::Double(0.),
                          "Rate of the haptic loop that interpolates and "
                          "sends the force (Hz).");
        // The devices are plug-ins (haptics/device.h): the choice and
        // each one's own subsection come from their declarations.
        internal::declare_plugin_choice(
          prm,
          "device",
          "Device",
          "simulated",
          "The haptic device, which the haptic loop reads "
          "and renders the force to:",
          "");
        prm.declare_entry("Force limit",
                          "8",
                          Patterns::Double(0.),
                          "Largest force magnitude sent to the device (N).");
        prm.declare_entry("Maximum force change",
                          "0.05",
                          Patterns::Double(0.),
                          "Largest change of the force vector from one "
                          "haptic tick to the next (N).");
        Trajectory::declare_parameters(prm);
      }
      prm.leave_subsection();
    }



    void
    Haptics::parse_parameters(ParameterHandler &prm)
    {
      prm.enter_subsection("Haptics");
      {
        loop_rate        = prm.get_double("Loop rate");
        device           = prm.get("Device");
        own              = internal::own_entries(prm, "device");
        force_limit      = prm.get_double("Force limit");
        max_force_change = prm.get_double("Maximum force change");
        trajectory.parse_parameters(prm);
      }
      prm.leave_subsection();
    }



    void
    Output::declare_parameters(ParameterHandler &prm)
    {
      prm.enter_subsection("Output");
      {
        prm.declare_entry("Directory",
                          "output",
                          Patterns::DirectoryName(),
                          "Directory for every file palpate writes (VTU, "
                          "logs, summaries), relative to the current "
                          "working directory; created if missing.");
        prm.declare_entry("Summary formats",
                          "",
                          Patterns::MultipleSelection("csv|json"),
                          "Machine-readable copies of the run summary, "
                          "besides the screen: any of csv, json.");
        prm.declare_entry("Print timings",
                          "true",
                          Patterns::Bool(),
                          "Whether reports include wall-clock times (ms). "
                          "Turn off for output that is the same on every "
                          "machine, as the tests do.");
      }
      prm.leave_subsection();
    }



    void
    Output::parse_parameters(ParameterHandler &prm)
    {
      prm.enter_subsection("Output");
      {
        directory = prm.get("Directory");
        summary_formats.clear();
        for (const auto &f : Utilities::split(prm.get("Summary formats"), ','))
          if (!f.empty())
            summary_formats.push_back(f);
        print_timings = prm.get_bool("Print timings");
      }
      prm.leave_subsection();
    }
  } // namespace Parameters
} // namespace palpate
