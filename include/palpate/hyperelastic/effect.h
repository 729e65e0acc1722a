// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

#ifndef palpate_hyperelastic_effect_h
#define palpate_hyperelastic_effect_h

#include <palpate/base/plugins.h>
#include <palpate/scene/parameters.h>

#include <memory>
#include <string>
#include <vector>

namespace palpate
{
  class HyperelasticSystem;
  class Mesh;

  /**
   * A load effect: something a scene may switch on that changes the
   * physics (gravity, a traction on part of the surface). Each is a
   * plug-in: its switch `Effects / NAME = true|false` and its own entries
   * (in subsection Effects, next to the switch) come from its
   * registration; it is built only when the scene switches it on, so an
   * effect that is off allocates, assembles and writes nothing.
   *
   * The output effects (shape output, VTU export, force log) are not
   * plug-ins: they are parts of a run, not of the model.
   */
  class Effect
  {
  public:
    virtual ~Effect() = default;

    /**
     * Check the effect against the mesh before anything is computed.
     * Throws Plugins::EntryError naming one of the effect's entries (e.g.
     * a boundary id no face has).
     */
    virtual void
    check(const Mesh &mesh) const;

    /** What the scene report says when it is on, e.g. "gravity (rho g =
     * 10399 N/m^3 along -z)". */
    virtual std::string
    description(const Mesh &mesh, const Parameters::AllParameters &p) const = 0;

    /** Add the effect's loads to @p system, once, after it is built. */
    virtual void
    apply(HyperelasticSystem              &system,
          const Parameters::AllParameters &p) const = 0;

    /** The effects @p p switches on, in the registry's order. Throws
     * Plugins::EntryError (with the entry's name inside subsection
     * Effects). */
    static std::vector<std::unique_ptr<Effect>>
    create_enabled(const Parameters::Effects &p);
  };

  /**
   * Effect plug-ins register themselves at the end of their `.cc`:
   *
   *     PALPATE_REGISTER_EFFECT(Gravity, "Gravity", "one line")
   *
   * with `static void declare_parameters(ParameterHandler &)` (its entries,
   * declared inside subsection Effects: give them names that say whose
   * they are) and `static std::unique_ptr<Effect> create(const
   * ParameterHandler &)`.
   */
  using EffectRegistry = Plugins::Registry<Effect>;
  extern template class Plugins::Registry<Effect>;

  /** An effect plug-in's entries checked by building it (its
   * Declaration's check_parameters: the scene checks them so, without
   * including this header). */
  template <typename Class>
  void
  check_effect_entries(const dealii::ParameterHandler &own)
  {
    Class::create(own);
  }

  /* Registered in EffectRegistry (the solver builds the effect from it)
   * and declared as an "effect" (Plugins::declarations(): the scene
   * declares and checks its entries without including this header). */
#define PALPATE_REGISTER_EFFECT(classname, name, description)           \
  namespace                                                             \
  {                                                                     \
    [[maybe_unused]] const bool palpate_effect_registered_##classname = \
      ::palpate::EffectRegistry::add({name,                             \
                                      description,                      \
                                      &classname::declare_parameters,   \
                                      &classname::create}) &&           \
      ::palpate::Plugins::add_declaration(                              \
        "effect",                                                       \
        {name,                                                          \
         description,                                                   \
         &classname::declare_parameters,                                \
         &::palpate::check_effect_entries<classname>});                 \
  }
} // namespace palpate

#endif
