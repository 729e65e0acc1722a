// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

#include <palpate/base/plugins.templates.h>
#include <palpate/mesh/probe_tip.h>
#include <palpate/scene/scene.h>

namespace palpate
{
  bool
  ProbeTip::is_sphere() const
  {
    return false;
  }



  void
  ProbeTip::place(const Scene &,
                  const Mesh &,
                  const std::set<unsigned int> &,
                  NodeSelection &,
                  const NodeSelection::SphereSizing &) const
  {}



  std::string
  ProbeTip::report(const Scene &, const NodeSelection &) const
  {
    return "";
  }



  std::string
  ProbeTip::effect(const NodeSelection &) const
  {
    return "";
  }



  std::unique_ptr<ProbeTip>
  ProbeTip::create(const Scene &scene)
  {
    const auto &a   = scene.parameters.boundary_conditions.active_node;
    const auto  own = a.own.find(a.tip);
    try
      {
        return ProbeTipRegistry::create(
          a.tip, own == a.own.end() ? Plugins::Entries() : own->second, scene);
      }
    catch (const Plugins::EntryError &e)
      {
        // No such plug-in is an error of Tip itself (a scene built in
        // code; a file's Selection pattern refuses the name before).
        const std::string section = "Boundary conditions/Active node/";
        throw scene.error(section +
                            (e.entry == a.tip ? "Tip" : a.tip + "/" + e.entry),
                          e.problem,
                          e.fix);
      }
  }



  void
  ProbeTip::check_radius(const Scene &scene, const std::string &what)
  {
    using namespace Limits;
    const auto &a = scene.parameters.boundary_conditions.active_node;
    if (!(a.tip_radius > 0))
      throw scene.error("Boundary conditions/Active node/Tip radius",
                        "Tip = " + a.tip + " needs a positive Tip radius",
                        "set Tip radius in metres, e.g. 0.01 for a probe of "
                        "1 cm radius.");
    if (a.tip_radius > max_sphere_radius)
      throw scene.error("Boundary conditions/Active node/Tip radius",
                        what + " of " +
                          Utilities::to_string_apart(a.tip_radius,
                                                     max_sphere_radius) +
                          " m radius is no probe (at most " +
                          Utilities::to_string(max_sphere_radius, 3) + " m)",
                        "give the radius in metres (a 1 cm probe: 0.01).");
  }



  template class Plugins::Registry<ProbeTip, Scene>;
} // namespace palpate
