// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

// A mesh source and a fixed region are one file each (issue 46,
// doc/extending.md): this test defines a new mesh source, "cube", and a new
// fixed region, "sphere", each with entries of its own, in this file only,
// and registers them. Without touching palpate:
// - Mesh / Source and Fixed nodes / Selection accept their names (their
//   Selection patterns come from the registries), and their own
//   subsections (Mesh / cube, Boundary conditions / Fixed nodes / sphere)
//   are declared and read;
// - Mesh::create() builds the cube, NodeSelection::create() fixes the
//   sphere's nodes and the scene report's words come from the region;
// - a static solve presses the cube's top 2 mm down: the force and the
//   reactions are the state solver's numbers on that body;
// - values their checks refuse are input errors naming the entry, the
//   file and the line: the region's own Radius (check_parameters, when the
//   scene is read), the shared File name a generator does not read
//   (check_scene), and a sphere that holds no node of the mesh.

#include <palpate/base/exceptions.h>
#include <palpate/mesh/fixed_region.h>
#include <palpate/mesh/generators.h>
#include <palpate/mesh/mesh_source.h>

#include <deal.II/base/parameter_handler.h>

#include <algorithm>
#include <cmath>

#include "../tests.h"

namespace
{
  using palpate::Utilities::Point3;

  /** A cube [0, Side]^3 (m) of Divisions^3 bricks, six tetrahedra each. */
  class Cube : public palpate::MeshSource
  {
  public:
    Cube(const double side, const unsigned int divisions)
      : side(side)
      , divisions(divisions)
    {}

    static void
    declare_parameters(dealii::ParameterHandler &prm)
    {
      prm.declare_entry("Side",
                        "0.05",
                        dealii::Patterns::Double(),
                        "Edge length of the cube (m).");
      prm.declare_entry("Divisions",
                        "4",
                        dealii::Patterns::Integer(1, 20),
                        "Bricks along each edge (dimensionless).");
    }

    static std::unique_ptr<palpate::MeshSource>
    create(const dealii::ParameterHandler &own, const palpate::Scene &)
    {
      const double side = own.get_double("Side");
      if (!(side >= 0.002 && side <= 1))
        throw palpate::Plugins::EntryError("Side",
                                           "must be between 2 mm and 1 m",
                                           "give the edge in metres.");
      return std::make_unique<Cube>(side, own.get_integer("Divisions"));
    }

    /** A generator reads no file: the interface's check says so. */
    static void
    check_scene(const palpate::Scene &scene)
    {
      check_no_file_named(scene);
    }

    palpate::Mesh
    create_mesh(const palpate::Scene &) const override
    {
      std::vector<double> x;
      for (unsigned int i = 0; i <= divisions; ++i)
        x.push_back(side * i / divisions);
      return palpate::Mesh(palpate::generate_tensor_block(x, x, x),
                           1.0,
                           "the cube generator");
    }

  private:
    const double       side;
    const unsigned int divisions;
  };

  /** The nodes within Radius (m) of Center, of them the surface ones if
   * Surface nodes only (a shared entry of Fixed nodes). */
  class Sphere : public palpate::FixedRegion
  {
  public:
    Sphere(const Point3 &center, const double radius, const bool surface_only)
      : center(center)
      , radius(radius)
      , surface_only(surface_only)
    {}

    static void
    declare_parameters(dealii::ParameterHandler &prm)
    {
      prm.declare_entry(
        "Center",
        "0, 0, 0",
        dealii::Patterns::List(dealii::Patterns::Double(), 3, 3, ","),
        "Centre of the sphere (m).");
      prm.declare_entry("Radius",
                        "0.01",
                        dealii::Patterns::Double(),
                        "Radius of the sphere (m).");
    }

    /** When the scene is read: a sphere without volume holds nothing. */
    static void
    check_parameters(const dealii::ParameterHandler &own)
    {
      if (!(own.get_double("Radius") > 0))
        throw palpate::Plugins::EntryError("Radius",
                                           "must be positive",
                                           "give the radius in metres.");
    }

    static std::unique_ptr<palpate::FixedRegion>
    create(const dealii::ParameterHandler &own, const palpate::Scene &scene)
    {
      return std::make_unique<Sphere>(
        palpate::Utilities::parse_point(own.get("Center")),
        own.get_double("Radius"),
        scene.parameters.boundary_conditions.fixed_nodes.surface_nodes_only);
    }

    Selected
    select(const palpate::Scene &, const palpate::Mesh &mesh) const override
    {
      return select_contained(mesh, surface_only);
    }

    std::string
    entry() const override
    {
      return "Boundary conditions/Fixed nodes/sphere/Radius";
    }

    std::string
    description(const Selected &) const override
    {
      return "nodes within " + palpate::Utilities::to_string(radius, 3) +
             " m of (" + palpate::Utilities::to_string(center, 3) + ")";
    }

    bool
    is_place() const override
    {
      return true;
    }

    bool
    contains(const Point3 &x) const override
    {
      return palpate::Utilities::distance(x, center) <= radius;
    }

  private:
    const Point3 center;
    const double radius;
    const bool   surface_only;
  };
} // namespace

PALPATE_REGISTER_MESH_SOURCE(Cube, "cube", "a cube of tetrahedra, of Side")
PALPATE_REGISTER_FIXED_REGION(Sphere,
                              "sphere",
                              "the nodes within Radius of Center")



namespace
{
  /** A 4 cm cube held by the nodes of its bottom face within @p radius of
   * the face's centre, pressed at the middle of its top face; @p more is
   * added to the Mesh subsection. */
  std::string
  scene_text(const std::string &radius, const std::string &more = "")
  {
    return R"(subsection Mesh
  set Source = cube
  subsection cube
    set Side      = 0.04
    set Divisions = 4
  end
)" + more + R"(end
subsection Boundary conditions
  subsection Fixed nodes
    set Selection = sphere
    subsection sphere
      set Center = 0.02, 0.02, 0
      set Radius = )" +
           radius + R"(
    end
  end
  subsection Active node
    set Point                   = 0.02, 0.02, 0.04
    set Prescribed displacement = 0, 0, -0.002
  end
end
)";
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
} // namespace



int
main(int argc, char **argv)
{
  palpate::Environment env(argc, argv);
  initlog();

  deallog << "Mesh / Source: one of "
          << palpate::Plugins::selection("mesh source") << std::endl;
  deallog << "Fixed nodes / Selection: one of "
          << palpate::Plugins::selection("fixed region") << std::endl;

  write_file("cube.prm", scene_text("0.015"));
  const palpate::Scene scene = palpate::Scene::read("cube.prm");
  const Body           body(scene);
  const auto          &mesh  = body.mesh;
  const auto          &nodes = body.nodes;
  deallog << "mesh: " << mesh.description() << ", " << mesh.n_vertices()
          << " nodes (" << mesh.n_surface_vertices() << " on the surface), "
          << mesh.n_cells() << " tetrahedra, volume " << mesh.volume() << " m^3"
          << std::endl;
  deallog << "fixed: " << nodes.fixed_vertices.size() << " nodes, "
          << nodes.fixed_description << std::endl;
  double farthest = 0;
  for (const unsigned int v : nodes.fixed_vertices)
    farthest = std::max(farthest,
                        palpate::Utilities::distance(mesh.vertices()[v],
                                                     Point3{{0.02, 0.02, 0}}));
  deallog << "every fixed node within the radius: " << ok(farthest <= 0.015)
          << std::endl;
  deallog << "active: " << mesh.node_name(nodes.active_vertex) << " at ("
          << palpate::Utilities::to_string(mesh.vertices()[nodes.active_vertex],
                                           4)
          << ") m" << std::endl;

  palpate::StateSolver solver(mesh, nodes, scene.parameters);
  const palpate::State state = solver.solve(
    solver.rest_state(),
    scene.parameters.boundary_conditions.active_node.prescribed_displacement);
  deallog << "pressed 2 mm down: "
          << (state.converged ? "converged" : state.message) << ", force ("
          << palpate::Utilities::to_string(state.force, 4) << ") N"
          << std::endl;
  // The fixed nodes' reactions balance the probe's force.
  const auto  r         = solver.system().nodal_residual(state.solution);
  const auto &component = solver.system().dof_components();
  Point3      sum{{0, 0, 0}};
  for (std::size_t d = 0; d < r.size(); ++d)
    if (component[d] < 3)
      sum[component[d]] += r[d];
  deallog << "reactions balance the force (to 1e-6 of it): "
          << ok(palpate::Utilities::norm(sum) <=
                1e-6 * palpate::Utilities::norm(state.force))
          << std::endl;

  deallog << "Radius = 0: " << refusal("zero.prm", scene_text("0"))
          << std::endl;
  deallog << "a file named: "
          << refusal("named.prm",
                     scene_text("0.015", "  set File name = cube.msh\n"))
          << std::endl;
  deallog << "Radius = 0.001 (one node): "
          << refusal("small.prm", scene_text("0.001")) << std::endl;
}
