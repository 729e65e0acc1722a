// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

// A probe tip is one file (issue 46, doc/extending.md): this test defines a
// new tip, "ring" (a hollow probe: the free surface nodes between Inner
// radius and Outer radius of the active node move with it), with entries of
// its own, in this file only, and registers it. Without touching palpate:
// - Active node / Tip accepts its name (the Selection pattern comes from
//   the registry), the parameter reference describes it, and its own
//   subsection (Boundary conditions / Active node / ring) is declared and
//   read;
// - NodeSelection::create() asks it to place itself, the scene report's
//   probe tip line and effect are its words, and a static solve presses
//   through its nodes: a ring of 4 to 6 mm on a 5 mm grid glues the same
//   four nodes as Tip = glued nodes with Tip radius = 6 mm, so the two
//   forces agree;
// - values its checks refuse are input errors naming the entry, the file
//   and the line: its own radii (check_parameters), the shared Tip radius
//   it does not read (check_scene), the contact patch that needs a sphere
//   (the checks of every tip), and a ring that holds no node (place()).

#include <palpate/app/scene_report.h>
#include <palpate/base/exceptions.h>
#include <palpate/mesh/mesh.h>
#include <palpate/mesh/probe_tip.h>
#include <palpate/scene/scene.h>

#include <deal.II/base/parameter_handler.h>

#include <cmath>
#include <sstream>

#include "../tests.h"

namespace
{
  /** The free surface nodes between Inner radius and Outer radius (m) of
   * the active node, glued to it. */
  class Ring : public palpate::ProbeTip
  {
  public:
    Ring(const double inner, const double outer)
      : inner(inner)
      , outer(outer)
    {}

    static void
    declare_parameters(dealii::ParameterHandler &prm)
    {
      prm.declare_entry("Inner radius",
                        "0.004",
                        dealii::Patterns::Double(0.),
                        "Inner radius of the ring (m).");
      prm.declare_entry("Outer radius",
                        "0.006",
                        dealii::Patterns::Double(0.),
                        "Outer radius of the ring (m).");
    }

    /** When the scene is read: a ring needs some width. */
    static void
    check_parameters(const dealii::ParameterHandler &own)
    {
      if (!(own.get_double("Outer radius") > own.get_double("Inner radius")))
        throw palpate::Plugins::EntryError("Outer radius",
                                           "must be larger than Inner radius",
                                           "give the radii in metres.");
    }

    /** The ring has radii of its own: a Tip radius would be ignored. */
    static void
    check_scene(const palpate::Scene &scene)
    {
      if (scene.parameters.boundary_conditions.active_node.tip_radius > 0)
        throw scene.error("Boundary conditions/Active node/Tip radius",
                          "Tip = ring has radii of its own",
                          "set its Inner radius and Outer radius instead.");
    }

    static std::unique_ptr<palpate::ProbeTip>
    create(const dealii::ParameterHandler &own, const palpate::Scene &)
    {
      return std::make_unique<Ring>(own.get_double("Inner radius"),
                                    own.get_double("Outer radius"));
    }

    void
    place(const palpate::Scene         &scene,
          const palpate::Mesh          &mesh,
          const std::set<unsigned int> &fixed,
          palpate::NodeSelection       &selection,
          const palpate::NodeSelection::SphereSizing &) const override
    {
      const auto &x = mesh.vertices();
      for (unsigned int v = 0; v < x.size(); ++v)
        if (mesh.on_surface()[v] && fixed.count(v) == 0)
          {
            const double d =
              palpate::Utilities::distance(x[v], x[selection.active_vertex]);
            if (d >= inner && d <= outer)
              selection.tip_vertices.push_back(v);
          }
      if (selection.tip_vertices.empty())
        throw scene.error("Boundary conditions/Active node/ring/Outer radius",
                          "the ring holds no surface node",
                          "make it wider than the mesh's spacing.");
    }

    std::string
    report(const palpate::Scene &,
           const palpate::NodeSelection &nodes) const override
    {
      return "a ring of " + std::to_string(nodes.tip_vertices.size()) +
             " nodes, " + palpate::Utilities::to_string(1000 * inner, 3) +
             " to " + palpate::Utilities::to_string(1000 * outer, 3) +
             " mm from the active node";
    }

    std::string
    effect(const palpate::NodeSelection &nodes) const override
    {
      return "ring probe (" + std::to_string(nodes.tip_vertices.size()) +
             " nodes)";
    }

  private:
    const double inner, outer;
  };
} // namespace

PALPATE_REGISTER_PROBE_TIP(Ring,
                           "ring",
                           "the free surface nodes between Inner radius and "
                           "Outer radius of the active node follow the HIP")



namespace
{
  /** A beam on a 5 mm grid, clamped at x = 0 and pressed at the middle of
   * its top face by the tip set by @p tip (lines of subsection Active
   * node); @p more is added at the end. */
  std::string
  scene_text(const std::string &tip, const std::string &more = "")
  {
    return R"(subsection Mesh
  set Source = beam
  subsection Beam
    set Subdivisions = 20, 4, 4
  end
end
subsection Boundary conditions
  subsection Fixed nodes
    set Selection    = boundary id
    set Boundary ids = 0
  end
  subsection Active node
    set Point                   = 0.05, 0, 0.01
    set Prescribed displacement = 0, 0, -0.002
)" + tip + R"(  end
end
)" + more;
  }

  const std::string ring_tip = R"(    set Tip = ring
    subsection ring
      set Inner radius = 0.004
      set Outer radius = 0.006
    end
)";

  /** The force of a static solve of @p scene to its Prescribed
   * displacement (N). */
  palpate::Utilities::Point3
  pressed_force(const palpate::Scene &scene)
  {
    const Body           body(scene);
    palpate::StateSolver solver(body.mesh, body.nodes, scene.parameters);
    const palpate::State state = solver.solve(
      solver.rest_state(),
      scene.parameters.boundary_conditions.active_node.prescribed_displacement);
    return state.force;
  }

  /** Read the scene @p text as the file @p name and set it up: the error
   * it gives, as the output shows it, or "" if there is none. */
  std::string
  refusal(const std::string &name, const std::string &text)
  {
    write_file(name, text);
    try
      {
        const palpate::Scene scene = palpate::Scene::read(name);
        const Body           body(scene);
        return "";
      }
    catch (const palpate::InputError &e)
      {
        return e.entry() + " (line " + std::to_string(e.line()) +
               "): " + e.problem();
      }
  }

  /** Log the lines of the scene report of @p body that start with
   * @p key. */
  void
  log_report_lines(const Body &body, const std::string &key)
  {
    std::ostringstream report;
    palpate::print_scene_report(report, body.scene, body.mesh, body.nodes);
    std::istringstream lines(report.str());
    std::string        line;
    while (std::getline(lines, line))
      if (line.rfind(key, 0) == 0)
        deallog << line << std::endl;
  }
} // namespace



int
main(int argc, char **argv)
{
  palpate::Environment env(argc, argv);
  initlog();

  deallog << "Active node / Tip: one of "
          << palpate::Plugins::selection("probe tip") << std::endl;
  std::ostringstream reference;
  palpate::print_parameters(reference, palpate::ParameterFormat::markdown);
  deallog << "the parameter reference describes the ring: "
          << ok(reference.str().find(
                  "ring: the free surface nodes between Inner radius") !=
                std::string::npos)
          << std::endl;

  write_file("ring.prm", scene_text(ring_tip));
  const palpate::Scene ring = palpate::Scene::read("ring.prm");
  const Body           body(ring);
  deallog << "ring: " << body.nodes.tip_vertices.size()
          << " nodes move with the active node, "
          << body.mesh.node_name(body.nodes.active_vertex) << std::endl;
  log_report_lines(body, "  probe tip:");
  log_report_lines(body, "  on:");

  write_file("glued.prm",
             scene_text("    set Tip = glued nodes\n"
                        "    set Tip radius = 0.006\n"));
  const palpate::Scene glued   = palpate::Scene::read("glued.prm");
  const auto           f_ring  = pressed_force(ring);
  const auto           f_glued = pressed_force(glued);
  // The beam is symmetric about y = 0: the force's y component is
  // round-off, shown as 0.
  auto shown = f_ring;
  for (double &f : shown)
    if (std::abs(f) < 1e-12 * palpate::Utilities::norm(f_ring))
      f = 0;
  deallog << "pressed 2 mm down through the ring: force ("
          << palpate::Utilities::to_string(shown, 4) << ") N" << std::endl;
  deallog << "the same as glued nodes of 6 mm (to 1e-9 of it): "
          << ok(palpate::Utilities::distance(f_ring, f_glued) <=
                1e-9 * palpate::Utilities::norm(f_glued))
          << std::endl;

  deallog << "Outer radius below Inner radius: "
          << refusal("narrow.prm",
                     scene_text("    set Tip = ring\n"
                                "    subsection ring\n"
                                "      set Outer radius = 0.003\n"
                                "    end\n"))
          << std::endl;
  deallog << "Tip radius set: "
          << refusal("radius.prm",
                     scene_text(ring_tip + "    set Tip radius = 0.01\n"))
          << std::endl;
  // The point's refusal of a radius offers the tips that take one, asked
  // of each registered tip: the ring, which has radii of its own, is not.
  try
    {
      write_file("point.prm",
                 scene_text("    set Tip = point\n"
                            "    set Tip radius = 0.01\n"));
      palpate::Scene::read("point.prm");
      deallog << "a point with a radius: ACCEPTED" << std::endl;
    }
  catch (const palpate::InputError &e)
    {
      deallog << "a point with a radius: " << e.problem()
              << "; fix: " << e.fix() << std::endl;
    }
  deallog << "contact patch: "
          << refusal("patch.prm",
                     scene_text(ring_tip,
                                "subsection State space\n"
                                "  set Interpolation = contact patch\n"
                                "end\n"))
          << std::endl;
  deallog << "a ring between the grid's nodes: "
          << refusal("empty.prm",
                     scene_text("    set Tip = ring\n"
                                "    subsection ring\n"
                                "      set Inner radius = 0.001\n"
                                "      set Outer radius = 0.002\n"
                                "    end\n"))
          << std::endl;
}
