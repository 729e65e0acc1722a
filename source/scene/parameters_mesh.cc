// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

// The parameters of the body (parameters.h): the subsections Mesh (a mesh
// file, an organ's surface to mesh, or a generated beam or blob) and
// Boundary conditions (the fixed nodes and the probe's active node), each
// declared with its help text and read back into its struct.

#include <palpate/scene/parameters_impl.h>

#include <tuple>

namespace palpate
{
  namespace Parameters
  {
    using namespace dealii;

    namespace
    {
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



      // Mesh / Beam: the generated beam's size and blocks, a step of
      // Mesh::declare_parameters() so that each subsection reads alone.
      void
      declare_beam_entries(ParameterHandler &prm)
      {
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
      }



      // Mesh / Surface: how an organ's surface is meshed, a step of
      // Mesh::declare_parameters() so that each subsection reads alone.
      void
      declare_surface_entries(ParameterHandler &prm)
      {
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
      }



      // Mesh / Blob: the generated organ-like body, a step of
      // Mesh::declare_parameters() so that each subsection reads alone.
      void
      declare_blob_entries(ParameterHandler &prm)
      {
        prm.enter_subsection("Blob");
        {
          prm.declare_entry("Semi-axes",
                            "0.125, 0.09, 0.07",
                            internal::point_pattern(),
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
    } // namespace



    void
    Mesh::declare_parameters(ParameterHandler &prm)
    {
      prm.enter_subsection("Mesh");
      {
        // The sources are plug-ins (mesh/mesh_source.h): the choice comes
        // from their declarations; the entries below are the built-in
        // sources', shared where two read one (File name, Scale factor).
        internal::declare_plugin_choice(
          prm,
          "mesh source",
          "Source",
          "blob",
          "Where the tetrahedral mesh of the body comes from:",
          "");
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

        declare_beam_entries(prm);
        declare_surface_entries(prm);
        declare_blob_entries(prm);
      }
      prm.leave_subsection();
    }



    bool
    Mesh::operator==(const Mesh &o) const
    {
      const auto entries = [](const Mesh &m) {
        return std::tie(m.source,
                        m.own,
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
        own          = internal::own_entries(prm, "mesh source");
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
          blob_semi_axes   = internal::get_point(prm, "Semi-axes");
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
        // The regions are plug-ins (mesh/fixed_region.h): the choice comes
        // from their declarations; the entries below are the built-in
        // regions'.
        internal::declare_plugin_choice(
          prm,
          "fixed region",
          "Selection",
          "half-space",
          "How the nodes held at zero displacement (homogeneous Dirichlet) "
          "are chosen:",
          "");
        prm.declare_entry("Boundary ids",
                          "1",
                          Patterns::List(Patterns::Integer(0), 1),
                          "Boundary ids whose faces' nodes are fixed, for "
                          "Selection = boundary id (dimensionless). Gmsh "
                          "files set them with physical tags of triangles.");
        prm.declare_entry("Box lower corner",
                          "-1, -1, -1",
                          internal::point_pattern(),
                          "Lower corner of the box for Selection = box, in "
                          "scaled mesh coordinates (m).");
        prm.declare_entry("Box upper corner",
                          "1, 1, 1",
                          internal::point_pattern(),
                          "Upper corner of the box for Selection = box, in "
                          "scaled mesh coordinates (m).");
        prm.declare_entry("Half-space point",
                          "0, 0, -0.04",
                          internal::point_pattern(),
                          "A point on the plane bounding the half-space for "
                          "Selection = half-space, in scaled mesh "
                          "coordinates (m).");
        prm.declare_entry("Half-space normal",
                          "0, 0, -1",
                          internal::point_pattern(),
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
        own                = internal::own_entries(prm, "fixed region");
        boundary_ids       = get_list<unsigned int>(prm, "Boundary ids");
        box_lower_corner   = internal::get_point(prm, "Box lower corner");
        box_upper_corner   = internal::get_point(prm, "Box upper corner");
        half_space_point   = internal::get_point(prm, "Half-space point");
        half_space_normal  = internal::get_point(prm, "Half-space normal");
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
                          internal::point_pattern(),
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
          internal::point_pattern(),
          "Displacement of the active node from its rest position for a "
          "static solve (`palpate solve`, or `palpate scene.prm` with Run / "
          "Mode = static solve), in metres; `palpate solve --to x,y,z` "
          "overrides it. An interaction does not use it (the device moves "
          "the probe), but a sphere's size is checked against it.");
        // The tips are plug-ins (mesh/probe_tip.h): the choice comes from
        // their declarations; Tip radius below is the built-in tips'.
        internal::declare_plugin_choice(
          prm, "probe tip", "Tip", "point", "What touches the organ.", "");
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
        selection = prm.get("Selection");
        point     = internal::get_point(prm, "Point");
        node_id   = prm.get_integer("Node id");
        prescribed_displacement =
          internal::get_point(prm, "Prescribed displacement");
        tip        = prm.get("Tip");
        own        = internal::own_entries(prm, "probe tip");
        tip_radius = prm.get_double("Tip radius");
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
  } // namespace Parameters
} // namespace palpate
