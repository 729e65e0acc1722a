// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

// A scene (scene.h), the Scene's own members: the defaults; Scene::read(),
// which reads a scene file and the command line's --set entries step by step
// (the file's text, deal.II's reading of it, the settings, the conversion,
// the checks); where an input file the scene names is looked for; the errors
// that point at an entry's line; and validate(), which runs the checks of
// the scene_checks_*.cc files. The steps are in the other scene files
// (scene_impl.h lists them).

#include <palpate/scene/scene_impl.h>

#include <algorithm>
#include <filesystem>
#include <regex>

namespace palpate
{
  Scene::Scene()
  {
    dealii::ParameterHandler prm;
    Parameters::AllParameters::declare_parameters(prm);
    parameters.parse_parameters(prm);
  }



  Scene
  Scene::read(const std::string              &filename,
              const std::vector<std::string> &command_line)
  {
    // The command line's --set entries first: a mistake there is reported
    // as one, whatever the file holds.
    const std::vector<internal::CommandLineSetting> overrides =
      internal::parse_command_line_settings(command_line);
    Scene scene{Unparsed()};
    scene.file_      = filename;
    scene.directory_ = std::filesystem::path(filename).parent_path().string();

    internal::check_is_regular_file(filename);
    std::string content = internal::read_scene_bytes(filename);
    internal::strip_byte_order_mark(content, filename);
    internal::check_plain_text(content, filename);
    const std::vector<std::string> lines = internal::split_lines(content);
    internal::check_no_includes(lines, filename);

    internal::RecordingReader reader(filename, content, lines);
    reader.parse_file();
    scene.command_line_settings_ = reader.apply_command_line(overrides);
    internal::keep_entry_lines_and_values(reader.settings(),
                                          filename,
                                          scene.entry_lines_,
                                          scene.entry_values_);
    internal::convert_parameters(scene.parameters,
                                 reader.handler(),
                                 reader.settings(),
                                 filename);
    scene.validate();
    return scene;
  }



  namespace
  {
    /** The candidates Scene::resolve_path() tries, in order, without
     * repeats. */
    std::vector<std::string>
    path_candidates(const std::string &directory, const std::string &path)
    {
      namespace fs = std::filesystem;
      if (path.empty() || fs::path(path).is_absolute())
        return {path};
      std::vector<std::string> candidates;
      const auto               add = [&](const fs::path &base) {
        const std::string c = (base / path).lexically_normal().string();
        if (std::find(candidates.begin(), candidates.end(), c) ==
            candidates.end())
          candidates.push_back(c);
      };
      add(directory.empty() ? fs::path() : fs::path(directory));
      add(fs::path());
#ifdef PALPATE_SOURCE_DIR
      add(fs::path(PALPATE_SOURCE_DIR) / "parameters");
#endif
      return candidates;
    }
  } // namespace



  std::string
  Scene::resolve_path(const std::string &path) const
  {
    const auto candidates = path_candidates(directory_, path);
    for (const auto &c : candidates)
      {
        // error_code: a name the file system refuses (too long, a loop of
        // links) is not there; the caller's message says so.
        std::error_code error;
        if (std::filesystem::exists(c, error))
          return c;
      }
    return candidates.front();
  }



  std::string
  Scene::where_looked(const std::string &path) const
  {
    const auto  candidates = path_candidates(directory_, path);
    std::string text;
    for (std::size_t i = 0; i < candidates.size(); ++i)
      {
        // Absolute: "../meshes/x.msh" would not say where that was.
        std::error_code error;
        const auto      shown = std::filesystem::absolute(candidates[i], error);
        text +=
          (i == 0                     ? "" :
           i + 1 == candidates.size() ? " or " :
                                        ", ") +
          ("'" + (error ? candidates[i] : shown.lexically_normal().string()) +
           "'");
        // A link to nowhere is there: what is missing is its target.
        if (const std::string link = dangling_link(candidates[i]);
            !link.empty())
          text += " (" + link.substr(link.find("' is ") + 5) + ")";
      }
    return text;
  }



  unsigned int
  Scene::line_of(const std::string &entry) const
  {
    const auto it = entry_lines_.find(entry);
    return it == entry_lines_.end() ? 0 : it->second;
  }



  InputError
  Scene::error(const std::string              &entry,
               const std::string              &problem_alone,
               const std::string              &fix,
               const std::vector<std::string> &with) const
  {
    // A relation between entries (Extent against Grid spacing) is blamed
    // on one of them; if another was set on the command line, the problem
    // says so, or the user would look for it in the file.
    std::string also;
    for (const std::string &other : with)
      for (const std::string &setting : command_line_settings_)
        if (setting.compare(0, other.size() + 1, other + "=") == 0)
          also += (also.empty() ? "" : ", ") + ("--set " + setting);
    const std::string problem =
      also.empty() ? problem_alone :
                     problem_alone + " (with " + also + " on the command line)";
    std::string shown = std::regex_replace(entry, std::regex("/"), " / ");
    const auto  value = entry_values_.find(entry);
    for (const std::string &setting : command_line_settings_)
      if (setting.compare(0, entry.size() + 1, entry + "=") == 0)
        return InputError("command line",
                          0,
                          "--set " + setting + " (scene " +
                            (file_.empty() ? std::string("(default)") : file_) +
                            ")",
                          problem,
                          fix);
    if (value != entry_values_.end())
      shown += " = " + value->second;
    else
      shown += " (default value; the file does not set it)";
    return InputError(file_.empty() ? std::string("(default scene)") : file_,
                      line_of(entry),
                      shown,
                      problem,
                      fix);
  }



  void
  Scene::validate() const
  {
    check_material();
    check_effects();
    check_plugin_entries();
    check_probe();
    check_interpolation();
    check_mesh();
    check_fixed_nodes();
    check_solver_tolerances();
    check_state_space();
    check_newton_counts();
    check_haptics();
    check_shape_output();
  }



  bool
  Scene::sets(const std::string &entry) const
  {
    return line_of(entry) > 0 ||
           std::any_of(command_line_settings_.begin(),
                       command_line_settings_.end(),
                       [&](const std::string &setting) {
                         return setting.compare(0,
                                                entry.size() + 1,
                                                entry + "=") == 0;
                       });
  }
  std::string
  Limits::body_size_problem(const double size)
  {
    const double limit = size < min_body_size ? min_body_size : max_body_size;
    return "the body is " + Utilities::to_string_apart(size, limit) +
           " m across (the diagonal of its bounding box); a body to palpate "
           "is between " +
           Utilities::to_string(min_body_size, 3) + " and " +
           Utilities::to_string(max_body_size, 3) + " m";
  }



} // namespace palpate
