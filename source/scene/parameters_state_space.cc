// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

// The parameters of the precomputed states (parameters.h): the
// subsections State space (the grid of active-node positions), Scheduler
// (the cloud of states kept around the HIP) and Engine (who computes
// states), each declared with its help text and read back into its struct.

#include <palpate/scene/parameters_impl.h>

namespace palpate
{
  namespace Parameters
  {
    using namespace dealii;



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
        // The interpolations are plug-ins (haptics/interpolation.h): the
        // choice and each one's own subsection come from their
        // declarations.
        internal::declare_plugin_choice(
          prm,
          "interpolation",
          "Interpolation",
          "trilinear",
          "How the haptic loop interpolates the force between grid points.",
          "");
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
        own           = internal::own_entries(prm, "interpolation");
        store         = prm.get("Store");
      }
      prm.leave_subsection();
    }



    Plugins::StateContents
    StateSpace::state_contents() const
    {
      const auto *plugin =
        Plugins::find_declaration("interpolation", interpolation);
      return plugin == nullptr ? Plugins::StateContents() :
                                 plugin->state_contents;
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
          "dropped with their patches; their forces stay (an interpolation "
          "that renders the contact patches renders a cell with such a "
          "corner from the corners' forces alone).");
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
  } // namespace Parameters
} // namespace palpate
