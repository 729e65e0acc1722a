// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

#ifndef palpate_haptics_interpolation_h
#define palpate_haptics_interpolation_h

#include <palpate/base/plugins.h>
#include <palpate/base/utilities.h>
#include <palpate/haptics/force_interpolation.h>

#include <array>
#include <memory>

namespace palpate
{
  class Mesh;
  class Scene;
  class StateCache;
  class StateGrid;

  /**
   * How the haptic loop turns the states computed at the grid points into
   * the force at the HIP, every tick: `State space / Interpolation` chooses
   * one from InterpolationRegistry by name, and the interaction builds it
   * once, for its grid and cache.
   *
   * Interpolations are plug-ins (doc/extending.md). One reads its own
   * entries from its subsection `State space / <its name>`; its file ends
   * with
   *
   *     PALPATE_REGISTER_INTERPOLATION(Nearest, "nearest corner", "one line")
   *
   * where the class has `static void declare_parameters(ParameterHandler
   * &)`, `static constexpr Plugins::StateContents state_contents` (what
   * each state must keep for it: the solver computes it and the store
   * keeps it), `static std::unique_ptr<Interpolation> create(const
   * ParameterHandler &own, const Scene &, const Mesh &, const StateGrid &,
   * const StateCache &)` and, optionally, `static void
   * check_parameters(const ParameterHandler &own)` and `static void
   * check_scene(const Scene &scene)`: the checks of its entries and of
   * what it needs of the scene (a probe tip), run when the scene is read
   * (Scene::validate()).
   *
   * force(), force_while_missing() and reset() run in the real-time
   * thread: they must not allocate, lock or throw. What they need (work
   * space, the last cell's data) is made in create().
   */
  class Interpolation
  {
  public:
    /** An interpolation of the states @p cache holds on @p grid (both
     * outlive it). */
    Interpolation(const StateGrid &grid, const StateCache &cache);

    virtual ~Interpolation() = default;

    /**
     * The force at @p x (m from the active node's rest position) from the
     * states of the corners of its cell: complete once the corners it
     * reads (sample.read) are computed, with the stiffness of the
     * interpolated field there. Real-time safe.
     */
    virtual ForceSample
    force(const Utilities::Point3 &x) noexcept = 0;

    /**
     * At @p x, where force() found data missing after a complete cell: a
     * force (N) and stiffness (N/m, row-major) from what the
     * interpolation kept of the last complete cell, and true; or false,
     * and the haptic loop holds or fades the force (ForceHold). The
     * default keeps nothing. Real-time safe.
     */
    virtual bool
    force_while_missing(const Utilities::Point3 &x,
                        Utilities::Point3       &force,
                        std::array<double, 9>   &stiffness) noexcept;

    /**
     * A new contact starts (Interaction::attach()): forget what
     * earlier ticks kept. Real-time safe; the default keeps nothing.
     */
    virtual void
    reset() noexcept;

    /**
     * The interpolation the scene's `State space / Interpolation` chooses,
     * built from its own entries for @p grid and @p cache of the body
     * @p mesh; a value its factory refuses is an InputError naming the
     * entry.
     */
    static std::unique_ptr<Interpolation>
    create(const Scene      &scene,
           const Mesh       &mesh,
           const StateGrid  &grid,
           const StateCache &cache);

  protected:
    /** The grid of states and the cache that holds them. */
    const StateGrid  &grid;
    const StateCache &cache;
  };

  /** The interpolations, by the names scenes give them. */
  using InterpolationRegistry =
    Plugins::Registry<Interpolation, Scene, Mesh, StateGrid, StateCache>;
  extern template class Plugins::
    Registry<Interpolation, Scene, Mesh, StateGrid, StateCache>;

/** Register the interpolation @p classname as @p name (PALPATE_REGISTER_PLUGIN,
 * plus its declaration for the scene's State space / Interpolation: its
 * entries, checks and the StateContents its states keep). */
#define PALPATE_REGISTER_INTERPOLATION(classname, name, description)           \
  namespace                                                                    \
  {                                                                            \
    [[maybe_unused]] const bool palpate_interpolation_registered_##classname = \
      ::palpate::InterpolationRegistry::add({name,                             \
                                             description,                      \
                                             &classname::declare_parameters,   \
                                             &classname::create}) &&           \
      ::palpate::Plugins::add_declaration(                                     \
        "interpolation",                                                       \
        {name,                                                                 \
         description,                                                          \
         &classname::declare_parameters,                                       \
         ::palpate::Plugins::check_function<classname>(),                      \
         ::palpate::Plugins::scene_check_function<classname>(),                \
         nullptr,                                                              \
         classname::state_contents});                                          \
  }
} // namespace palpate

#endif
