// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

// The parameters of a whole scene (parameters.h): the subsection Run, and
// AllParameters, which declares and reads every subsection in the order of
// a scene file. The subsections are in the parameters_*.cc files
// (parameters_impl.h lists them), with the helpers they share here: the
// plug-ins' entries and choices, and the 3-vector entries.

#include <palpate/scene/parameters_impl.h>

namespace palpate
{
  namespace internal
  {
    using namespace dealii;

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
                          const std::string &other_choices)
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

    Utilities::Point3
    get_point(ParameterHandler &prm, const std::string &name)
    {
      return Utilities::parse_point(prm.get(name));
    }
  } // namespace internal



  namespace Parameters
  {
    using namespace dealii;



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
