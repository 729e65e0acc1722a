// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

#include <palpate/hyperelastic/effect.h>
#include <palpate/hyperelastic/material.h>
#include <palpate/scene/parameters.h>

#include <deal.II/base/parameter_handler.h>

#include <iomanip>
#include <sstream>
#include <stdexcept>
#include <tuple>

namespace palpate
{
  namespace Parameters
  {

    using namespace dealii;

    namespace
    {
      /** The values of the own entries of each plug-in of @p kind, from
       * their subsections (declared only by plug-ins that have entries). */
      std::map<std::string, Plugins::Entries>
      own_entries(ParameterHandler &prm, const std::string &kind)
      {
        std::map<std::string, Plugins::Entries> own;
        for (const auto &plugin : Plugins::declarations(kind))
          {
            const auto declared =
              Plugins::declared_entries(plugin.declare_parameters);
            if (declared.empty())
              continue;
            auto &entries = own[plugin.name];
            prm.enter_subsection(plugin.name);
            for (const auto &entry : declared)
              entries[entry.first] = prm.get(entry.first);
            prm.leave_subsection();
          }
        return own;
      }

      /**
       * The entry @p entry that chooses a plug-in of @p kind (its choices
       * @p other_choices and the plug-ins' names, its documentation
       * @p intro, each plug-in's description, then @p outro), and the
       * subsection of each plug-in that has entries of its own.
       */
      void
      declare_plugin_choice(ParameterHandler  &prm,
                            const std::string &kind,
                            const std::string &entry,
                            const std::string &default_value,
                            std::string        doc,
                            const std::string &outro,
                            const std::string &other_choices = "")
      {
        for (const auto &plugin : Plugins::declarations(kind))
          doc += " " + plugin.name + ": " + plugin.description + ";";
        if (outro.empty())
          doc.back() = '.';
        else
          doc += outro;
        prm.declare_entry(entry,
                          default_value,
                          Patterns::Selection(other_choices +
                                              Plugins::selection(kind)),
                          doc);
        for (const auto &plugin : Plugins::declarations(kind))
          if (!Plugins::declared_entries(plugin.declare_parameters).empty())
            {
              prm.enter_subsection(plugin.name);
              plugin.declare_parameters(prm);
              prm.leave_subsection();
            }
      }



      /** Pattern of a 3-vector entry "x, y, z". */
      Patterns::List
      point_pattern()
      {
        return Patterns::List(Patterns::Double(), 3, 3, ",");
      }

      Point3
      get_point(ParameterHandler &prm, const std::string &name)
      {
        return Utilities::parse_point(prm.get(name));
      }

      template <typename T>
      std::vector<T>
      get_list(ParameterHandler &prm, const std::string &name)
      {
        std::vector<T> values;
        for (const auto &piece : Utilities::split(prm.get(name), ','))
          if (!piece.empty())
            values.push_back(static_cast<T>(std::stol(piece)));
        return values;
      }
    } // namespace



    void
    Mesh::declare_parameters(ParameterHandler &prm)
    {
      prm.enter_subsection("Mesh");
      {
        prm.declare_entry("Source",
                          "blob",
                          Patterns::Selection("file|surface|beam|blob"),
                          "Where the tetrahedral mesh of the body comes from: "
                          "a mesh file; an organ's closed surface (File name: "
                          ".stl, .obj, .ply, .vtk or .vtp), meshed by palpate "
                          "(see subsection Surface) and kept for the next "
                          "run; or one of the built-in generators (a "
                          "rectangular beam, an organ-like blob), which need "
                          "no external data.");
        prm.declare_entry(
          "File name",
          "",
          Patterns::FileName(),
          "Mesh file read when Source = file: Gmsh .msh (format 2.2 or "
          "v1, ASCII), legacy VTK .vtk (ASCII UNSTRUCTURED_GRID) or "
          ".vtu (ASCII, or binary inline, appended, raw or zlib-compressed, "
          "in either byte order). Only linear "
          "tetrahedra form the body; triangles set boundary ids. With "
          "Source = surface: the organ's closed surface (.stl, .obj, .ply, "
          ".vtk POLYDATA, .vtp). A relative path is looked up against the "
          "scene file's directory first (see 'Relative paths' at the top "
          "of doc/parameters.md).");
        prm.declare_entry("Scale factor",
                          "1",
                          Patterns::Double(0.),
                          "Metres per length unit of the mesh file: every "
                          "coordinate is multiplied by it (m/unit), from "
                          "1e-9 to 1e6. The generators produce metres and "
                          "ignore it.");

        prm.enter_subsection("Beam");
        {
          prm.declare_entry("Length",
                            "0.1",
                            Patterns::Double(0.),
                            "Length of the beam along x (m). The beam spans "
                            "[0, Length] x [-Width/2, Width/2] x "
                            "[-Height/2, Height/2].");
          prm.declare_entry("Width",
                            "0.02",
                            Patterns::Double(0.),
                            "Width of the beam along y (m).");
          prm.declare_entry("Height",
                            "0.02",
                            Patterns::Double(0.),
                            "Height of the beam along z (m).");
          prm.declare_entry("Subdivisions",
                            "10, 2, 2",
                            Patterns::List(Patterns::Integer(1), 3, 3, ","),
                            "Number of hexahedral blocks along x, y, z; each "
                            "block is split into tetrahedra (dimensionless).");
        }
        prm.leave_subsection();

        prm.enter_subsection("Surface");
        {
          prm.declare_entry("Target nodes",
                            "1500",
                            Patterns::Integer(50, 200000),
                            "With Source = surface: about how many nodes the "
                            "volume mesh has (within 10 %). The paper's "
                            "livers have 501 and 2011; each state costs "
                            "roughly in proportion.");
          prm.declare_entry("Time limit",
                            "60",
                            Patterns::Double(0.01),
                            "With Source = surface: the most the meshing may "
                            "take (s); Gmsh is stopped after it, so a bad "
                            "surface cannot hang palpate.");
          prm.declare_entry(
            "Volume mesh directory",
            "meshes",
            Patterns::DirectoryName(),
            "With Source = surface: where palpate keeps the volume meshes it "
            "makes (Gmsh 2.2, in metres), relative to the current "
            "directory. A mesh is reused while the surface file, the scale "
            "factor and the target are the same.");
          prm.declare_entry(
            "Refinement size",
            "0",
            Patterns::Double(0., 1.),
            "With Source = surface: the element size (m) near where the "
            "probe works, within Refinement radius of Boundary conditions / "
            "Active node / Point; beyond it the size grows by 0.3 m per m of "
            "distance up to the size that Target nodes sets. A probe's "
            "contact needs elements well below its radius where it touches "
            "(a third of the sphere's radius is a good start; "
            "doc/benchmarks/convergence.md), and nothing of the kind "
            "elsewhere. 0: a uniform mesh. With a refinement, Target nodes sets "
            "the size away from the probe (that of a uniform mesh of so many "
            "nodes) and the refined region adds its nodes.");
          prm.declare_entry(
            "Refinement radius",
            "0.02",
            Patterns::Double(0., 10.),
            "With Refinement size > 0: the radius (m) around Active node / "
            "Point that is meshed at Refinement size: the region the probe "
            "explores.");
        }
        prm.leave_subsection();

        prm.enter_subsection("Blob");
        {
          prm.declare_entry("Semi-axes",
                            "0.125, 0.09, 0.07",
                            point_pattern(),
                            "Semi-axes of the ellipsoid the organ-like blob is "
                            "built from, along x, y, z (m). The default gives "
                            "a liver-sized body, 25 cm long.");
          prm.declare_entry(
            "Refinements",
            "1",
            Patterns::Integer(0, 3),
            "Resolution r of the blob: a cube of 3 (r + 1) blocks per "
            "axis, each split into 5 tetrahedra, is mapped "
            "onto the ball (dimensionless). 1 gives 343 nodes "
            "(218 on the surface) and 1080 tetrahedra.");
        }
        prm.leave_subsection();
      }
      prm.leave_subsection();
    }



    bool
    Mesh::operator==(const Mesh &o) const
    {
      const auto entries = [](const Mesh &m) {
        return std::tie(m.source,
                        m.file_name,
                        m.scale_factor,
                        m.beam_length,
                        m.beam_width,
                        m.beam_height,
                        m.beam_subdivisions_length,
                        m.beam_subdivisions_width,
                        m.beam_subdivisions_height,
                        m.blob_semi_axes,
                        m.blob_refinements,
                        m.surface_target_nodes,
                        m.surface_time_limit,
                        m.surface_mesh_directory,
                        m.surface_fine_size,
                        m.surface_fine_radius);
      };
      return entries(*this) == entries(o);
    }



    void
    Mesh::parse_parameters(ParameterHandler &prm)
    {
      prm.enter_subsection("Mesh");
      {
        source       = prm.get("Source");
        file_name    = prm.get("File name");
        scale_factor = prm.get_double("Scale factor");

        prm.enter_subsection("Beam");
        {
          beam_length    = prm.get_double("Length");
          beam_width     = prm.get_double("Width");
          beam_height    = prm.get_double("Height");
          const auto sub = get_list<unsigned int>(prm, "Subdivisions");
          beam_subdivisions_length = sub[0];
          beam_subdivisions_width  = sub[1];
          beam_subdivisions_height = sub[2];
        }
        prm.leave_subsection();

        prm.enter_subsection("Surface");
        {
          surface_target_nodes   = prm.get_integer("Target nodes");
          surface_time_limit     = prm.get_double("Time limit");
          surface_mesh_directory = prm.get("Volume mesh directory");
          surface_fine_size      = prm.get_double("Refinement size");
          surface_fine_radius    = prm.get_double("Refinement radius");
        }
        prm.leave_subsection();

        prm.enter_subsection("Blob");
        {
          blob_semi_axes   = get_point(prm, "Semi-axes");
          blob_refinements = prm.get_integer("Refinements");
        }
        prm.leave_subsection();
      }
      prm.leave_subsection();
    }



    void
    FixedNodes::declare_parameters(ParameterHandler &prm)
    {
      prm.enter_subsection("Fixed nodes");
      {
        prm.declare_entry(
          "Selection",
          "half-space",
          Patterns::Selection("boundary id|box|half-space|node list"),
          "How the nodes held at zero displacement (homogeneous Dirichlet) "
          "are chosen: all nodes on boundary faces with given ids, the nodes "
          "inside an axis-aligned box, the nodes in a half-space, or an "
          "explicit list of node numbers.");
        prm.declare_entry("Boundary ids",
                          "1",
                          Patterns::List(Patterns::Integer(0), 1),
                          "Boundary ids whose faces' nodes are fixed, for "
                          "Selection = boundary id (dimensionless). Gmsh "
                          "files set them with physical tags of triangles.");
        prm.declare_entry("Box lower corner",
                          "-1, -1, -1",
                          point_pattern(),
                          "Lower corner of the box for Selection = box, in "
                          "scaled mesh coordinates (m).");
        prm.declare_entry("Box upper corner",
                          "1, 1, 1",
                          point_pattern(),
                          "Upper corner of the box for Selection = box, in "
                          "scaled mesh coordinates (m).");
        prm.declare_entry("Half-space point",
                          "0, 0, -0.04",
                          point_pattern(),
                          "A point on the plane bounding the half-space for "
                          "Selection = half-space, in scaled mesh "
                          "coordinates (m).");
        prm.declare_entry("Half-space normal",
                          "0, 0, -1",
                          point_pattern(),
                          "Direction pointing into the fixed half-space: "
                          "nodes x with (x - point) . normal >= 0 are fixed "
                          "(dimensionless, need not be normalised).");
        prm.declare_entry("Node ids",
                          "",
                          Patterns::List(Patterns::Integer(0), 0),
                          "Node numbers for Selection = node list, as the "
                          "mesh file numbers them: Gmsh node tags, VTK/VTU "
                          "point indices (from 0), generator vertex indices. "
                          "The VTU output shows them as 'node_id'. Surface "
                          "nodes only does not apply to a list.");
        prm.declare_entry("Surface nodes only",
                          "true",
                          Patterns::Bool(),
                          "If true, only nodes on the surface of the body "
                          "inside the region are fixed (the body is held by "
                          "its skin, as by a ligament); if false, interior "
                          "nodes in the region are fixed as well.");
        prm.declare_entry(
          "Treatment",
          "elimination",
          Patterns::Selection("elimination|multipliers"),
          "How the zero displacement of fixed nodes enters the system: by "
          "eliminating their unknowns (smaller system), or by Lagrange "
          "multipliers as in the paper (their values are the reactions, N). "
          "Both give the same state.");
      }
      prm.leave_subsection();
    }



    void
    FixedNodes::parse_parameters(ParameterHandler &prm)
    {
      prm.enter_subsection("Fixed nodes");
      {
        selection          = prm.get("Selection");
        boundary_ids       = get_list<unsigned int>(prm, "Boundary ids");
        box_lower_corner   = get_point(prm, "Box lower corner");
        box_upper_corner   = get_point(prm, "Box upper corner");
        half_space_point   = get_point(prm, "Half-space point");
        half_space_normal  = get_point(prm, "Half-space normal");
        node_ids           = get_list<long>(prm, "Node ids");
        surface_nodes_only = prm.get_bool("Surface nodes only");
        treatment          = prm.get("Treatment");
      }
      prm.leave_subsection();
    }



    void
    ActiveNode::declare_parameters(ParameterHandler &prm)
    {
      prm.enter_subsection("Active node");
      {
        prm.declare_entry("Selection",
                          "nearest surface node",
                          Patterns::Selection("nearest surface node|node id"),
                          "How the active node (the surface node that follows "
                          "the haptic interaction point) is chosen.");
        prm.declare_entry("Point",
                          "0, 0, 0.07",
                          point_pattern(),
                          "For Selection = nearest surface node: the surface "
                          "node closest to this point becomes active, in "
                          "scaled mesh coordinates (m).");
        prm.declare_entry("Node id",
                          "0",
                          Patterns::Integer(0),
                          "For Selection = node id: the node number as the "
                          "mesh file numbers it (see Fixed nodes / Node ids).");
        prm.declare_entry(
          "Prescribed displacement",
          "0, 0, 0",
          point_pattern(),
          "Displacement of the active node from its rest position for a "
          "static solve (`palpate solve`, or `palpate scene.prm` with Run / "
          "Mode = static solve), in metres; `palpate solve --to x,y,z` "
          "overrides it. An interaction does not use it (the device moves "
          "the probe), but a sphere's size is checked against it.");
        prm.declare_entry(
          "Tip",
          "point",
          Patterns::Selection("point|glued nodes|sphere"),
          "What touches the organ. point: the paper's probe, the active node "
          "follows the haptic interaction point (HIP) and the force is its "
          "multiplier; the force of a point load is a property of the mesh "
          "(it tends to zero as the mesh is refined). glued nodes: every "
          "free surface node within Tip radius of the active node follows "
          "the HIP, and the force is the sum of their multipliers. sphere: "
          "a rigid sphere of radius Tip radius, whose centre moves with the "
          "HIP, in frictionless unilateral contact with the surface (no "
          "node is glued to it; the force is the resultant of the contact "
          "pressure, zero off the surface). At HIP = 0 the sphere touches "
          "the surface from outside, along the outward normal, at the point "
          "of the surface nearest to Point (Selection = nearest surface "
          "node) or at the node (Selection = node id); palpate solve --to X "
          "moves it by X. The contact acts at the surface nodes: a state "
          "where the sphere went between them (its centre less than half "
          "its radius from the deformed surface, as a sphere smaller than "
          "the triangles it pushes does) is a failure point, not a force.");
        prm.declare_entry(
          "Tip radius",
          "0",
          Patterns::Double(0.),
          "Radius (m) of the glued tip (Tip = glued nodes) or of the "
          "sphere (Tip = sphere). Must be 0 for Tip = point. The contact "
          "acts at nodes, so a sphere's radius must be at least twice the "
          "distance to the nearest surface node and two thirds of the "
          "longest surface edge within two radii of its path (with "
          "quadratic elements the edge midpoints count), both by a margin "
          "of 2.2 (then on the vertices) when pushed deeper than its "
          "radius, or, dragged along the surface, rising from 1 at half a "
          "radius deep to 2.2 at a radius; and a sphere may be pushed at "
          "most 1.5 radii deep. The depth is "
          "the push's component along the surface's inward normal at the "
          "probe (Prescribed displacement, solve's --to, a trajectory's "
          "deepest and farthest points); its sideways part slides the "
          "frictionless sphere. A refusal names the radius that passes, "
          "for a push no deeper than 0.22 of the way from the active node "
          "to the nearest fixed node (deeper, the radius found was "
          "measured to fail: the refusal names the push instead); an "
          "interaction whose trajectory goes deeper is warned.");
      }
      prm.leave_subsection();
    }



    void
    ActiveNode::parse_parameters(ParameterHandler &prm)
    {
      prm.enter_subsection("Active node");
      {
        selection               = prm.get("Selection");
        point                   = get_point(prm, "Point");
        node_id                 = prm.get_integer("Node id");
        prescribed_displacement = get_point(prm, "Prescribed displacement");
        tip_radius              = prm.get_double("Tip radius");
        const std::string t     = prm.get("Tip");
        tip                     = t == "sphere"      ? Tip::sphere :
                                  t == "glued nodes" ? Tip::glued_nodes :
                                                       Tip::point;
      }
      prm.leave_subsection();
    }



    void
    BoundaryConditions::declare_parameters(ParameterHandler &prm)
    {
      prm.enter_subsection("Boundary conditions");
      {
        FixedNodes::declare_parameters(prm);
        ActiveNode::declare_parameters(prm);
      }
      prm.leave_subsection();
    }



    void
    BoundaryConditions::parse_parameters(ParameterHandler &prm)
    {
      prm.enter_subsection("Boundary conditions");
      {
        fixed_nodes.parse_parameters(prm);
        active_node.parse_parameters(prm);
      }
      prm.leave_subsection();
    }



    void
    MaterialModel::set(const std::string &model,
                       const std::string &entry,
                       const std::string &value)
    {
      const auto *plugin = MaterialRegistry::find(model);
      AssertThrow(plugin != nullptr,
                  ExcMessage("no material model called " + model));
      auto &entries = models[model];
      if (entries.empty())
        entries = Plugins::declared_entries(plugin->declare_parameters);
      if (entries.count(entry) != 1)
        {
          // Said to a person (palpate serve's m key): which entries there are.
          std::string names;
          for (const auto &[name, v] : entries)
            names += (names.empty() ? "" : ", ") + name;
          throw std::invalid_argument("material model " + model +
                                      " has no entry '" + entry +
                                      "'; its entries are: " + names);
        }
      entries[entry] = value;
    }



    void
    MaterialModel::set(const std::string &model,
                       const std::string &entry,
                       const double       value)
    {
      std::ostringstream s;
      s << std::setprecision(17) << value;
      set(model, entry, s.str());
    }



    std::string
    MaterialModel::get(const std::string &model, const std::string &entry) const
    {
      const auto m = models.find(model);
      if (m != models.end() && m->second.count(entry) == 1)
        return m->second.at(entry);
      const auto *plugin = MaterialRegistry::find(model);
      AssertThrow(plugin != nullptr,
                  ExcMessage("no material model called " + model));
      const auto defaults =
        Plugins::declared_entries(plugin->declare_parameters);
      AssertThrow(defaults.count(entry) == 1,
                  ExcMessage("material model " + model + " has no entry " +
                             entry));
      return defaults.at(entry);
    }



    double
    MaterialModel::get_double(const std::string &model,
                              const std::string &entry) const
    {
      return std::stod(get(model, entry));
    }



    void
    MaterialModel::declare_parameters(ParameterHandler &prm)
    {
      prm.enter_subsection("Material model");
      {
        // The models are plug-ins: the choice and each model's subsection
        // come from the registry (doc/extending.md).
        std::string doc = "The hyperelastic constitutive law:";
        for (const auto &plugin : MaterialRegistry::plugins())
          doc += " " + plugin.name + ": " + plugin.description + ";";
        doc.back() = '.';
        prm.declare_entry("Model name",
                          "St.Venant-Kirchhoff",
                          Patterns::Selection(MaterialRegistry::selection()),
                          doc);
        prm.declare_entry("Density",
                          "1060",
                          Patterns::Double(0.),
                          "Mass density of the tissue in the reference "
                          "configuration (kg/m^3); used only when the "
                          "gravity effect is on. 1060 is liver tissue.");
        for (const auto &plugin : MaterialRegistry::plugins())
          {
            prm.enter_subsection(plugin.name);
            plugin.declare_parameters(prm);
            prm.leave_subsection();
          }
      }
      prm.leave_subsection();
    }



    void
    MaterialModel::parse_parameters(ParameterHandler &prm)
    {
      prm.enter_subsection("Material model");
      {
        model_name = prm.get("Model name");
        density    = prm.get_double("Density");
        models.clear();
        for (const auto &plugin : MaterialRegistry::plugins())
          {
            auto &entries = models[plugin.name];
            prm.enter_subsection(plugin.name);
            for (const auto &entry :
                 Plugins::declared_entries(plugin.declare_parameters))
              entries[entry.first] = prm.get(entry.first);
            prm.leave_subsection();
          }
      }
      // Build the chosen model once: values its patterns accept but
      // deal.II cannot convert (1e-320) fail here, where Scene::read()
      // names them. What makes no physical sense (nu = 0.5) is
      // Scene::validate()'s, with the entry's line.
      try
        {
          Material::create(*this);
        }
      catch (const Plugins::EntryError &)
        {}
      prm.leave_subsection();
    }



    void
    Discretization::declare_parameters(ParameterHandler &prm)
    {
      prm.enter_subsection("Discretization");
      {
        prm.declare_entry("Polynomial degree",
                          "1",
                          Patterns::Integer(1, 2),
                          "Degree of the Lagrange elements for the "
                          "displacement: 1 (linear tetrahedra, the paper's) "
                          "or 2 (quadratic, 10 nodes).");
        prm.declare_entry(
          "Quadrature order",
          "0",
          Patterns::Integer(0, 4),
          "Number of Gauss points per direction of the simplex quadrature "
          "rule (QGaussSimplex). 0 picks the rule that is exact for "
          "St.Venant-Kirchhoff: 1 point for linear, 3 for quadratic "
          "elements.");
      }
      prm.leave_subsection();
    }



    void
    Discretization::parse_parameters(ParameterHandler &prm)
    {
      prm.enter_subsection("Discretization");
      {
        polynomial_degree = prm.get_integer("Polynomial degree");
        quadrature_order  = prm.get_integer("Quadrature order");
      }
      prm.leave_subsection();
    }



    bool
    Effects::on(const std::string &name) const
    {
      const auto s = switches.find(name);
      return s != switches.end() && s->second;
    }



    void
    Effects::turn_on(const std::string &name, const bool on)
    {
      AssertThrow(EffectRegistry::find(name) != nullptr,
                  ExcMessage("no effect called " + name));
      switches[name] = on;
    }



    void
    Effects::set(const std::string &effect,
                 const std::string &entry,
                 const std::string &value)
    {
      const auto *plugin = EffectRegistry::find(effect);
      AssertThrow(plugin != nullptr, ExcMessage("no effect called " + effect));
      auto &entries = loads[effect];
      if (entries.empty())
        entries = Plugins::declared_entries(plugin->declare_parameters);
      AssertThrow(entries.count(entry) == 1,
                  ExcMessage("effect " + effect + " has no entry " + entry));
      entries[entry] = value;
    }



    void
    Effects::declare_parameters(ParameterHandler &prm)
    {
      prm.enter_subsection("Effects");
      {
        // The load effects are plug-ins: each one's switch and entries
        // come from the registry (doc/extending.md).
        for (const auto &plugin : EffectRegistry::plugins())
          {
            prm.declare_entry(plugin.name,
                              "false",
                              Patterns::Bool(),
                              "Whether to switch on " + plugin.description +
                                ". Off: nothing of it is built, assembled "
                                "or written.");
            plugin.declare_parameters(prm);
          }
        prm.declare_entry("Shape output",
                          "false",
                          Patterns::Bool(),
                          "Whether the whole displacement field is "
                          "interpolated for rendering during an interaction "
                          "(the shape interpolator) and written as VTU/PVD "
                          "frames: only while the probe moves, on the force "
                          "log's clock (seconds since the motion started), "
                          "at low priority (frames the machine has no time "
                          "for are skipped and counted). With palpate solve: "
                          "the path from rest, a frame per staging "
                          "increment. "
                          "Off: the shape interpolator does not run.");
        prm.declare_entry("Shape output rate",
                          "30",
                          Patterns::Double(0.),
                          "Rate of the shape interpolator (Hz).");
        prm.declare_entry("Shape output limit",
                          "1000",
                          Patterns::Double(0.),
                          "The most the shape frames of one run may write "
                          "(MiB), so that a long run cannot fill the disk: "
                          "past half of it every 2nd frame is written, past "
                          "3/4 every 4th, and so on down to every 64th (a "
                          "long run keeps frames of its whole length); at the "
                          "limit no frame is "
                          "written. The run says how many it thinned out and "
                          "left out. A frame of a 500-node liver "
                          "is about 85 KiB (about 2.5 MiB per second at "
                          "30 Hz).");
        prm.declare_entry("VTU export",
                          "false",
                          Patterns::Bool(),
                          "Whether computed states (deformed mesh, "
                          "displacement, fixed and active nodes) are written "
                          "as VTU files for ParaView: with palpate solve, the "
                          "state; in an interaction, at its end, every state "
                          "the haptic loop interpolated from "
                          "(STEM-state-I_J_K.vtu, grid index I, J, K), with "
                          "an index STEM-states.csv.");
        prm.declare_entry("Force log",
                          "false",
                          Patterns::Bool(),
                          "Whether the force at the active node is logged to "
                          "a CSV file (time s, position m, force N): in an "
                          "interaction one row per haptic tick from the "
                          "motion's start (time 0) on; with palpate solve, "
                          "the target, the force at the last equilibrium "
                          "reached, and how far along the path that is (1: "
                          "the target; less if a stop signal or a failure "
                          "point ended the solve).");
      }
      prm.leave_subsection();
    }



    void
    Effects::parse_parameters(ParameterHandler &prm)
    {
      prm.enter_subsection("Effects");
      {
        switches.clear();
        loads.clear();
        for (const auto &plugin : EffectRegistry::plugins())
          {
            switches[plugin.name] = prm.get_bool(plugin.name);
            auto &entries         = loads[plugin.name];
            for (const auto &entry :
                 Plugins::declared_entries(plugin.declare_parameters))
              entries[entry.first] = prm.get(entry.first);
          }
        try
          {
            Effect::create_enabled(*this);
          }
        catch (const Plugins::EntryError &)
          {}
        shape_output       = prm.get_bool("Shape output");
        shape_output_rate  = prm.get_double("Shape output rate");
        shape_output_limit = prm.get_double("Shape output limit");
        vtu_export         = prm.get_bool("VTU export");
        force_log          = prm.get_bool("Force log");
      }
      prm.leave_subsection();
    }



    void
    NonlinearSolver::declare_parameters(ParameterHandler &prm)
    {
      prm.enter_subsection("Nonlinear solver");
      {
        prm.declare_entry("Number of increments",
                          "1",
                          Patterns::Integer(1),
                          "Minimum number n of equal increments the path "
                          "x_a -> x_b of the active node is split into "
                          "(incremental staging, dimensionless).");
        prm.declare_entry("Maximum increment length",
                          "0.01",
                          Patterns::Double(0.),
                          "Longest increment of the active node's path (m); "
                          "a longer path gets more increments. 0 means no "
                          "limit. With Tip = sphere, never more than the "
                          "sphere's radius (a longer step could carry it "
                          "past a surface node unseen).");
        prm.declare_entry("Maximum Newton iterations",
                          "25",
                          Patterns::Integer(1),
                          "Newton iterations allowed per increment before "
                          "the state is declared a failure point.");
        prm.declare_entry(
          "Residual tolerance",
          "1e-8",
          Patterns::Double(0.),
          "Newton converges when the Euclidean norm of the force residual is "
          "below this times the force scale max(|f_int|, |multipliers|, "
          "1e-12 E L^2) (dimensionless) and the active node is on its "
          "target to Increment tolerance.");
        prm.declare_entry(
          "Increment tolerance",
          "1e-8",
          Patterns::Double(0.),
          "The active node must be on its target to this times the body's "
          "diameter L (dimensionless). Where round-off keeps the residual "
          "above its tolerance, Newton also converges when the full Newton "
          "step is below this times L and the residual below 1000 times its "
          "tolerance.");
        prm.declare_entry("Line search",
                          "true",
                          Patterns::Bool(),
                          "Whether each Newton step is shortened by a "
                          "backtracking line search on the residual norm "
                          "(and to keep every element's det F > 0).");
        prm.declare_entry("Maximum line search steps",
                          "16",
                          Patterns::Integer(1),
                          "Backtracking steps of the line search before the "
                          "smallest step is accepted (dimensionless). They "
                          "cost a residual each, only where the full Newton "
                          "step fails; 8 gave up on 10 of the 11 "
                          "neo-Hookean states the failure-points benchmark "
                          "found solver-caused.");
        prm.declare_entry(
          "Maximum cutbacks",
          "2",
          Patterns::Integer(0),
          "How often an increment whose Newton iteration stagnates is halved "
          "and retried before the state becomes a failure point (adaptive "
          "staging; an increment that inverts an element is not retried: "
          "smaller steps almost never help there). 0 is the paper's fixed "
          "staging. On the shipped liver, 2 turns a third of the initial "
          "cloud's failure points into states (18 -> 13).");
        prm.declare_entry("Assembly threads",
                          "1",
                          Patterns::Integer(1),
                          "Threads that assemble one state's residual and "
                          "tangent (dimensionless). Independent states run "
                          "on different workers (Engine / Workers).");
        prm.declare_entry(
          "Reuse factorization",
          "by size",
          Patterns::Selection("by size|true|false"),
          "true: solve each Newton step by GMRES, preconditioned with the "
          "last factorisation of the tangent this solver made (in this state "
          "or a neighbouring one), to 1e-4 of the residual, and factorise "
          "the current tangent only when GMRES needs more than Maximum "
          "Krylov iterations. The states are those of the exact Newton "
          "method to the residual tolerance (forces within 1e-7 measured), "
          "but Newton converges at a fixed rate of 1e-4 per step instead of "
          "quadratically. false: a factorisation every Newton step. 'by "
          "size': true from 1,500 equations on. Per state on the engine's "
          "path: Mooney-Rivlin P1-P1 on liver501 (1,974 equations) 28 -> 16 "
          "ms, on a 3,976-node liver 4.9 -> 3.6 s; StVK on liver501 (1,473 "
          "equations) 12.6 -> 12.3 ms for one solver but 8 % fewer states "
          "per second for two, measured while their triangular solves "
          "shared one MUMPS (doc/benchmarks/newton.md, scaling.md, "
          "organ-speed.md).");
        prm.declare_entry("Maximum Krylov iterations",
                          "10",
                          Patterns::Integer(1, 100),
                          "With Reuse factorization: GMRES iterations after "
                          "which the kept factorisation counts as too old "
                          "and the tangent is factorised anew "
                          "(dimensionless).");
        prm.declare_entry(
          "Contact solver",
          "in matrix",
          Patterns::Selection("in matrix|condensed"),
          "How a sphere's frictionless contact enters each Newton step. 'in "
          "matrix': the contact rows of the nodes touching it are part of the "
          "tangent that is factorised (Alart and Curnier's semi-smooth "
          "Newton), so every change of the contact set changes the matrix. "
          "'condensed': the factorised tangent leaves the contact out; the "
          "contact is solved on the compliance W = C K^-1 C^T of the surface "
          "nodes near the sphere (a small dense complementarity problem) and "
          "the kept factorisation serves while the contact set moves. Both "
          "converge to the same states (Residual tolerance). Ignored without "
          "a sphere (doc/benchmarks/organ-speed.md).");
        prm.declare_entry(
          "Anderson depth",
          "4",
          Patterns::Integer(0, 20),
          "With Contact solver = condensed: how many earlier Newton steps "
          "on kept factors are combined into each new one (Anderson "
          "acceleration; 0: none). Steps on factors of an older tangent cut "
          "the residual by a fixed ratio; the combination removes the few "
          "modes that make the ratio slow. Restarted when the factors or "
          "the set of nodes touching the sphere change; a combined step "
          "that does not reduce the residual is replaced by the plain one. "
          "The states are the same (Residual tolerance); on the shipped liver a "
          "state costs 0.7x (doc/benchmarks/organ-speed.md).");
      }
      prm.leave_subsection();
    }



    void
    NonlinearSolver::parse_parameters(ParameterHandler &prm)
    {
      prm.enter_subsection("Nonlinear solver");
      {
        n_increments            = prm.get_integer("Number of increments");
        max_increment_length    = prm.get_double("Maximum increment length");
        max_newton_iterations   = prm.get_integer("Maximum Newton iterations");
        residual_tolerance      = prm.get_double("Residual tolerance");
        increment_tolerance     = prm.get_double("Increment tolerance");
        line_search             = prm.get_bool("Line search");
        max_line_search_steps   = prm.get_integer("Maximum line search steps");
        max_cutbacks            = prm.get_integer("Maximum cutbacks");
        assembly_threads        = prm.get_integer("Assembly threads");
        const std::string reuse = prm.get("Reuse factorization");
        reuse_by_size           = reuse == "by size";
        reuse_factorization     = reuse != "false";
        max_krylov_iterations   = prm.get_integer("Maximum Krylov iterations");
        condensed_contact       = prm.get("Contact solver") == "condensed";
        anderson_depth          = prm.get_integer("Anderson depth");
      }
      prm.leave_subsection();
    }



    void
    LinearSolver::declare_parameters(ParameterHandler &prm)
    {
      prm.enter_subsection("Linear solver");
      {
        // The solvers are plug-ins (hyperelastic/linear_solver.h): the
        // choice and each one's own subsection come from their
        // declarations; Ordering is shared.
        declare_plugin_choice(
          prm,
          "linear solver",
          "Solver",
          "by size",
          "Sparse direct solver for the linearised systems: by size: MUMPS "
          "below 5,000 equations and MUMPS single from 5,000 on (a state "
          "9-13 % faster at 5,358-6,965 equations, 30-43 % at 16,980, "
          "doc/benchmarks/organ-speed.md);",
          " all analyse the sparsity pattern once per solver. With MUMPS "
          "single, if GMRES fails, the state solver changes to MUMPS for "
          "good.",
          "by size|");
        prm.declare_entry(
          "Ordering",
          "by size",
          Patterns::Selection(
            "by size|AMF|METIS|AMD|QAMD|PORD|SCOTCH|automatic"),
          "Fill-reducing ordering of the MUMPS analysis (ICNTL(7)). 'by "
          "size' chooses by the number of equations: AMF below 5,000 (the "
          "fastest on liver501, doc/benchmarks/newton.md), METIS nested "
          "dissection from 5,000 on (computed by palpate, since Debian's "
          "MUMPS lacks it): on a 3,976-node liver it makes a state 1.2x "
          "faster, on 1,607 nodes the two are even "
          "(doc/benchmarks/organ-speed.md). 'automatic' is MUMPS's own "
          "choice.");
      }
      prm.leave_subsection();
    }



    void
    LinearSolver::parse_parameters(ParameterHandler &prm)
    {
      prm.enter_subsection("Linear solver");
      {
        solver   = prm.get("Solver");
        ordering = prm.get("Ordering");
        own      = own_entries(prm, "linear solver");
      }
      prm.leave_subsection();
    }



    void
    StateSpace::declare_parameters(ParameterHandler &prm)
    {
      prm.enter_subsection("State space");
      {
        prm.declare_entry("Grid spacing",
                          "0.005",
                          Patterns::Double(0.),
                          "Distance h between neighbouring points of the "
                          "regular grid of active-node positions (m).");
        prm.declare_entry("Extent",
                          "0.1",
                          Patterns::Double(0.),
                          "Half-width of the grid along each axis, centred "
                          "on the active node's rest position (m).");
        prm.declare_entry(
          "Interpolation",
          "trilinear",
          Patterns::Selection("trilinear|tricubic Hermite|contact patch"),
          "How the haptic loop interpolates the force between grid points. "
          "trilinear: the paper's, from the 8 corners' forces; continuous, "
          "but the stiffness the hand feels jumps at every cell face. "
          "tricubic Hermite: from the corners' forces and active-node "
          "stiffnesses (three extra solves per state with the kept "
          "factorisation) and the neighbours' stiffnesses; the force and "
          "the stiffness are continuous, so a coarser grid gives the same "
          "accuracy (doc/accuracy-vs-time.md). "
          "contact patch (Tip = sphere): each state also keeps the "
          "compliance of the surface nodes the sphere can touch from the "
          "cells around it (one solve per node with the state's "
          "factorisation), and the haptic loop solves the sphere's contact "
          "against the corners' patches at every tick, for the sphere where "
          "the hand is: zero force off the surface, the tissue's onset "
          "between the states (doc/formulation.md).");
        prm.declare_entry(
          "Store",
          "",
          Patterns::Anything(),
          "An HDF5 file of computed states (relative to the current "
          "directory), or empty for none. When set, the states in it are "
          "loaded before attaching (no waiting where states exist) and the "
          "states the run computes are appended. 'palpate precompute' fills "
          "it off-line. A store computed for other physics (mesh, material, "
          "fixed or active node, element, grid, tolerances, effects) is "
          "refused, naming what differs.");
      }
      prm.leave_subsection();
    }



    void
    StateSpace::parse_parameters(ParameterHandler &prm)
    {
      prm.enter_subsection("State space");
      {
        grid_spacing  = prm.get_double("Grid spacing");
        extent        = prm.get_double("Extent");
        interpolation = prm.get("Interpolation");
        store         = prm.get("Store");
      }
      prm.leave_subsection();
    }



    void
    Scheduler::declare_parameters(ParameterHandler &prm)
    {
      prm.enter_subsection("Scheduler");
      {
        prm.declare_entry("Cloud radius",
                          "0.025",
                          Patterns::Double(0.),
                          "Radius R of the spherical cloud of grid states "
                          "kept computed around the haptic interaction point "
                          "(m).");
        prm.declare_entry("Rate",
                          "100",
                          Patterns::Double(0.),
                          "Rate at which the scheduler updates the cloud "
                          "(Hz).");
        prm.declare_entry("Look-ahead time",
                          "0.2",
                          Patterns::Double(0.),
                          "The cloud is centred on the point the HIP will "
                          "reach after this time at its current velocity "
                          "(s, at most 2); 0 is the paper's cloud around the "
                          "HIP.");
      }
      prm.leave_subsection();
    }



    void
    Scheduler::parse_parameters(ParameterHandler &prm)
    {
      prm.enter_subsection("Scheduler");
      {
        cloud_radius    = prm.get_double("Cloud radius");
        rate            = prm.get_double("Rate");
        look_ahead_time = prm.get_double("Look-ahead time");
      }
      prm.leave_subsection();
    }



    void
    Engine::declare_parameters(ParameterHandler &prm)
    {
      prm.enter_subsection("Engine");
      {
        prm.declare_entry("Type",
                          "threads",
                          Patterns::Selection("threads|mpi"),
                          "Where states are computed: solver workers as "
                          "threads of this process, or MPI solver servers "
                          "(run as `mpirun -np N palpate SCENE.prm`: rank 0 "
                          "is the haptic client, ranks 1..N-1 are N-1 "
                          "solver servers).");
        prm.declare_entry("Workers",
                          "2",
                          Patterns::Integer(1),
                          "Number of solver threads, each computing one "
                          "state at a time with its own FE solver "
                          "(dimensionless). With Type = mpi the number of "
                          "servers is set by mpirun -np, and this entry is "
                          "not used.");
        prm.declare_entry(
          "Memory budget",
          "1024",
          Patterns::Double(1.),
          "Memory for the whole states kept in the cache (MiB), "
          "their contact patches included; with Type = mpi, on each "
          "server and on the client (the states its shape output fetched, "
          "the contact patches the results carry). Beyond it, the states farthest from the HIP are "
          "dropped with their patches; their forces stay (with "
          "Interpolation = contact patch, a cell with such a corner is "
          "interpolated trilinearly).");
        // At most an hour: the servers end only when the client (rank 0)
        // has been silent this long, so with 1e308 those of a killed
        // client would run on for good.
        prm.declare_entry("Server timeout",
                          "5",
                          Patterns::Double(0.5, 3600),
                          "Type = mpi: a solver server that has sent "
                          "nothing (it sends a heartbeat every 0.1 s) for "
                          "this long is lost: it gets no more work and its "
                          "task is planned again. The other way round, a "
                          "server that has heard nothing from the client "
                          "(rank 0, also every 0.1 s) for this long ends, "
                          "saying so (s; at most 3600).");
        prm.declare_entry("Task timeout",
                          "60",
                          Patterns::Double(0.1, 86400),
                          "Type = mpi: a server whose task has run this "
                          "long is treated as hung and lost (s).");
      }
      prm.leave_subsection();
    }



    void
    Engine::parse_parameters(ParameterHandler &prm)
    {
      prm.enter_subsection("Engine");
      {
        type           = prm.get("Type");
        workers        = prm.get_integer("Workers");
        memory_budget  = prm.get_double("Memory budget");
        server_timeout = prm.get_double("Server timeout");
        task_timeout   = prm.get_double("Task timeout");
      }
      prm.leave_subsection();
    }



    void
    Trajectory::declare_parameters(ParameterHandler &prm)
    {
      prm.enter_subsection("Trajectory");
      {
        // The trajectories are plug-ins (haptics/trajectory.h): the
        // choice and each one's own subsection come from their
        // declarations, the entries below are shared.
        declare_plugin_choice(prm,
                              "trajectory",
                              "Type",
                              "straight line",
                              "Motion of the simulated device's HIP, "
                              "relative to the active node's rest position:",
                              "");
        prm.declare_entry("Direction",
                          "0, 0, -1",
                          point_pattern(),
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
        own                      = own_entries(prm, "trajectory");
        direction                = get_point(prm, "Direction");
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
        declare_plugin_choice(prm,
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
        own              = own_entries(prm, "device");
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



    void
    Run::declare_parameters(ParameterHandler &prm)
    {
      prm.enter_subsection("Run");
      {
        prm.declare_entry("Mode",
                          "interaction",
                          Patterns::Selection(
                            "interaction|static solve|set-up only"),
                          "What 'palpate SCENE.prm' does after setting the "
                          "scene up: an interaction with the simulated device "
                          "(states computed on-line, forces at the haptic "
                          "rate, a run summary), a static solve to the active "
                          "node's Prescribed displacement, or nothing more.");
      }
      prm.leave_subsection();
    }



    void
    Run::parse_parameters(ParameterHandler &prm)
    {
      prm.enter_subsection("Run");
      mode = prm.get("Mode");
      prm.leave_subsection();
    }



    void
    AllParameters::declare_parameters(ParameterHandler &prm)
    {
      Run::declare_parameters(prm);
      Mesh::declare_parameters(prm);
      BoundaryConditions::declare_parameters(prm);
      MaterialModel::declare_parameters(prm);
      Discretization::declare_parameters(prm);
      Effects::declare_parameters(prm);
      NonlinearSolver::declare_parameters(prm);
      LinearSolver::declare_parameters(prm);
      StateSpace::declare_parameters(prm);
      Scheduler::declare_parameters(prm);
      Engine::declare_parameters(prm);
      Haptics::declare_parameters(prm);
      Output::declare_parameters(prm);
    }



    void
    AllParameters::parse_parameters(ParameterHandler &prm)
    {
      run.parse_parameters(prm);
      mesh.parse_parameters(prm);
      boundary_conditions.parse_parameters(prm);
      material_model.parse_parameters(prm);
      discretization.parse_parameters(prm);
      effects.parse_parameters(prm);
      nonlinear_solver.parse_parameters(prm);
      linear_solver.parse_parameters(prm);
      state_space.parse_parameters(prm);
      scheduler.parse_parameters(prm);
      engine.parse_parameters(prm);
      haptics.parse_parameters(prm);
      output.parse_parameters(prm);
    }
  } // namespace Parameters
} // namespace palpate
