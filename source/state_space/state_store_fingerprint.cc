// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

// The fingerprint of a scene (StoreFingerprint::of): what a stored state
// depends on, one field at a time. Apart from the store's file and records
// because it reads the scene, the mesh and the node selection, which the
// rest of the store never needs, and it grows with every new input of the
// physics.

#include <palpate/mesh/mesh.h>
#include <palpate/mesh/node_selection.h>
#include <palpate/scene/scene.h>
#include <palpate/state_space/state_store_impl.h>

#include <algorithm>
#include <sstream>
#include <string>

namespace palpate
{
  using internal::Hash;

  namespace
  {
    std::string
    exact(const double x)
    {
      std::ostringstream s;
      s.precision(17);
      s << x;
      return s.str();
    }
  } // namespace



  StoreFingerprint
  StoreFingerprint::of(const Scene         &scene,
                       const Mesh          &mesh,
                       const NodeSelection &nodes)
  {
    const auto      &p = scene.parameters;
    StoreFingerprint f;
    {
      Hash h;
      for (const auto &x : mesh.vertices())
        h.add(x.data(), sizeof(x));
      for (const auto &c : mesh.cells())
        h.add(c.data(), sizeof(c));
      f.fields.emplace_back("mesh",
                            std::to_string(mesh.n_vertices()) + " nodes, " +
                              std::to_string(mesh.n_cells()) +
                              " tetrahedra, hash " + h.hex());
    }
    {
      std::string m       = p.material_model.model_name;
      const auto  entries = p.material_model.models.find(m);
      if (entries != p.material_model.models.end())
        for (const auto &[name, value] : entries->second)
          m += "; " + name + " = " + value;
      f.fields.emplace_back("material", m);
    }
    {
      Hash h;
      h.add(nodes.fixed_vertices);
      for (const auto &c : nodes.fixed_components)
        h.add(&c, sizeof(c));
      f.fields.emplace_back("fixed nodes",
                            std::to_string(nodes.fixed_vertices.size()) +
                              " nodes by " +
                              p.boundary_conditions.fixed_nodes.treatment +
                              ", hash " + h.hex());
    }
    {
      std::string a = mesh.node_name(nodes.active_vertex);
      if (!nodes.tip_vertices.empty())
        a += ", tip of " + std::to_string(nodes.tip_vertices.size() + 1) +
             " nodes";
      if (nodes.sphere_tip)
        a += ", sphere of radius " +
             Utilities::to_string(p.boundary_conditions.active_node.tip_radius,
                                  9) +
             " m at (" + Utilities::to_string(nodes.sphere_center, 9) + ")";
      f.fields.emplace_back("active node", a);
    }
    f.fields.emplace_back("element",
                          "degree " +
                            std::to_string(p.discretization.polynomial_degree) +
                            ", quadrature " +
                            std::to_string(p.discretization.quadrature_order));
    f.fields.emplace_back("grid",
                          "spacing " + exact(p.state_space.grid_spacing) +
                            " m, extent " + exact(p.state_space.extent) + " m");
    f.fields.emplace_back(
      "tolerances",
      "residual " + exact(p.nonlinear_solver.residual_tolerance) +
        ", increment " + exact(p.nonlinear_solver.increment_tolerance) +
        ", increments " + std::to_string(p.nonlinear_solver.n_increments) +
        ", longest increment " +
        exact(p.nonlinear_solver.max_increment_length) + " m");
    {
      std::string e;
      for (const auto &[name, on] : p.effects.switches)
        if (on)
          {
            e += (e.empty() ? "" : "; ") + name;
            const auto entries = p.effects.loads.find(name);
            if (entries != p.effects.loads.end())
              for (const auto &[entry, value] : entries->second)
                e += ", " + entry + " = " + value;
          }
      if (std::find_if(p.effects.switches.begin(),
                       p.effects.switches.end(),
                       [](const auto &s) { return s.second; }) !=
          p.effects.switches.end())
        e += "; density " + exact(p.material_model.density);
      f.fields.emplace_back("load effects", e.empty() ? "none" : e);
    }
    // A store of states without their patches cannot serve an
    // interpolation that renders them (its cells would render without
    // them), nor the reverse be told apart by the states alone.
    // Layout 2: each patch with its model's force at the neighbours
    // (ContactPatch::neighbour_force); a store of layout 1 is another
    // store.
    f.fields.emplace_back("contact patches",
                          p.state_space.state_contents().contact_patch ?
                            "kept (layout 2)" :
                            "none");
    f.fields.emplace_back("palpate version", PALPATE_VERSION);
    return f;
  }
} // namespace palpate
