// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

#ifndef palpate_scene_parameters_impl_h
#define palpate_scene_parameters_impl_h

// Not an interface: the declarations and readings of the parameter structs
// (parameters.h), shared by their source files, one group of subsections
// each:
//   parameters.cc              the subsection Run, AllParameters, and the
//                              helpers below
//   parameters_mesh.cc         Mesh and Boundary conditions (the fixed
//                              nodes, the probe's active node)
//   parameters_solver.cc       Material model, Discretization, Effects,
//                              Nonlinear solver and Linear solver
//   parameters_state_space.cc  State space, Scheduler and Engine
//   parameters_haptics.cc      Haptics, its Trajectory, and Output
// Users of the parameters include parameters.h, never this header.

#include <palpate/base/plugins.h>
#include <palpate/base/utilities.h>
#include <palpate/scene/parameters.h>

#include <deal.II/base/parameter_handler.h>

#include <map>
#include <string>

namespace palpate
{
  namespace internal
  {
    /** The values of the own entries of each plug-in of @p kind
     * (parameters.cc). */
    std::map<std::string, Plugins::Entries>
    own_entries(dealii::ParameterHandler &prm, const std::string &kind);

    /** The entry @p entry that chooses a plug-in of @p kind, and the
     * subsection of each plug-in that has entries of its own
     * (parameters.cc). */
    void
    declare_plugin_choice(dealii::ParameterHandler &prm,
                          const std::string        &kind,
                          const std::string        &entry,
                          const std::string        &default_value,
                          std::string               doc,
                          const std::string        &outro,
                          const std::string        &other_choices = "");

    /** Pattern of a 3-vector entry "x, y, z" (parameters.cc). */
    dealii::Patterns::List
    point_pattern();

    /** The 3-vector entry @p name (parameters.cc). */
    Utilities::Point3
    get_point(dealii::ParameterHandler &prm, const std::string &name);
  } // namespace internal
} // namespace palpate

#endif
