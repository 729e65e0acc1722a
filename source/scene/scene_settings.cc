// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

// The command line's `--set ENTRY=VALUE` settings, a variant of a scene
// without copying it: each checked before the file is read (the entry must
// be declared, its pattern must accept the value, and it may be set once),
// with the same help as a bad line in a file, then applied after the file,
// replacing its value or the default.

#include <palpate/scene/scene_impl.h>

#include <algorithm>
#include <set>

namespace palpate
{
  namespace internal
  {
    /**
     * Check the command line's `--set ENTRY=VALUE` strings: the entry must
     * exist, deal.II's pattern must accept the value, and each entry may be
     * set once. The errors name the --set (not the scene file, which is
     * fine) with the same help as a bad line in a file.
     */
    std::vector<CommandLineSetting>
    parse_command_line_settings(const std::vector<std::string> &settings)
    {
      std::vector<CommandLineSetting> parsed;
      std::set<std::string>           keys;
      for (const std::string &text : settings)
        {
          const auto fail = [&](const std::string &problem,
                                const std::string &fix) {
            return InputError("command line", 0, "--set " + text, problem, fix);
          };
          const std::string example =
            "e.g. --set 'Material model/Model name=Neo-Hookean' (the "
            "subsections and the entry separated by '/'); 'palpate "
            "--print-parameters' lists every entry.";
          const auto equal = text.find('=');
          if (equal == std::string::npos)
            throw fail("--set takes ENTRY=VALUE", example);
          CommandLineSetting s;
          s.path  = Utilities::split(text.substr(0, equal), '/');
          s.value = Utilities::trim(text.substr(equal + 1));
          s.name  = s.path.back();
          s.path.pop_back();
          if (s.name.empty() ||
              std::find(s.path.begin(), s.path.end(), "") != s.path.end())
            throw fail("the entry's path has an empty name", example);
          const DeclaredSection *here = &declared_tree();
          for (std::size_t i = 0; i < s.path.size(); ++i)
            {
              const DeclaredSection *next = here->find_subsection(s.path[i]);
              if (next == nullptr)
                throw fail("there is no subsection '" + s.path[i] + "' in " +
                             path_to_string(std::vector<std::string>(
                               s.path.begin(), s.path.begin() + i)),
                           suggestion(s.path[i], here->subsection_names()) +
                             (here->subsection_names().empty() ?
                                path_to_string(std::vector<std::string>(
                                  s.path.begin(), s.path.begin() + i)) +
                                  " has no subsections; its entries are: " +
                                  join(here->entry_names(), ", ") + ". " :
                                "The subsections there are: " +
                                  join(here->subsection_names(), ", ") + ". ") +
                             example);
              here = next;
            }
          const DeclaredEntry *entry = here->find_entry(s.name);
          if (entry == nullptr)
            throw fail("there is no entry '" + s.name + "' in " +
                         path_to_string(s.path),
                       suggestion(s.name, here->entry_names()) +
                         (here->entry_names().empty() ?
                            std::string("That is a subsection without "
                                        "entries of its own. ") :
                            "The entries there are: " +
                              join(here->entry_names(), ", ") + ". ") +
                         example);
          // deal.II's own pattern check, as for a line in the file.
          dealii::ParameterHandler prm;
          Parameters::AllParameters::declare_parameters(prm);
          for (const auto &name : s.path)
            prm.enter_subsection(name);
          try
            {
              prm.set(s.name, s.value);
            }
          catch (const std::exception &)
            {
              throw fail("'" + s.value +
                           "' is not allowed here: the entry "
                           "takes " +
                           describe_pattern(entry->pattern_description),
                         "give such a value (its default is '" +
                           entry->default_value + "').");
            }
          if (!keys.insert(entry_key(s.path, s.name)).second)
            throw fail("the entry is set twice on the command line",
                       "give one --set per entry.");
          parsed.push_back(s);
        }
      return parsed;
    }



    std::vector<std::string>
    RecordingReader::apply_command_line(
      const std::vector<CommandLineSetting> &overrides)
    {
      // The --set entries, after the file (whose text they never touch: a
      // value holding '#' or '\' stays whole, and a file's own mistakes are
      // reported as before). ParameterHandler::set() runs the same actions
      // as a line of the file; parse_command_line_settings() checked each
      // value against its pattern already.
      std::vector<std::string> applied;
      applying_command_line = true;
      for (const CommandLineSetting &o : overrides)
        {
          for (const auto &name : o.path)
            prm.enter_subsection(name);
          prm.set(o.name, o.value);
          for (std::size_t i = 0; i < o.path.size(); ++i)
            prm.leave_subsection();
          applied.push_back(entry_key(o.path, o.name) + "=" + o.value);
        }
      applying_command_line = false;
      return applied;
    }
  } // namespace internal
} // namespace palpate
