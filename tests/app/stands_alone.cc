// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

// The project stands on its own (issue 27): nothing in the source tree
// refers to data outside it, every shipped scene's mesh or surface is a
// file of the project found from the scene's own directory, every scene
// and organ the README names exists, and a scene copied out of
// parameters/ still finds its organ (Scene::resolve_path), while a
// missing one is reported with every place looked.

#include <palpate/base/exceptions.h>
#include <palpate/mesh/mesh.h>
#include <palpate/scene/scene.h>

#include <algorithm>
#include <filesystem>
#include <regex>
#include <set>

#include "../tests.h"

namespace fs = std::filesystem;

namespace
{
  /** Whether @p path is one of the source tree's own files (not a build
   * tree, git's data, outputs or npm's packages). */
  bool
  skipped(const fs::path &relative)
  {
    const std::string first = relative.begin()->string();
    if (first.rfind("build", 0) == 0 || first == ".git" || first == "output")
      return true;
    for (const auto &part : relative)
      if (part == "node_modules" || part == "results")
        return true;
    return false;
  }

  /** A file's text, or "" for a binary or large one. */
  std::string
  text_of(const fs::path &file)
  {
    std::error_code error;
    if (fs::file_size(file, error) > (std::uintmax_t(4) << 20) || error)
      return "";
    const std::string text = read_file(file.string());
    return text.find('\0') == std::string::npos ? text : "";
  }
} // namespace

int
main(int argc, char **argv)
{
  palpate::Environment env(argc, argv);
  initlog();
  const fs::path root(palpate_source_dir);

  // 1. Nothing names the data the project once read from beside it. (The
  // words are put together here so that this file does not name it.)
  const std::vector<std::string> outside = {std::string("../") + "shared",
                                            std::string("shared") + "/meshes",
                                            std::string("PALPATE_") + "SHARED"};
  unsigned int                   files   = 0;
  std::vector<std::string>       offenders;
  for (auto it = fs::recursive_directory_iterator(root);
       it != fs::recursive_directory_iterator();
       ++it)
    {
      const fs::path relative = fs::relative(it->path(), root);
      // Build trees are recognised by their cache too, whatever their name.
      if (skipped(relative) ||
          (it->is_directory() && fs::exists(it->path() / "CMakeCache.txt")))
        {
          if (it->is_directory())
            it.disable_recursion_pending();
          continue;
        }
      if (!it->is_regular_file())
        continue;
      const std::string text = text_of(it->path());
      if (text.empty())
        continue;
      ++files;
      for (const auto &word : outside)
        if (text.find(word) != std::string::npos)
          {
            offenders.push_back(relative.string() + " ('" + word + "')");
            break;
          }
    }
  deallog << "text files of the project searched: "
          << (files > 150 ? std::string("more than 150") :
                            "FEW (" + std::to_string(files) + ")")
          << std::endl;
  deallog << "files referring to data outside the project: " << offenders.size()
          << " (must be 0)" << std::endl;
  for (const auto &o : offenders)
    deallog << "  " << o << std::endl;

  // 2. Every shipped scene's organ is in the project, found from the
  // scene's own directory (not by the fallback to parameters/).
  std::vector<fs::path> scenes;
  for (const auto &e : fs::directory_iterator(root / "parameters"))
    if (e.path().extension() == ".prm")
      scenes.push_back(e.path());
  std::sort(scenes.begin(), scenes.end());
  for (const auto &file : scenes)
    {
      const palpate::Scene scene = palpate::Scene::read(file.string());
      const auto          &mesh  = scene.parameters.mesh;
      deallog << file.filename().string() << ": ";
      if (mesh.source != "file" && mesh.source != "surface")
        {
          deallog << "Mesh / Source = " << mesh.source << ", no file"
                  << std::endl;
          continue;
        }
      const fs::path found =
        fs::weakly_canonical(file.parent_path() / mesh.file_name);
      const std::string in_tree = fs::relative(found, root).string();
      deallog << mesh.file_name << " -> " << in_tree << ": "
              << (fs::exists(found) && in_tree.rfind("..", 0) != 0 ?
                    "a file of the project" :
                    "NOT in the project")
              << std::endl;
    }

  // 3. What the README names exists: scenes and organs.
  const std::string     readme = read_file((root / "README.md").string());
  std::set<std::string> named;
  const std::regex      path_pattern(
    R"((parameters/[A-Za-z0-9_.-]+\.prm|meshes/[A-Za-z0-9_./-]+\.(msh|obj|vtk)))");
  for (auto it =
         std::sregex_iterator(readme.begin(), readme.end(), path_pattern);
       it != std::sregex_iterator();
       ++it)
    named.insert((*it)[1].str());
  unsigned int missing = 0;
  for (const auto &n : named)
    // (Not the files the README's commands make: 'palpate mesh ...
    // meshes/my-liver.msh'.)
    if (!fs::exists(root / n) && n.find("my-") == std::string::npos)
      {
        ++missing;
        deallog << "  the README names " << n << ", which is NOT there"
                << std::endl;
      }
  deallog << "scenes and organs the README names: "
          << (named.size() >= 3 ? "several" : "FEW") << ", missing " << missing
          << " (must be 0)" << std::endl;

  // 4. A scene copied out of parameters/ (here: into the test's directory)
  // still finds the organ its '../meshes/...' names, through the fallback
  // to the shipped scenes' directory; a missing file is reported with
  // every place looked.
  write_file("copied.prm",
             read_file((root / "parameters" / "paper-stvk.prm").string()));
  const palpate::Scene copied = palpate::Scene::read("copied.prm");
  const fs::path found(copied.resolve_path(copied.parameters.mesh.file_name));
  deallog << "copied scene: its mesh is found: "
          << ok(
               fs::exists(found) &&
               fs::equivalent(found, root / "meshes/liver-tetgen/liver501.msh"))
          << std::endl;
  const std::string looked = copied.where_looked("../meshes/none.msh");
  deallog << "a missing file: the message names the current directory and "
             "parameters/: "
          << ok(looked.find(fs::current_path().parent_path().string() +
                            "/meshes/none.msh") != std::string::npos &&
                looked.find(root.string() + "/meshes/none.msh") !=
                  std::string::npos)
          << std::endl;
  try
    {
      palpate::Mesh::create(
        palpate::Scene::read("copied.prm",
                             {"Mesh/File name=../meshes/none.msh"}));
      deallog << "a missing mesh: NOT refused" << std::endl;
    }
  catch (const palpate::InputError &e)
    {
      const std::string what = e.what();
      deallog << "a missing mesh: refused, naming the --set and where it "
                 "looked: "
              << ok(what.find("--set Mesh/File name=../meshes/none.msh") !=
                      std::string::npos &&
                    what.find("looked for") != std::string::npos &&
                    what.find(root.string() + "/meshes/none.msh") !=
                      std::string::npos)
              << std::endl;
    }
  fs::remove("copied.prm");
}
