// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

#include <palpate/app/scene_report.h>
#include <palpate/hyperelastic/effect.h>
#include <palpate/hyperelastic/material.h>
#include <palpate/mesh/mesh.h>
#include <palpate/mesh/mesh_quality.h>
#include <palpate/mesh/mesh_source.h>
#include <palpate/mesh/node_selection.h>
#include <palpate/mesh/probe_tip.h>
#include <palpate/mesh/volume_mesher.h>
#include <palpate/scene/scene.h>

#include <iomanip>
#include <ostream>
#include <sstream>

namespace palpate
{
  namespace
  {
    std::string
    join(const std::vector<std::string> &items)
    {
      std::string s;
      for (unsigned int i = 0; i < items.size(); ++i)
        s += (i ? ", " : "") + items[i];
      return s.empty() ? std::string("none") : s;
    }

    /** The --set entries of a variant made on the command line. */
    void
    report_command_line(std::ostream &s, const Scene &scene)
    {
      // A variant made on the command line says so first: its output is not
      // the scene file's.
      if (!scene.command_line_settings().empty())
        {
          s << "Command line\n";
          for (const auto &setting : scene.command_line_settings())
            s << "  --set " << setting << "\n";
        }
    }

    /**
     * A warning if slivers of @p quality lie near the active node, where the
     * body deforms most.
     */
    void
    report_slivers_near_active_node(std::ostream        &s,
                                    const Mesh          &mesh,
                                    const NodeSelection &nodes,
                                    const MeshQuality   &quality)
    {
      if (nodes.active_vertex == NodeSelection::no_active_node)
        return;
      const auto  &x     = mesh.vertices();
      const auto  &xa0   = x[nodes.active_vertex];
      const double near  = 0.1 * mesh.diameter();
      unsigned int close = 0;
      for (const unsigned int c : quality.slivers)
        {
          bool is_near = false;
          for (const unsigned int v : mesh.cells()[c])
            is_near = is_near || Utilities::distance(x[v], xa0) < near;
          close += is_near;
        }
      if (close > 0)
        s << "  warning:       " << close << " of the "
          << quality.slivers.size() << " slivers lie within " << 1000 * near
          << " mm of the active node, where the body deforms most: their "
             "strains are unreliable and Newton may need more steps. A "
             "finer or optimised mesh (palpate mesh, or Gmsh's "
             "Optimize) removes them.\n";
    }

    /** The mesh: its source, counts, size and quality, and warnings. */
    void
    report_mesh(std::ostream        &s,
                const Scene         &scene,
                const Mesh          &mesh,
                const NodeSelection &nodes)
    {
      const auto &p      = scene.parameters;
      const auto  source = MeshSource::create(scene);
      const auto  box    = mesh.bounding_box();
      s << "Mesh\n"
        << "  source:        " << source->description(mesh, scene);
      s << "\n  nodes:         " << mesh.n_vertices() << " ("
        << mesh.n_surface_vertices() << " on the surface)";
      if (mesh.n_merged_nodes() > 0)
        s << "; " << mesh.n_merged_nodes() << " repeated nodes merged";
      if (mesh.n_dropped_nodes() > 0)
        s << "; " << mesh.n_dropped_nodes() << " unused nodes dropped";
      s << "\n  tetrahedra:    " << mesh.n_cells() << ", volume "
        << mesh.volume() << " m^3, smallest " << mesh.min_cell_volume()
        << " m^3\n"
        << "  bounding box:  [" << Utilities::to_string(box.first, 4) << "] - ["
        << Utilities::to_string(box.second, 4) << "] m, size "
        << box.second[0] - box.first[0] << " x " << box.second[1] - box.first[1]
        << " x " << box.second[2] - box.first[2] << " m\n";
      // Quality, and slivers where the body deforms most: near the active
      // node (within a tenth of the body's size).
      const MeshQuality quality = mesh_quality(mesh.vertices(), mesh.cells());
      s << "  quality:       " << quality.summary() << "\n";
      report_slivers_near_active_node(s, mesh, nodes, quality);
      // A body smaller or larger than an organ is likely a unit slip
      // (beyond Limits::min_body_size and max_body_size it is refused).
      if (const std::string advice =
            unit_advice(mesh.diameter(),
                        source->from_file() ? p.mesh.scale_factor : 1.0);
          !advice.empty() && source->from_file())
        s << "  warning:       the body is " << mesh.diameter()
          << " m across: is Mesh / Scale factor right? " << advice << ".\n";
    }

    /** The probe tip's line, if the tip has one to say. */
    void
    report_probe_tip(std::ostream        &s,
                     const Scene         &scene,
                     const NodeSelection &nodes)
    {
      if (const std::string line =
            ProbeTip::create(scene)->report(scene, nodes);
          !line.empty())
        s << "\n  probe tip:     " << line;
    }

    /** The fixed nodes, the active node and the probe tip. */
    void
    report_boundary_conditions(std::ostream        &s,
                               const Scene         &scene,
                               const Mesh          &mesh,
                               const NodeSelection &nodes)
    {
      const auto &p  = scene.parameters;
      const auto &f  = p.boundary_conditions.fixed_nodes;
      const auto &a  = p.boundary_conditions.active_node;
      const auto &xa = mesh.vertices()[nodes.active_vertex];
      s << "Boundary conditions\n"
        << "  fixed nodes:   " << nodes.fixed_vertices.size() << " ("
        << nodes.fixed_description << "), by " << f.treatment << "\n"
        << "  active node:   " << mesh.node_name(nodes.active_vertex) << " at ("
        << Utilities::to_string(xa, 4) << ") m";
      if (a.selection == "nearest surface node")
        s << ", the surface node nearest to ("
          << Utilities::to_string(a.point, 4) << ") m, "
          << 1000 * nodes.active_distance << " mm away";
      if (a.selection == "nearest surface node" &&
          nodes.active_distance > 0.1 * mesh.diameter())
        s << "\n  warning:       the Point is " << 1000 * nodes.active_distance
          << " mm from the body's surface ("
          << 100 * nodes.active_distance / mesh.diameter()
          << " % of its size): is it in the mesh's scaled coordinates "
             "(metres, after Scale factor)? The mesh's bounding box is above.";
      report_probe_tip(s, scene, nodes);
      s << "\n";
    }

    /** The material law, and a warning where it locks. */
    void
    report_material(std::ostream &s, const Parameters::AllParameters &p)
    {
      const auto &m        = p.material_model;
      const auto  material = Material::create(m);
      s << "Material\n  model:         " << m.model_name << ", "
        << material->description() << "\n";
      // Volumetric locking: a compressible law on linear tetrahedra near
      // nu = 0.5 is far too stiff (the divergence-free displacements of P1
      // tetrahedra are almost only rigid motions).
      const double nu = material->poissons_ratio();
      if (material->formulation().pressure == Formulation::Pressure::none &&
          nu >= 0.495 && p.discretization.polynomial_degree == 1)
        s << "  warning:       nu = " << Utilities::to_string_exact(nu)
          << " on linear tetrahedra locks (volumetric locking): the body "
             "is too stiff and Newton may stagnate. For a nearly "
             "incompressible organ use Mooney-Rivlin (mixed u-p, exactly "
             "incompressible), or Polynomial degree = 2, or nu <= 0.49.\n";
    }

    /** The effects the scene switches on, and those it leaves off. */
    void
    report_effects(std::ostream        &s,
                   const Scene         &scene,
                   const Mesh          &mesh,
                   const NodeSelection &nodes)
    {
      const auto &p = scene.parameters;
      // Effects are what a scene switches on; incompressibility is the
      // material's (see Material above), not an effect.
      std::vector<std::string> on, off;
      for (const auto &plugin : EffectRegistry::plugins())
        if (!p.effects.on(plugin.name))
          {
            std::string name = plugin.name;
            name[0]          = std::tolower(name[0]);
            off.push_back(name);
          }
      for (const auto &effect : Effect::create_enabled(p.effects))
        on.push_back(effect->description(mesh, p));
      if (const std::string tip = ProbeTip::create(scene)->effect(nodes);
          !tip.empty())
        on.push_back(tip);
      (p.effects.shape_output ? on : off).push_back("shape output");
      (p.effects.vtu_export ? on : off).push_back("VTU export");
      (p.effects.force_log ? on : off).push_back("force log");
      s << "Effects\n"
        << "  on:            " << join(on) << "\n"
        << "  off:           " << join(off) << "\n";
    }
  } // namespace



  void
  print_scene_report(std::ostream        &out,
                     const Scene         &scene,
                     const Mesh          &mesh,
                     const NodeSelection &nodes)
  {
    std::ostringstream s;
    s << std::setprecision(4);
    report_command_line(s, scene);
    report_mesh(s, scene, mesh, nodes);
    report_boundary_conditions(s, scene, mesh, nodes);
    report_material(s, scene.parameters);
    report_effects(s, scene, mesh, nodes);
    out << s.str();
  }
} // namespace palpate
