// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

#ifndef palpate_base_plugins_h
#define palpate_base_plugins_h

#include <map>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

namespace dealii
{
  class ParameterHandler;
}

namespace palpate
{
  class Scene;

  /**
   * Pieces of palpate chosen by name in a scene (materials, effects) are
   * plug-ins, registered the way ASPECT registers its material models: the
   * plug-in's `.cc` ends with a registration macro that puts its name, a
   * one-line description, its `declare_parameters` and its factory into the
   * registry of its interface. The `Selection` patterns, the parameter
   * reference, the scene report and the error messages are generated from
   * the registry, so a new plug-in is one new file (doc/extending.md).
   */
  namespace Plugins
  {
    /**
     * The values of a plug-in's own entries (entry name -> value, as text),
     * as a scene file set them or as declared by default. Kept as text so
     * that a scene can be copied, compared and changed (tests, the accuracy
     * study) without knowing the plug-in's types.
     */
    using Entries = std::map<std::string, std::string>;

    /**
     * What a plug-in's factory throws when its entries do not make sense
     * together (e.g. nu = 0.5). The scene turns it into an InputError that
     * names the file, the line and the full entry path.
     */
    class EntryError : public std::runtime_error
    {
    public:
      /** @p entry is the name inside the plug-in's own subsection. */
      EntryError(const std::string &entry,
                 const std::string &problem,
                 const std::string &fix)
        : std::runtime_error(entry + ": " + problem + "; " + fix)
        , entry(entry)
        , problem(problem)
        , fix(fix)
      {}

      const std::string entry, problem, fix;
    };

    /** The declarations of one plug-in's entries, as its own subsection. */
    using DeclareFunction = void (*)(dealii::ParameterHandler &prm);

    /**
     * What each precomputed state keeps besides its force and displacement
     * field, because the interpolation that renders the states reads it:
     * an interpolation plug-in declares it (haptics/interpolation.h). The
     * solver that computes the states and the store that keeps them sit
     * below the haptic side, so they read it from the Declaration
     * (Parameters::StateSpace::state_contents()), never from the
     * interpolation's name.
     */
    struct StateContents
    {
      /** The active node's stiffness K = -df/dx: three more solves per
       * state with its kept factorisation. */
      bool stiffness = false;
      /** The contact patch: the compliance of the surface nodes a sphere
       * can touch from the cells around the state, one solve per node. */
      bool contact_patch = false;
    };

    template <typename Class>
    constexpr auto
    has_check(int) -> decltype(&Class::check_parameters, bool())
    {
      return true;
    }
    template <typename Class>
    constexpr bool
    has_check(long)
    {
      return false;
    }

    template <typename Class>
    constexpr auto
    has_scene_check(int) -> decltype(&Class::check_scene, bool())
    {
      return true;
    }
    template <typename Class>
    constexpr bool
    has_scene_check(long)
    {
      return false;
    }

    /**
     * What a scene needs of a plug-in to declare it: its name, description
     * and entries, without its interface. The scene declares the plug-ins
     * of a kind (e.g. "trajectory") from these, so it does not include the
     * layer that defines them (tests/check_layering.sh).
     */
    struct Declaration
    {
      std::string     name;
      std::string     description;
      DeclareFunction declare_parameters;
      /** Checks the plug-in's own entries when the scene is read (throws
       * EntryError); nullptr if it has no check_parameters(). */
      void (*check_parameters)(const dealii::ParameterHandler &own) = nullptr;
      /** Checks the entries of the scene the plug-in reads outside its own
       * subsection (a mesh source: File name, Mesh / Beam) when the scene
       * is read, throwing the scene's InputError (Scene::error()); nullptr
       * if it has no check_scene(). */
      void (*check_scene)(const Scene &scene) = nullptr;
      /** For a material: the displacement degree its element pair fixes,
       * from its own entries (0: Discretization / Polynomial degree
       * decides); nullptr for the other kinds. */
      unsigned int (*element_degree)(const dealii::ParameterHandler &own) =
        nullptr;
      /** For an interpolation: what each state keeps for it; nothing for
       * the other kinds. */
      StateContents state_contents = {};
    };

    /** A plug-in class's `static void check_parameters(const
     * ParameterHandler &own)`, or nullptr if it has none: what its values
     * must satisfy beyond their patterns, checked when the scene is read,
     * before anything is built. */
    template <typename Class>
    constexpr void (*check_function())(const dealii::ParameterHandler &)
    {
      if constexpr (has_check<Class>(0))
        return &Class::check_parameters;
      else
        return nullptr;
    }

    /** A plug-in class's `static void check_scene(const Scene &scene)`, or
     * nullptr if it has none: what the scene's shared entries must satisfy
     * for it (a mesh source that reads a file needs File name), checked
     * when the scene is read. */
    template <typename Class>
    constexpr void (*scene_check_function())(const Scene &)
    {
      if constexpr (has_scene_check<Class>(0))
        return &Class::check_scene;
      else
        return nullptr;
    }

    /** Check the own @p entries of the plug-in of @p kind called @p name
     * (their patterns, then its check_parameters()): throws EntryError. */
    void
    check_entries(const std::string &kind,
                  const std::string &name,
                  const Entries     &entries);

    /** Run the check_scene() of the plug-in of @p kind called @p name on
     * @p scene, if it has one: throws the scene's InputError. */
    void
    check_scene(const std::string &kind,
                const std::string &name,
                const Scene       &scene);

    /** Add @p declaration to those of @p kind (at static initialisation,
     * by a registration macro). */
    bool
    add_declaration(const std::string &kind, const Declaration &declaration);

    /** The plug-ins of @p kind, sorted by name. */
    const std::vector<Declaration> &
    declarations(const std::string &kind);

    /** The plug-in of @p kind called @p name, or nullptr. */
    const Declaration *
    find_declaration(const std::string &kind, const std::string &name);

    /** Their names joined by '|', for a Patterns::Selection. */
    std::string
    selection(const std::string &kind);

    /**
     * The names and default values of the entries a declare function
     * declares (it is run on a scratch ParameterHandler).
     */
    Entries
    declared_entries(const DeclareFunction declare);

    /**
     * A scratch ParameterHandler with the plug-in's declarations and the
     * values of @p entries set (unknown names and values that do not match
     * an entry's pattern throw EntryError), for the plug-in's factory.
     */
    std::unique_ptr<dealii::ParameterHandler>
    make_parameter_handler(const DeclareFunction declare,
                           const Entries        &entries);

    /**
     * The registry of the plug-ins of one @p Interface. Each plug-in is a
     * name (as scenes spell it), a one-line description, the declarations
     * of its own entries and a factory that builds it from them.
     */
    template <typename Interface, typename... Context>
    class Registry
    {
    public:
      /** Build the plug-in from its entries (the ParameterHandler holds
       * only them) and, for interfaces that have one, the @p Context it
       * lives in (a trajectory: the scene, for its shared entries and
       * paths). Throws EntryError for values that make no sense. */
      using CreateFunction =
        std::unique_ptr<Interface> (*)(const dealii::ParameterHandler &prm,
                                       const Context &...context);

      struct Plugin
      {
        std::string     name;
        std::string     description;
        DeclareFunction declare_parameters;
        CreateFunction  create;
      };

      /** Register @p plugin (at static initialisation, by the macro).
       * Returns true; a second plug-in with the same name aborts: two
       * files would claim one name. */
      static bool
      add(const Plugin &plugin);

      /** add(), and the plug-in's Declaration as one of @p kind (for the
       * built-in plug-ins of a kind the scene declares through
       * Plugins::declarations(); they have no check_parameters()). */
      static bool
      add_declared(const std::string &kind, const Plugin &plugin);

      /** Every registered plug-in, sorted by name. */
      static const std::vector<Plugin> &
      plugins();

      /** The plug-in called @p name, or nullptr. */
      static const Plugin *
      find(const std::string &name);

      /** The names joined by '|', for a Patterns::Selection. */
      static std::string
      selection();

      /** The names as a sentence ("A, B or C"), for messages. */
      static std::string
      names_sentence();

      /** Build the plug-in called @p name from @p entries (missing entries
       * take their default). Throws EntryError. */
      static std::unique_ptr<Interface>
      create(const std::string &name,
             const Entries     &entries,
             const Context &...context);

    private:
      static std::vector<Plugin> &
      storage();
    };
  } // namespace Plugins
} // namespace palpate

/**
 * Register the plug-in @p classname of @p Interface under @p name. The class
 * provides `static void declare_parameters(dealii::ParameterHandler &)` and
 * `static std::unique_ptr<Interface> create(const dealii::ParameterHandler
 * &)`. Put it at the end of the plug-in's `.cc`, at namespace scope.
 */
#define PALPATE_REGISTER_PLUGIN(Interface, classname, name, description) \
  namespace                                                              \
  {                                                                      \
    [[maybe_unused]] const bool palpate_plugin_registered_##classname =  \
      ::palpate::Plugins::Registry<Interface>::add(                      \
        {name,                                                           \
         description,                                                    \
         &classname::declare_parameters,                                 \
         &classname::create});                                           \
  }

/**
 * Register the plug-in @p classname in @p Registry (a Registry<Interface,
 * Context...>) under @p name, and its Declaration as one of @p kind, so that
 * the scene declares and checks its entries without including its interface
 * (devices, trajectories, linear solvers). The class also provides an
 * optional `static void check_parameters(const dealii::ParameterHandler &)`
 * and an optional `static void check_scene(const Scene &)`.
 */
#define PALPATE_REGISTER_DECLARED_PLUGIN(                           \
  Registry, kind, classname, name, description)                     \
  namespace                                                         \
  {                                                                 \
    [[maybe_unused]] const bool                                     \
      palpate_declared_plugin_registered_##classname =              \
        Registry::add({name,                                        \
                       description,                                 \
                       &classname::declare_parameters,              \
                       &classname::create}) &&                      \
        ::palpate::Plugins::add_declaration(                        \
          kind,                                                     \
          {name,                                                    \
           description,                                             \
           &classname::declare_parameters,                          \
           ::palpate::Plugins::check_function<classname>(),         \
           ::palpate::Plugins::scene_check_function<classname>()}); \
  }

#endif
