// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

// The parameters of the body's model and of its solution (parameters.h):
// the subsections Material model (the material plug-ins' choice and
// constants), Discretization, Effects (the effect plug-ins, on or off, and
// their entries), Nonlinear solver and Linear solver (the linear solver
// plug-ins), each declared with its help text and read back into its struct.

#include <palpate/scene/parameters_impl.h>

#include <iomanip>
#include <sstream>
#include <stdexcept>

namespace palpate
{
  namespace Parameters
  {
    using namespace dealii;



    void
    MaterialModel::set(const std::string &model,
                       const std::string &entry,
                       const std::string &value)
    {
      const auto *plugin = Plugins::find_declaration("material", model);
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
      const auto *plugin = Plugins::find_declaration("material", model);
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
        for (const auto &plugin : Plugins::declarations("material"))
          doc += " " + plugin.name + ": " + plugin.description + ";";
        doc.back() = '.';
        prm.declare_entry("Model name",
                          "St.Venant-Kirchhoff",
                          Patterns::Selection(Plugins::selection("material")),
                          doc);
        prm.declare_entry("Density",
                          "1060",
                          Patterns::Double(0.),
                          "Mass density of the tissue in the reference "
                          "configuration (kg/m^3); used only when the "
                          "gravity effect is on. 1060 is liver tissue.");
        for (const auto &plugin : Plugins::declarations("material"))
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
        for (const auto &plugin : Plugins::declarations("material"))
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
          Plugins::check_entries("material", model_name, models[model_name]);
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
      AssertThrow(Plugins::find_declaration("effect", name) != nullptr,
                  ExcMessage("no effect called " + name));
      switches[name] = on;
    }



    void
    Effects::set(const std::string &effect,
                 const std::string &entry,
                 const std::string &value)
    {
      const auto *plugin = Plugins::find_declaration("effect", effect);
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
        for (const auto &plugin : Plugins::declarations("effect"))
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
        for (const auto &plugin : Plugins::declarations("effect"))
          {
            switches[plugin.name] = prm.get_bool(plugin.name);
            auto &entries         = loads[plugin.name];
            for (const auto &entry :
                 Plugins::declared_entries(plugin.declare_parameters))
              entries[entry.first] = prm.get(entry.first);
          }
        for (const auto &plugin : Plugins::declarations("effect"))
          if (on(plugin.name))
            try
              {
                Plugins::check_entries("effect",
                                       plugin.name,
                                       loads[plugin.name]);
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



    namespace
    {
      // Nonlinear solver: the staging of the path and the Newton iteration
      // (tolerances, line search, cutbacks), a step of
      // NonlinearSolver::declare_parameters() so that each group reads alone.
      void
      declare_newton_entries(ParameterHandler &prm)
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
      }



      // Nonlinear solver: how each Newton step's linear system is assembled
      // and solved (threads, kept factors, the contact's place), a step of
      // NonlinearSolver::declare_parameters() so that each group reads alone.
      void
      declare_linear_step_entries(ParameterHandler &prm)
      {
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
    } // namespace



    void
    NonlinearSolver::declare_parameters(ParameterHandler &prm)
    {
      prm.enter_subsection("Nonlinear solver");
      {
        declare_newton_entries(prm);
        declare_linear_step_entries(prm);
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
        internal::declare_plugin_choice(
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
        own      = internal::own_entries(prm, "linear solver");
      }
      prm.leave_subsection();
    }
  } // namespace Parameters
} // namespace palpate
