// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

// Haptics / Trajectory / Type = replay: the timed positions of a recorded
// motion, read from the CSV file File name (t, x, y, z).

#include <palpate/base/plugins.h>
#include <palpate/haptics/trajectory.h>
#include <palpate/scene/scene.h>

#include <deal.II/base/parameter_handler.h>

#include <filesystem>

namespace palpate
{
  namespace
  {
    /** The plug-in: it reads only the shared File name. Speed and
     * Duration are the recording's. */
    class ReplayTrajectory : public SharedTrajectoryEntries
    {
    public:
      static std::unique_ptr<Trajectory>
      create(const dealii::ParameterHandler &, const Scene &scene)
      {
        const auto       &t    = scene.parameters.haptics.trajectory;
        const std::string path = scene.resolve_path(t.file_name);
        std::error_code   error;
        const bool        exists = std::filesystem::exists(path, error);
        // A name the file system refuses (a loop of links, too long) is not
        // a missing file: say what it said.
        if (error)
          throw scene.error("Haptics/Trajectory/File name",
                            "the recording '" + path +
                              "' cannot be opened: " + error.message(),
                            "check the path and the links on the way to the "
                            "recording's CSV file.");
        if (!exists)
          throw scene.error("Haptics/Trajectory/File name",
                            "the recording '" + t.file_name +
                              "' was not found: looked for " +
                              scene.where_looked(t.file_name),
                            "a relative path is relative to the scene file's "
                            "directory; give the recording's path from there, "
                            "or an absolute one.");
        return std::make_unique<Replay>(path);
      }

      static void
      check_scene(const Scene &scene)
      {
        if (scene.parameters.haptics.trajectory.file_name.empty())
          throw scene.error("Haptics/Trajectory/File name",
                            "Type = replay, but no CSV file is named",
                            "name a CSV file with columns t, x, y, z.");
      }
    };
  } // namespace

  PALPATE_REGISTER_TRAJECTORY(
    ReplayTrajectory,
    "replay",
    "replay of the timed positions of the CSV file File name")
} // namespace palpate
