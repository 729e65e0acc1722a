// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

// The checks of a scene's body and its boundary conditions
// (Scene::validate()): the probe's tip and its radius, the mesh's source,
// file and scale and the generated beam's or blob's size, and the fixed-node
// region.

#include <palpate/scene/scene_impl.h>

#include <algorithm>
#include <cmath>

namespace palpate
{
  void
  Scene::check_probe() const
  {
    using namespace Limits;
    const auto &p = parameters;

    // The probe's tip: a radius means something only for a glued tip or a
    // sphere (before Tip existed, Tip radius > 0 meant glued nodes).
    {
      using Tip     = Parameters::ActiveNode::Tip;
      const auto &a = p.boundary_conditions.active_node;
      if (a.tip == Tip::point && a.tip_radius > 0)
        throw error("Boundary conditions/Active node/Tip radius",
                    "Tip radius = " + Utilities::to_string(a.tip_radius, 4) +
                      " m, but Tip = point has no radius",
                    "set Tip = sphere (a rigid sphere in contact with the "
                    "surface: a force that converges with the mesh) or Tip "
                    "= glued nodes (the surface nodes within the radius "
                    "follow the probe), or remove Tip radius.");
      if (a.tip != Tip::point && !(a.tip_radius > 0))
        throw error("Boundary conditions/Active node/Tip radius",
                    "Tip = " +
                      std::string(a.tip == Tip::sphere ? "sphere" :
                                                         "glued nodes") +
                      " needs a positive Tip radius",
                    "set Tip radius in metres, e.g. 0.01 for a probe of "
                    "1 cm radius.");
      if (a.tip != Tip::point && a.tip_radius > max_sphere_radius)
        throw error(
          "Boundary conditions/Active node/Tip radius",
          std::string(a.tip == Tip::sphere ? "a sphere" : "a glued tip") +
            " of " +
            Utilities::to_string_apart(a.tip_radius, max_sphere_radius) +
            " m radius is no probe (at most " +
            Utilities::to_string(max_sphere_radius, 3) + " m)",
          "give the radius in metres (a 1 cm probe: 0.01).");
    }
  }



  namespace
  {
    // Scene::check_mesh(), a step: the generated beam's sides and node count,
    // the entries only Source = beam reads.
    void
    check_beam(const Scene &scene)
    {
      using namespace Limits;
      const auto  &p        = scene.parameters;
      const double dims[3]  = {p.mesh.beam_length,
                               p.mesh.beam_width,
                               p.mesh.beam_height};
      const char  *names[3] = {"Length", "Width", "Height"};
      const char  *words[3] = {"length", "width", "height"};
      for (unsigned int d = 0; d < 3; ++d)
        if (!(dims[d] > 0))
          throw scene.error(std::string("Mesh/Beam/") + names[d],
                            std::string("the beam's ") + words[d] +
                              " must be positive: a beam of zero or negative " +
                              words[d] + " has no volume",
                            std::string("set it in metres, e.g. ") +
                              (d == 0 ? "0.1." : "0.02."));
        else if (dims[d] < min_body_size / 2 || dims[d] > max_body_size)
          // As a mesh file's body (check_size in mesh.cc): past these its
          // elements' volumes under- or overflow and the messages blame
          // the generated mesh.
          throw scene.error(std::string("Mesh/Beam/") + names[d],
                            std::string("a beam ") +
                              Utilities::to_string(dims[d], 3) + " m in " +
                              words[d] + "; a body to palpate is " +
                              Utilities::to_string(min_body_size / 2, 3) +
                              " to " + Utilities::to_string(max_body_size, 3) +
                              " m in each direction",
                            std::string("set it in metres, e.g. ") +
                              (d == 0 ? "0.1." : "0.02."));
      const double nodes = (p.mesh.beam_subdivisions_length + 1.) *
                           (p.mesh.beam_subdivisions_width + 1.) *
                           (p.mesh.beam_subdivisions_height + 1.);
      if (nodes > max_generated_nodes)
        throw scene.error("Mesh/Beam/Subdivisions",
                          "the beam would have " +
                            Utilities::to_string(nodes, 3) +
                            " nodes; at most " +
                            Utilities::to_string(max_generated_nodes, 3) +
                            " are allowed (a state of 1e5 nodes takes minutes, "
                            "far from haptic rates)",
                          "use fewer subdivisions, e.g. 10, 2, 2.");
    }



    // Scene::check_mesh(), a step: the generated blob's semi-axes, the entry
    // only Source = blob reads.
    void
    check_blob(const Scene &scene)
    {
      using namespace Limits;
      const auto &p = scene.parameters;
      for (unsigned int d = 0; d < 3; ++d)
        {
          if (!(p.mesh.blob_semi_axes[d] > 0))
            throw scene.error(
              "Mesh/Blob/Semi-axes",
              "every semi-axis must be positive: a blob with a zero "
              "or negative semi-axis has no volume",
              "give three lengths in metres, e.g. 0.125, 0.09, 0.07.");
          else if (p.mesh.blob_semi_axes[d] < min_body_size / 4 ||
                   p.mesh.blob_semi_axes[d] > max_body_size / 2)
            throw scene.error(
              "Mesh/Blob/Semi-axes",
              "a semi-axis of " +
                Utilities::to_string(p.mesh.blob_semi_axes[d], 3) +
                " m; a body to palpate is " +
                Utilities::to_string(min_body_size / 2, 3) + " to " +
                Utilities::to_string(max_body_size, 3) +
                " m across, a semi-axis half that",
              "give three lengths in metres, e.g. 0.125, 0.09, 0.07.");
        }
    }
  } // namespace



  void
  Scene::check_mesh() const
  {
    using namespace Limits;
    const auto &p = parameters;

    // Mesh.
    if (p.mesh.source == "file" && p.mesh.file_name.empty())
      throw error("Mesh/File name",
                  "Source = file, but no mesh file is named",
                  "set File name to a .msh, .vtk or .vtu file, or choose "
                  "Source = beam or blob.");
    if (p.mesh.source == "surface" && p.mesh.file_name.empty())
      throw error("Mesh/File name",
                  "Source = surface, but no surface file is named",
                  "set File name to the organ's closed surface (.stl, .obj, "
                  ".ply, .vtk or .vtp).");
    // A file named for a generator is a mistake: the run would silently
    // use a beam or blob instead of the organ the user meant.
    if ((p.mesh.source == "beam" || p.mesh.source == "blob") &&
        !p.mesh.file_name.empty() && sets("Mesh/File name"))
      throw error("Mesh/File name",
                  "a file is named, but Source = " + p.mesh.source +
                    " generates the mesh and ignores it",
                  "set Source = file (a tetrahedral mesh) or Source = "
                  "surface (an organ's surface, meshed by palpate), or "
                  "remove File name.");
    if (p.mesh.scale_factor <= 0)
      throw error("Mesh/Scale factor",
                  "the scale factor must be positive",
                  "set it to the number of metres per mesh-file unit, e.g. "
                  "0.001 for a mesh in millimetres.");
    // No file unit is below a nanometre or above a thousand kilometres;
    // past that the coordinates in metres under- or overflow, and the
    // messages that follow would blame the mesh instead of the scale.
    if (p.mesh.scale_factor < 1e-9 || p.mesh.scale_factor > 1e6)
      throw error("Mesh/Scale factor",
                  "a scale factor of " +
                    Utilities::to_string(p.mesh.scale_factor, 3) +
                    " m per mesh-file unit is no unit of length a mesh is "
                    "written in (1e-9, a nanometre, to 1e6)",
                  "set it to the number of metres per mesh-file unit, e.g. "
                  "0.001 for a mesh in millimetres, 1 for metres.");

    if (p.mesh.source == "beam")
      check_beam(*this);
    // As palpate mesh --fine-size: below 10 micrometres Gmsh works until
    // its time limit and the message blames the limit.
    if (p.mesh.source == "surface" && p.mesh.surface_fine_size > 0 &&
        p.mesh.surface_fine_size < 1e-5)
      throw error("Mesh/Surface/Refinement size",
                  "an element size of " +
                    Utilities::to_string(p.mesh.surface_fine_size, 3) +
                    " m near the probe; at least 1e-5 m (10 micrometres)",
                  "give the size in metres: a third of the sphere's radius "
                  "is a good start, e.g. 0.003 for a 1 cm sphere.");
    if (p.mesh.source == "blob")
      check_blob(*this);
  }



  void
  Scene::check_fixed_nodes() const
  {
    using namespace Limits;
    const auto &p = parameters;

    // Fixed nodes: the region must be well-defined.
    const auto &f = p.boundary_conditions.fixed_nodes;
    if (f.selection == "box")
      for (unsigned int d = 0; d < 3; ++d)
        if (!(f.box_lower_corner[d] < f.box_upper_corner[d]))
          throw error("Boundary conditions/Fixed nodes/Box upper corner",
                      "the box is empty: its upper corner is not above its "
                      "lower corner in every coordinate",
                      "make each coordinate of Box upper corner larger than "
                      "that of Box lower corner.");
    if (f.selection == "half-space" &&
        std::max({std::abs(f.half_space_normal[0]),
                  std::abs(f.half_space_normal[1]),
                  std::abs(f.half_space_normal[2])}) == 0)
      throw error("Boundary conditions/Fixed nodes/Half-space normal",
                  "the normal is the zero vector",
                  "give the direction pointing into the fixed half-space, "
                  "e.g. 0, 0, -1.");
    if (f.selection == "node list" && f.node_ids.empty())
      throw error("Boundary conditions/Fixed nodes/Node ids",
                  "Selection = node list, but the list is empty",
                  "list the node numbers to fix, separated by commas.");
  }

} // namespace palpate
