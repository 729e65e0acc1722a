// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

#ifndef palpate_base_plugins_templates_h
#define palpate_base_plugins_templates_h

// The registry's member definitions. Only the `.cc` that explicitly
// instantiates Registry<Interface> (the interface's own file) includes this,
// so there is one registry per interface in libpalpate.

#include <palpate/base/plugins.h>

#include <deal.II/base/parameter_handler.h>

#include <algorithm>
#include <iostream>

namespace palpate
{
  namespace Plugins
  {
    template <typename Interface, typename... Context>
    std::vector<typename Registry<Interface, Context...>::Plugin> &
    Registry<Interface, Context...>::storage()
    {
      // A function-local static: registrations run during static
      // initialisation, in an order the language leaves open.
      static std::vector<Plugin> plugins;
      return plugins;
    }



    template <typename Interface, typename... Context>
    bool
    Registry<Interface, Context...>::add(const Plugin &plugin)
    {
      auto &all = storage();
      if (find(plugin.name) != nullptr)
        {
          std::cerr << "palpate: two plug-ins are registered as \""
                    << plugin.name << "\"; rename one of them." << std::endl;
          std::abort();
        }
      all.push_back(plugin);
      std::sort(all.begin(), all.end(), [](const Plugin &a, const Plugin &b) {
        return a.name < b.name;
      });
      return true;
    }



    template <typename Interface, typename... Context>
    bool
    Registry<Interface, Context...>::add_declared(const std::string &kind,
                                                  const Plugin      &plugin)
    {
      return add(plugin) && add_declaration(kind,
                                            {plugin.name,
                                             plugin.description,
                                             plugin.declare_parameters});
    }



    template <typename Interface, typename... Context>
    const std::vector<typename Registry<Interface, Context...>::Plugin> &
    Registry<Interface, Context...>::plugins()
    {
      return storage();
    }



    template <typename Interface, typename... Context>
    const typename Registry<Interface, Context...>::Plugin *
    Registry<Interface, Context...>::find(const std::string &name)
    {
      for (const auto &plugin : storage())
        if (plugin.name == name)
          return &plugin;
      return nullptr;
    }



    template <typename Interface, typename... Context>
    std::string
    Registry<Interface, Context...>::selection()
    {
      std::string s;
      for (const auto &plugin : storage())
        s += (s.empty() ? "" : "|") + plugin.name;
      return s;
    }



    template <typename Interface, typename... Context>
    std::string
    Registry<Interface, Context...>::names_sentence()
    {
      const auto &all = storage();
      std::string s;
      for (unsigned int i = 0; i < all.size(); ++i)
        s += (i == 0 ? "" : i + 1 == all.size() ? " or " : ", ") + all[i].name;
      return s;
    }



    template <typename Interface, typename... Context>
    std::unique_ptr<Interface>
    Registry<Interface, Context...>::create(const std::string &name,
                                            const Entries     &entries,
                                            const Context &...context)
    {
      const Plugin *plugin = find(name);
      if (plugin == nullptr)
        throw EntryError(name,
                         "no such plug-in",
                         "use " + names_sentence() + ".");
      const auto prm =
        make_parameter_handler(plugin->declare_parameters, entries);
      return plugin->create(*prm, context...);
    }
  } // namespace Plugins
} // namespace palpate

#endif
