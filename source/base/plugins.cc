// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

#include <palpate/base/plugins.h>
#include <palpate/base/utilities.h>

#include <deal.II/base/parameter_handler.h>

#include <algorithm>
#include <map>
#include <sstream>

namespace palpate
{
  namespace Plugins
  {
    Entries
    declared_entries(const DeclareFunction declare)
    {
      // deal.II 9.4 cannot list a subsection's entries; its short output
      // format can ("set NAME = VALUE", one per line, names padded).
      dealii::ParameterHandler prm;
      declare(prm);
      std::ostringstream out;
      prm.print_parameters(out, dealii::ParameterHandler::ShortPRM);
      Entries            entries;
      std::istringstream in(out.str());
      std::string        line;
      while (std::getline(in, line))
        {
          line = Utilities::trim(line);
          if (line.rfind("set ", 0) != 0)
            continue;
          const auto equals = line.find('=');
          if (equals == std::string::npos)
            continue;
          entries[Utilities::trim(line.substr(4, equals - 4))] =
            Utilities::trim(line.substr(equals + 1));
        }
      return entries;
    }



    namespace
    {
      std::map<std::string, std::vector<Declaration>> &
      all_declarations()
      {
        // A function-local static, as Registry::storage().
        static std::map<std::string, std::vector<Declaration>> all;
        return all;
      }
    } // namespace



    bool
    add_declaration(const std::string &kind, const Declaration &declaration)
    {
      auto &of_kind = all_declarations()[kind];
      of_kind.push_back(declaration);
      std::sort(of_kind.begin(),
                of_kind.end(),
                [](const Declaration &a, const Declaration &b) {
                  return a.name < b.name;
                });
      return true;
    }



    const std::vector<Declaration> &
    declarations(const std::string &kind)
    {
      return all_declarations()[kind];
    }



    const Declaration *
    find_declaration(const std::string &kind, const std::string &name)
    {
      for (const auto &d : declarations(kind))
        if (d.name == name)
          return &d;
      return nullptr;
    }



    void
    check_entries(const std::string &kind,
                  const std::string &name,
                  const Entries     &entries)
    {
      for (const auto &d : declarations(kind))
        if (d.name == name)
          {
            const auto prm =
              make_parameter_handler(d.declare_parameters, entries);
            if (d.check_parameters != nullptr)
              d.check_parameters(*prm);
          }
    }



    void
    check_scene(const std::string &kind,
                const std::string &name,
                const Scene       &scene)
    {
      for (const auto &d : declarations(kind))
        if (d.name == name && d.check_scene != nullptr)
          d.check_scene(scene);
    }



    std::string
    selection(const std::string &kind)
    {
      std::string s;
      for (const auto &d : declarations(kind))
        s += (s.empty() ? "" : "|") + d.name;
      return s;
    }



    std::unique_ptr<dealii::ParameterHandler>
    make_parameter_handler(const DeclareFunction declare,
                           const Entries        &entries)
    {
      auto prm = std::make_unique<dealii::ParameterHandler>();
      declare(*prm);
      for (const auto &[name, value] : entries)
        try
          {
            prm->set(name, value);
          }
        catch (const std::exception &)
          {
            const auto declared = declared_entries(declare);
            throw EntryError(name,
                             declared.count(name) == 0 ?
                               "no such entry" :
                               "\"" + value + "\" is not a valid value",
                             declared.count(name) == 0 ?
                               "remove it." :
                               "the default is " + declared.at(name) + ".");
          }
      return prm;
    }
  } // namespace Plugins
} // namespace palpate
