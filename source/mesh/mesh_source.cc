// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

#include <palpate/base/plugins.templates.h>
#include <palpate/mesh/mesh_source.h>
#include <palpate/scene/scene.h>

namespace palpate
{
  bool
  MeshSource::from_file() const
  {
    return false;
  }



  std::string
  MeshSource::description(const Mesh &mesh, const Scene &) const
  {
    return mesh.description();
  }



  std::optional<MeshSource::Finer>
  MeshSource::make_finer(Parameters::Mesh &, const Scene &) const
  {
    return std::nullopt;
  }



  std::unique_ptr<MeshSource>
  MeshSource::create(const Scene &scene)
  {
    const auto &m   = scene.parameters.mesh;
    const auto  own = m.own.find(m.source);
    try
      {
        return MeshSourceRegistry::create(m.source,
                                          own == m.own.end() ?
                                            Plugins::Entries() :
                                            own->second,
                                          scene);
      }
    catch (const Plugins::EntryError &e)
      {
        // No such plug-in is an error of Source itself (a scene built in
        // code; a file's Selection pattern refuses the name before).
        throw scene.error(e.entry == m.source ?
                            "Mesh/Source" :
                            "Mesh/" + m.source + "/" + e.entry,
                          e.problem,
                          e.fix);
      }
  }



  void
  MeshSource::check_no_file_named(const Scene &scene)
  {
    const auto &p = scene.parameters.mesh;
    if (!p.file_name.empty() && scene.sets("Mesh/File name"))
      throw scene.error("Mesh/File name",
                        "a file is named, but Source = " + p.source +
                          " generates the mesh and ignores it",
                        "set Source = file (a tetrahedral mesh) or Source = "
                        "surface (an organ's surface, meshed by palpate), or "
                        "remove File name.");
  }



  InputError
  MeshSource::read_by(const InputError  &e,
                      const Scene       &scene,
                      const std::string &what)
  {
    return InputError(e.file(),
                      e.line(),
                      e.entry(),
                      e.problem(),
                      e.fix() + " (The scene '" + scene.file() + "' reads " +
                        what + " through Mesh / File name.)");
  }



  template class Plugins::Registry<MeshSource, Scene>;
} // namespace palpate
