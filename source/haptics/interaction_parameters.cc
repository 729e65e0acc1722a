// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

// Interaction::change_parameters() and check_parameters(): what may change
// while the interaction runs (the material, the boundary conditions, the
// effects, the solver settings; not what the grid, cache, engine and filter are
// built for), checked before anything changes.

#include <palpate/haptics/interaction_impl.h>

#include <mutex>
#include <stdexcept>
#include <string>

namespace palpate
{
  namespace
  {
    /**
     * The checks of Interaction::change_parameters(): that @p parameters
     * change only what may change during an interaction, and that @p scene
     * with them is valid and selects nodes on @p mesh. @p scene becomes the
     * changed scene; returns its nodes.
     */
    NodeSelection
    checked_change(Scene                           &scene,
                   const Mesh                      &mesh,
                   const Parameters::AllParameters &parameters)
    {
      // What the grid, the cache, the mesh and the engine's threads were
      // built for cannot change here.
      const Parameters::AllParameters &o = scene.parameters;
      // The Mesh subsection is compared as a whole: a field-by-field list
      // misses the fields nobody added to it (the surface settings), and a
      // live change of one would be accepted and then ignored.
      const char *fixed = nullptr;
      if (o.mesh != parameters.mesh)
        fixed = "Mesh";
      // The interpolation too: it was made for the scene the interaction
      // started with, and it decides what each state keeps (a stiffness, a
      // contact patch), so the solvers and the haptic loop would disagree.
      else if (o.state_space.grid_spacing !=
                 parameters.state_space.grid_spacing ||
               o.state_space.extent != parameters.state_space.extent ||
               o.state_space.interpolation !=
                 parameters.state_space.interpolation ||
               o.state_space.own != parameters.state_space.own)
        fixed = "State space";
      else if (o.engine.type != parameters.engine.type ||
               o.engine.workers != parameters.engine.workers ||
               o.engine.memory_budget != parameters.engine.memory_budget)
        fixed = "Engine";
      else if (o.scheduler.cloud_radius != parameters.scheduler.cloud_radius ||
               o.scheduler.rate != parameters.scheduler.rate ||
               o.scheduler.look_ahead_time !=
                 parameters.scheduler.look_ahead_time)
        fixed = "Scheduler";
      else if (o.haptics.force_limit != parameters.haptics.force_limit ||
               o.haptics.max_force_change !=
                 parameters.haptics.max_force_change)
        fixed = "Haptics";
      if (fixed != nullptr)
        throw std::invalid_argument(
          std::string("Interaction::change_parameters: the subsection '") +
          fixed +
          "' cannot change during an interaction (the mesh, state grid, cache, "
          "engine and force filter are built for it). Change only the "
          "material, the boundary conditions, the effects or the solver "
          "settings, or create a new Interaction from the changed scene.");

      // Check the new scene and select its nodes before anything changes, so
      // that bad parameters leave the interaction as it was.
      scene.parameters = parameters;
      scene.validate();
      return select_nodes(scene, mesh);
    }
  } // namespace



  void
  Interaction::change_parameters(const Parameters::AllParameters &parameters)
  {
    Impl                       &s = *impl;
    std::lock_guard<std::mutex> lock(s.control_mutex);
    if (s.is_attached.load())
      throw std::logic_error(
        "Interaction::change_parameters: detach first (parameters can "
        "change only while no contact is active)");

    Scene         changed = s.scene;
    NodeSelection nodes   = checked_change(changed, s.mesh, parameters);

    // The engine's solvers are built from s.nodes: commit, and restore the
    // old scene if the engine cannot take the new one (the cache is
    // invalidated either way, so nothing computed before is used again).
    Scene         old_scene = std::move(s.scene);
    NodeSelection old_nodes = std::move(s.nodes);
    s.scene                 = std::move(changed);
    s.nodes                 = std::move(nodes);
    try
      {
        s.engine->change_parameters(parameters);
      }
    catch (...)
      {
        s.scene = std::move(old_scene);
        s.nodes = std::move(old_nodes);
        throw;
      }
    // The store holds states of the old physics: nothing of the new ones
    // may go into it (its fingerprint would lie).
    if (s.store)
      {
        s.store.reset();
        s.store_error = "the parameters changed during the interaction, so "
                        "the states computed after the change were not "
                        "stored (they belong to other physics)";
      }
  }



  void
  Interaction::check_parameters(
    const Parameters::AllParameters &parameters) const
  {
    Scene scene = this->scene();
    checked_change(scene, impl->mesh, parameters);
  }
} // namespace palpate
