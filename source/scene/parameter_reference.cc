// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

// The declared parameters in words: the tree of subsections and entries as
// deal.II's ParameterHandler knows them, each entry's pattern described for
// a user, and the names and paths that the messages of the reader and of
// --set quote (with a "did you mean"); and the parameter reference
// print_parameters() prints from them, a complete .prm file or
// doc/parameters.md.

#include <palpate/scene/scene_impl.h>

#include <deal.II/base/patterns.h>

#include <boost/property_tree/ptree.hpp>
#include <boost/property_tree/xml_parser.hpp>

#include <algorithm>
#include <cctype>
#include <ostream>
#include <regex>
#include <sstream>

namespace palpate
{
  namespace internal
  {
    namespace
    {
      /** Undo ParameterHandler's XML name mangling ("_2e" -> "."). */
      std::string
      demangle(const std::string &name)
      {
        std::string s;
        for (std::size_t i = 0; i < name.size(); ++i)
          if (name[i] == '_' && i + 2 < name.size() &&
              std::isxdigit(static_cast<unsigned char>(name[i + 1])) &&
              std::isxdigit(static_cast<unsigned char>(name[i + 2])))
            {
              s += static_cast<char>(
                std::stoi(name.substr(i + 1, 2), nullptr, 16));
              i += 2;
            }
          else
            s += name[i];
        return s;
      }

      DeclaredSection
      to_section(const boost::property_tree::ptree &tree)
      {
        DeclaredSection section;
        for (const auto &child : tree)
          {
            const auto &node = child.second;
            if (node.find("pattern_description") != node.not_found())
              section.entries.emplace_back(
                demangle(child.first),
                DeclaredEntry{node.get<std::string>("default_value", ""),
                              node.get<std::string>("documentation", ""),
                              node.get<std::string>("pattern_description")});
            else
              section.subsections.emplace_back(demangle(child.first),
                                               to_section(node));
          }
        return section;
      }
    } // namespace



    /** The declared parameter tree, in declaration order. */
    const DeclaredSection &
    declared_tree()
    {
      static const DeclaredSection tree = []() {
        dealii::ParameterHandler prm;
        Parameters::AllParameters::declare_parameters(prm);
        // The XML output keeps the mangled names deal.II stores (its JSON
        // output would split names like "St.Venant-Kirchhoff" at the dot).
        std::stringstream xml;
        prm.print_parameters(xml,
                             dealii::ParameterHandler::XML |
                               dealii::ParameterHandler::KeepDeclarationOrder);
        boost::property_tree::ptree ptree;
        boost::property_tree::read_xml(xml, ptree);
        return to_section(ptree.get_child("ParameterHandler"));
      }();
      return tree;
    }

    std::string
    join(const std::vector<std::string> &pieces, const std::string &separator)
    {
      std::string s;
      for (unsigned int i = 0; i < pieces.size(); ++i)
        s += (i > 0 ? separator : "") + pieces[i];
      return s;
    }

    std::string
    path_to_string(const std::vector<std::string> &path)
    {
      return path.empty() ? std::string("(top level)") : join(path, " / ");
    }

    std::string
    suggestion(const std::string &word, const std::vector<std::string> &names)
    {
      const std::string close = Utilities::closest_match(word, names);
      return close.empty() ? std::string() : "did you mean '" + close + "'? ";
    }

    /** What a pattern description means, in words a user understands. */
    std::string
    describe_pattern(const std::string &description)
    {
      std::smatch m;
      if (std::regex_match(description,
                           m,
                           std::regex(R"(\[Selection (.*) \])")))
        return "one of: " +
               std::regex_replace(m[1].str(), std::regex(R"(\|)"), ", ");
      if (std::regex_match(description,
                           m,
                           std::regex(R"(\[MultipleSelection (.*) \])")))
        return "a comma-separated list of any of: " +
               std::regex_replace(m[1].str(), std::regex(R"(\|)"), ", ");
      if (description == "[Bool]")
        return "true or false";
      if (std::regex_match(description,
                           m,
                           std::regex(R"(\[Double (\S+)\.\.\.(\S+) .*\])")))
        {
          const bool no_max = m[2].str() == "MAX_DOUBLE";
          const bool no_min = m[1].str() == "-MAX_DOUBLE";
          if (no_min && no_max)
            return "a number";
          if (no_max)
            return "a number >= " + m[1].str();
          return "a number from " + m[1].str() + " to " + m[2].str();
        }
      if (std::regex_match(description,
                           m,
                           std::regex(
                             R"(\[Integer range (\S+)\.\.\.(\S+) .*\])")))
        {
          if (m[2].str() == "2147483647")
            return "a whole number >= " + m[1].str();
          return "a whole number from " + m[1].str() + " to " + m[2].str();
        }
      if (std::regex_search(
            description,
            m,
            std::regex(
              R"(^\[List of <\[Double (\S+)\.\.\.(\S+) .*of length 3\.\.\.3)")))
        return "three numbers separated by commas (x, y, z)" +
               (m[1].str() == "-MAX_DOUBLE" && m[2].str() == "MAX_DOUBLE" ?
                  std::string() :
                  ", each from " + m[1].str() + " to " + m[2].str());
      if (std::regex_search(description,
                            std::regex(
                              R"(^\[List of <\[Double.*of length 3\.\.\.3)")))
        return "three numbers separated by commas (x, y, z)";
      if (std::regex_search(description,
                            std::regex(R"(^\[List of <\[Integer)")))
        return "whole numbers separated by commas";
      // A pattern this function does not know: deal.II's own words.
      const auto pattern = dealii::Patterns::pattern_factory(description);
      return pattern != nullptr ?
               pattern->description(dealii::Patterns::PatternBase::Text) :
               description;
    }

    std::string
    entry_key(const std::vector<std::string> &path, const std::string &name)
    {
      std::string key;
      for (const auto &p : path)
        key += p + "/";
      return key + name;
    }



    namespace
    {
      std::string
      markdown_escape(const std::string &s)
      {
        std::string out;
        for (const char c : s)
          {
            if (c == '|')
              out += "\\|";
            else if (c == '\n')
              out += ' ';
            else
              out += c;
          }
        return out;
      }

      void
      print_markdown_section(std::ostream                   &out,
                             const DeclaredSection          &section,
                             const std::vector<std::string> &path)
      {
        if (!section.entries.empty())
          {
            out << "\n"
                << std::string(std::min<std::size_t>(path.size(), 3) + 1, '#')
                << " `" << join(path, " / ") << "`\n\n"
                << "| Entry | Default | Allowed values | Meaning |\n"
                << "|---|---|---|---|\n";
            for (const auto &[name, entry] : section.entries)
              out << "| `" << markdown_escape(name) << "` | `"
                  << markdown_escape(entry.default_value) << "` | "
                  << markdown_escape(
                       describe_pattern(entry.pattern_description))
                  << " | " << markdown_escape(entry.documentation) << " |\n";
          }
        else
          out << "\n"
              << std::string(std::min<std::size_t>(path.size(), 3) + 1, '#')
              << " `" << join(path, " / ") << "`\n";
        for (const auto &[name, sub] : section.subsections)
          {
            auto sub_path = path;
            sub_path.push_back(name);
            print_markdown_section(out, sub, sub_path);
          }
      }
    } // namespace
  }   // namespace internal



  void
  print_parameters(std::ostream &out, const ParameterFormat format)
  {
    if (format == ParameterFormat::prm)
      {
        dealii::ParameterHandler prm;
        Parameters::AllParameters::declare_parameters(prm);
        // Into a string first: deal.II asserts on a stream that failed
        // (standard output closed or full), which is an output error the
        // caller reports, not an internal one.
        std::ostringstream text;
        prm.print_parameters(text,
                             dealii::ParameterHandler::PRM |
                               dealii::ParameterHandler::KeepDeclarationOrder);
        out << "# Every scene parameter of palpate, at its default value.\n"
            << "# Generated by 'palpate --print-parameters'.\n"
            << text.str();
        return;
      }

    out << "# Scene parameters\n\n"
        << "Every entry a scene file (`.prm`) can set, with its default, the "
           "values it accepts and its meaning (units in brackets or in the "
           "text). A scene that sets nothing gets these defaults: the "
           "built-in organ-like blob, St.Venant-Kirchhoff, no effects.\n\n"
        << "This page is generated by `palpate --print-parameters markdown "
           "> doc/parameters.md`; the test `scene/parameter_reference` fails "
           "when it is out of date.\n\n"
        << "**Relative paths.** A file a scene reads (Mesh / File name, "
           "Haptics / Trajectory / File name) may be given relative to the "
           "scene file's directory: the shipped scenes name the example "
           "organs as `../meshes/...`. If it is not there, palpate looks "
           "relative to the current directory, then relative to "
           "`parameters/` of the palpate source tree it was built from, so "
           "a scene copied out of `parameters/` still finds its organ. A "
           "file found nowhere is reported with every place looked. Files "
           "a scene writes (Output / Directory, State space / Store, the "
           "volume meshes of Mesh / Surface) are relative to the current "
           "directory.\n\n"
        << "**Variants without copying.** Every command that reads a scene "
           "takes `--set ENTRY=VALUE`, repeatable, with the entry's path "
           "from the top (subsections and entry separated by `/`), e.g. "
           "`palpate parameters/liver-stvk.prm --set 'Material model/Model "
           "name=Neo-Hookean' --set \"Material model/Neo-Hookean/Young's "
           "modulus=15465\"`. It replaces the file's value (or the "
           "default), is checked like a line of the file, and the scene "
           "report lists it first.\n";
    for (const auto &[name, sub] : internal::declared_tree().subsections)
      internal::print_markdown_section(out, sub, {name});
  }
} // namespace palpate
