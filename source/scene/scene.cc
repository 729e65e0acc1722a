// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

#include <palpate/hyperelastic/effect.h>
#include <palpate/hyperelastic/material.h>
#include <palpate/scene/scene.h>

#include <deal.II/base/parameter_handler.h>
#include <deal.II/base/patterns.h>

#include <boost/property_tree/ptree.hpp>
#include <boost/property_tree/xml_parser.hpp>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iostream>
#include <regex>
#include <set>
#include <sstream>
#include <thread>

namespace palpate
{
  namespace
  {
    /** One declared entry, as the ParameterHandler knows it. */
    struct DeclaredEntry
    {
      std::string default_value;
      std::string documentation;
      std::string pattern_description;
    };

    /** One declared subsection: its entries and subsections, in order. */
    struct DeclaredSection
    {
      std::vector<std::pair<std::string, DeclaredEntry>>   entries;
      std::vector<std::pair<std::string, DeclaredSection>> subsections;

      const DeclaredEntry *
      find_entry(const std::string &name) const
      {
        for (const auto &e : entries)
          if (e.first == name)
            return &e.second;
        return nullptr;
      }

      const DeclaredSection *
      find_subsection(const std::string &name) const
      {
        for (const auto &s : subsections)
          if (s.first == name)
            return &s.second;
        return nullptr;
      }

      std::vector<std::string>
      entry_names() const
      {
        std::vector<std::string> names;
        for (const auto &e : entries)
          names.push_back(e.first);
        return names;
      }

      std::vector<std::string>
      subsection_names() const
      {
        std::vector<std::string> names;
        for (const auto &s : subsections)
          names.push_back(s.first);
        return names;
      }
    };

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
            s +=
              static_cast<char>(std::stoi(name.substr(i + 1, 2), nullptr, 16));
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

    /** The physical lines of a scene file, without line ends. */
    std::vector<std::string>
    split_lines(const std::string &content)
    {
      std::vector<std::string> lines;
      std::istringstream       in(content);
      std::string              line;
      while (std::getline(in, line))
        {
          if (!line.empty() && line.back() == '\r')
            line.pop_back();
          lines.push_back(line);
        }
      return lines;
    }

    /** @p line without its comment ('#' not after a backslash), trimmed. */
    std::string
    without_comment(const std::string &line)
    {
      for (std::size_t i = 0; i < line.size(); ++i)
        if (line[i] == '#' && (i == 0 || line[i - 1] != '\\'))
          return Utilities::trim(line.substr(0, i));
      return Utilities::trim(line);
    }

    bool
    starts_with_keyword(const std::string &line,
                        const std::string &keyword,
                        std::string       &rest)
    {
      if (line.size() < keyword.size())
        return false;
      for (unsigned int i = 0; i < keyword.size(); ++i)
        if (std::tolower(static_cast<unsigned char>(line[i])) != keyword[i])
          return false;
      if (line.size() == keyword.size())
        {
          rest.clear();
          return true;
        }
      if (line[keyword.size()] != ' ' && line[keyword.size()] != '\t')
        return false;
      rest = Utilities::trim(line.substr(keyword.size()));
      return true;
    }

    /**
     * The statement that ends on line @p last (1-based): its first line
     * and its text, continuation lines ('\' at the end) joined.
     */
    std::pair<unsigned int, std::string>
    statement_at(const std::vector<std::string> &lines, const unsigned int last)
    {
      if (last == 0 || last > lines.size())
        return {last, ""};
      unsigned int first = last;
      while (first > 1)
        {
          const std::string previous = without_comment(lines[first - 2]);
          if (previous.empty() || previous.back() != '\\')
            break;
          --first;
        }
      std::string text;
      for (unsigned int l = first; l <= last; ++l)
        {
          std::string piece = without_comment(lines[l - 1]);
          if (l < last && !piece.empty() && piece.back() == '\\')
            piece.pop_back();
          text += (text.empty() ? "" : " ") + piece;
        }
      return {first, Utilities::trim(text)};
    }

    /**
     * The subsection path in force before line @p line (1-based), and
     * where each of its subsections was opened. deal.II's ParameterHandler
     * has accepted these lines: this only finds where a message points.
     */
    std::vector<std::string>
    path_before(const std::vector<std::string> &lines,
                const unsigned int              line,
                std::vector<unsigned int>      *opened_at = nullptr)
    {
      std::vector<std::string>  path;
      std::vector<unsigned int> opened;
      for (unsigned int l = 1; l < line && l <= lines.size(); ++l)
        {
          std::string       rest;
          const std::string t = without_comment(lines[l - 1]);
          if (starts_with_keyword(t, "subsection", rest))
            {
              path.push_back(rest);
              opened.push_back(l);
            }
          else if (starts_with_keyword(t, "end", rest) && rest.empty() &&
                   !path.empty())
            {
              path.pop_back();
              opened.pop_back();
            }
        }
      if (opened_at != nullptr)
        *opened_at = opened;
      return path;
    }

    /** The declared subsection at @p path, nullptr if there is none. */
    const DeclaredSection *
    section_at(const std::vector<std::string> &path)
    {
      const DeclaredSection *s = &declared_tree();
      for (const auto &name : path)
        if (s != nullptr)
          s = s->find_subsection(name);
      return s;
    }

    std::string
    entry_key(const std::vector<std::string> &path, const std::string &name)
    {
      std::string key;
      for (const auto &p : path)
        key += p + "/";
      return key + name;
    }

    /**
     * Attach to every declared entry below @p section an action that
     * passes the entry's key ("Section/Entry") and value to @p record.
     */
    void
    record_every_entry(dealii::ParameterHandler                       &prm,
                       const DeclaredSection                          &section,
                       std::vector<std::string>                       &path,
                       const std::function<void(const std::string &,
                                                const std::string &)> &record)
    {
      for (const auto &named_entry : section.entries)
        {
          const std::string key = entry_key(path, named_entry.first);
          prm.add_action(named_entry.first,
                         [key, &record](const std::string &value) {
                           record(key, value);
                         });
        }
      for (const auto &[name, sub] : section.subsections)
        {
          prm.enter_subsection(name);
          path.push_back(name);
          record_every_entry(prm, sub, path, record);
          path.pop_back();
          prm.leave_subsection();
        }
    }

    /** deal.II's own words for an exception, without the stack trace. */
    std::string
    dealii_message(const std::exception &e)
    {
      if (const auto *d = dynamic_cast<const dealii::ExceptionBase *>(&e))
        {
          std::ostringstream s;
          d->print_info(s);
          std::string text = Utilities::trim(s.str());
          for (char &c : text)
            if (c == '\n')
              c = ' ';
          return text;
        }
      return e.what();
    }

    /** "A/B/C" as "A / B / C". */
    std::string
    shown_key(const std::string &key)
    {
      std::string s;
      for (const char c : key)
        s += c == '/' ? std::string(" / ") : std::string(1, c);
      return s;
    }

    /**
     * The error for the statement deal.II's ParameterHandler stopped at:
     * which line, which entry, why, and a likely fix. @p kind says which
     * of deal.II's exceptions it threw.
     */
    enum class Rejection
    {
      no_subsection,
      cannot_parse,
      invalid_value,
      other
    };

    InputError
    explain_rejection(const std::string              &filename,
                      const std::vector<std::string> &lines,
                      const unsigned int              last_line,
                      const Rejection                 kind,
                      const std::string              &dealii_words)
    {
      const auto [line, text]             = statement_at(lines, last_line);
      const std::vector<std::string> path = path_before(lines, line);
      const DeclaredSection         *here = section_at(path);
      std::string                    rest;
      if (here != nullptr && kind == Rejection::no_subsection &&
          starts_with_keyword(text, "subsection", rest))
        return InputError(filename,
                          line,
                          "subsection " + rest + " (in " +
                            path_to_string(path) + ")",
                          "there is no subsection '" + rest + "' here",
                          suggestion(rest, here->subsection_names()) +
                            "The subsections here are: " +
                            join(here->subsection_names(), ", ") +
                            ". 'palpate --print-parameters' lists everything.");
      if (here != nullptr && starts_with_keyword(text, "set", rest))
        {
          const auto equal = rest.find('=');
          if (equal == std::string::npos)
            return InputError(filename,
                              line,
                              text,
                              "a 'set' line needs the form 'set Name = value'",
                              "add ' = value' after the entry name.");
          const std::string    name  = Utilities::trim(rest.substr(0, equal));
          const std::string    value = Utilities::trim(rest.substr(equal + 1));
          const DeclaredEntry *entry = here->find_entry(name);
          if (entry == nullptr)
            return InputError(filename,
                              line,
                              path_to_string(path) + " / " + name,
                              "there is no entry '" + name + "' in " +
                                path_to_string(path),
                              suggestion(name, here->entry_names()) +
                                "The entries here are: " +
                                join(here->entry_names(), ", ") + ".");
          if (kind == Rejection::invalid_value)
            {
              std::string       hint;
              const std::string selection = "[Selection ";
              const auto       &d         = entry->pattern_description;
              if (d.compare(0, selection.size(), selection) == 0 &&
                  d.size() > selection.size() + 2)
                hint =
                  suggestion(value,
                             Utilities::split(d.substr(selection.size(),
                                                       d.size() -
                                                         selection.size() - 2),
                                              '|'));
              return InputError(
                filename,
                line,
                path_to_string(path) + " / " + name + " = " + value,
                "'" + value + "' is not allowed here: the entry takes " +
                  describe_pattern(d),
                hint + "Set " + name + " to such a value (its default is '" +
                  entry->default_value + "').");
            }
        }
      if (starts_with_keyword(text, "end", rest) && rest.empty() &&
          path.empty())
        return InputError(filename,
                          line,
                          "end",
                          "'end' without a matching 'subsection'",
                          "remove this line, or add the 'subsection' it is "
                          "meant to close.");
      if (kind == Rejection::cannot_parse &&
          !starts_with_keyword(text, "set", rest) &&
          !starts_with_keyword(text, "subsection", rest) &&
          !starts_with_keyword(text, "end", rest))
        return InputError(filename,
                          line,
                          text,
                          "this line is not 'subsection Name', 'end' or "
                          "'set Name = value'",
                          "fix the line or comment it out with '#'.");
      return InputError(filename,
                        line,
                        text.empty() ? std::string("(whole file)") : text,
                        "deal.II's ParameterHandler rejected the file: " +
                          dealii_words,
                        "fix the line the message names.");
    }

    /** A `--set ENTRY=VALUE` from the command line, checked against the
     * declared parameters. */
    struct CommandLineSetting
    {
      std::vector<std::string> path; // subsections
      std::string              name, value;
    };

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

    /**
     * Refuse a name that is not a scene file before opening it: a directory
     * (named with the .prm files in it), or a pipe, a device or a socket.
     */
    void
    check_is_regular_file(const std::string &filename)
    {
      namespace fs = std::filesystem;
      std::error_code ec;
      if (fs::is_directory(filename, ec))
        {
          std::vector<std::string> scenes;
          for (const auto &e : fs::directory_iterator(filename, ec))
            if (e.path().extension() == ".prm")
              scenes.push_back(e.path().string());
          std::sort(scenes.begin(), scenes.end());
          throw InputError(
            filename,
            0,
            "(the scene file itself)",
            "this is a directory, not a scene file",
            scenes.empty() ?
              std::string("give a .prm scene file; shipped scenes are in "
                          "parameters/, e.g. 'palpate "
                          "parameters/default.prm'.") :
              "give one of the " + std::to_string(scenes.size()) +
                " .prm files in it, e.g. 'palpate " + scenes.front() + "'.");
        }
      if (const auto status = fs::status(filename, ec);
          !ec && fs::exists(status) && !fs::is_regular_file(status))
        throw InputError(filename.substr(0, 300),
                         0,
                         "(the scene file itself)",
                         "this is not a regular file but a pipe, a device or "
                         "a socket: palpate would wait for it, or read it "
                         "without end",
                         "name the scene's .prm file itself.");
    }

    /**
     * The error for a scene file that cannot be opened, with the reason the
     * file system gives.
     */
    InputError
    cannot_open(const std::string &filename)
    {
      bool              none = false;
      const std::string why  = why_cannot_open(filename, &none);
      return InputError(
        filename.substr(0, 300),
        0,
        "(the scene file itself)",
        "the file cannot be opened: " +
          (why.empty() ? std::string("it is not readable") : why),
        none ? "check the path; shipped scenes are in parameters/, e.g. "
               "'palpate parameters/default.prm'." :
               "name the scene's .prm file itself (check the links on "
               "the way and the permissions).");
    }

    /**
     * The scene file's bytes: an error that says why if it cannot be opened
     * or read, or if it is too large to be a scene.
     */
    std::string
    read_scene_bytes(const std::string &filename)
    {
      std::ifstream in(filename, std::ios::binary);
      if (!in)
        throw cannot_open(filename);
      // A scene is a few kB of text: refuse to read gigabytes by mistake.
      constexpr std::size_t max_bytes = std::size_t(4) << 20;
      std::string           content(max_bytes + 1, '\0');
      in.read(content.data(), content.size());
      if (in.bad())
        throw InputError(filename,
                         0,
                         "(the scene file itself)",
                         "the file cannot be read (an input/output error)",
                         "check the disk and the path.");
      content.resize(in.gcount());
      if (content.size() > max_bytes)
        throw InputError(filename,
                         0,
                         "(the scene file itself)",
                         "the file is larger than 4 MiB; a scene file is a "
                         "few kB of text",
                         "check that this is the scene (.prm) and not a mesh "
                         "or an output file.");
      return content;
    }

    /**
     * Drop a UTF-8 byte order mark from @p content; refuse UTF-16 text.
     */
    void
    strip_byte_order_mark(std::string &content, const std::string &filename)
    {
      // A byte order mark: some editors (Notepad) begin UTF-8 with one; it
      // is not part of the text. UTF-16 is not a scene file palpate reads:
      // named, instead of "a NUL byte" in column 2.
      if (content.rfind("\xEF\xBB\xBF", 0) == 0)
        content.erase(0, 3);
      else if (content.rfind("\xFF\xFE", 0) == 0 ||
               content.rfind("\xFE\xFF", 0) == 0)
        throw InputError(filename,
                         1,
                         "(the scene file itself)",
                         "the file is UTF-16 text (it begins with a UTF-16 "
                         "byte order mark); a scene file is plain text (ASCII "
                         "or UTF-8)",
                         "save it as UTF-8 (in Notepad: Save as, Encoding "
                         "UTF-8), or convert it: iconv -f UTF-16 -t UTF-8 '" +
                           filename + "' > scene.prm");
    }

    /**
     * Refuse NUL bytes and control characters (other than tabs and carriage
     * returns), naming the line and column of the first.
     */
    void
    check_plain_text(const std::string &content, const std::string &filename)
    {
      unsigned int line = 1, column = 1;
      for (const char c : content)
        {
          const auto byte = static_cast<unsigned char>(c);
          if (c == '\n')
            {
              ++line;
              column = 1;
              continue;
            }
          if (byte < 0x20 && c != '\t' && c != '\r')
            throw InputError(
              filename,
              line,
              "column " + std::to_string(column) + " of line " +
                std::to_string(line),
              "the line holds " +
                std::string(byte == 0 ? "a NUL byte" :
                                        "a control character (byte " +
                                          std::to_string(byte) + ")") +
                ", which a scene file (plain text) cannot contain",
              "delete the character, or check that this is the scene file "
              "and not a binary file.");
          ++column;
        }
    }

    /** Refuse the first 'include' line: a scene is one file. */
    void
    check_no_includes(const std::vector<std::string> &lines,
                      const std::string              &filename)
    {
      for (unsigned int l = 1; l <= lines.size(); ++l)
        {
          std::string rest;
          if (starts_with_keyword(without_comment(lines[l - 1]),
                                  "include",
                                  rest))
            throw InputError(filename,
                             l,
                             without_comment(lines[l - 1]),
                             "scene files cannot include other files",
                             "copy the entries you need into this file.");
        }
    }

    /** One entry set by the scene file or by a --set. */
    struct Setting
    {
      std::string  key;
      std::string  value;
      unsigned int line;
      bool         command_line; // a --set, applied after the file
    };

    /**
     * deal.II's ParameterHandler reading a scene's text. An action on every
     * entry records what the file sets and on which line (the stream
     * position tells), so messages can point at the line and an entry set
     * twice is caught instead of the last one silently winning.
     */
    class RecordingReader
    {
    public:
      /** Declare the parameters and attach the recording actions. */
      RecordingReader(const std::string              &filename,
                      std::string                     text,
                      const std::vector<std::string> &lines);

      RecordingReader(const RecordingReader &) = delete;
      RecordingReader &
      operator=(const RecordingReader &) = delete;

      /** Parse the file's text; explain a rejection by its line. */
      void
      parse_file();

      /**
       * Apply the --set entries after the file; return them as
       * "key=value" strings.
       */
      std::vector<std::string>
      apply_command_line(const std::vector<CommandLineSetting> &overrides);

      /** The entries set, in the order the file and the --set set them. */
      const std::vector<Setting> &
      settings() const
      {
        return settings_;
      }

      /** The parameters as read. */
      dealii::ParameterHandler &
      handler()
      {
        return prm;
      }

    private:
      /** The line the stream has reached. */
      unsigned int
      line_now();

      const std::string              &filename;
      const std::string               content;
      const std::vector<std::string> &lines;
      std::istringstream              stream;
      std::vector<Setting>            settings_;
      bool                            applying_command_line = false;
      const std::function<void(const std::string &, const std::string &)>
                               record;
      dealii::ParameterHandler prm;
    };



    RecordingReader::RecordingReader(const std::string              &filename,
                                     std::string                     text,
                                     const std::vector<std::string> &lines)
      : filename(filename)
      , content(text.empty() || text.back() != '\n' ? text + '\n' : text)
      , lines(lines)
      , stream(content)
      , record([this](const std::string &key, const std::string &value) {
        settings_.push_back({key,
                             value,
                             applying_command_line ? 0u : line_now(),
                             applying_command_line});
      })
    {
      Parameters::AllParameters::declare_parameters(prm);
      std::vector<std::string> path;
      record_every_entry(prm, declared_tree(), path, record);
      settings_.clear(); // add_action() ran each action once for the default
    }



    unsigned int
    RecordingReader::line_now()
    {
      const std::streamoff position = stream.tellg();
      if (position < 0)
        return lines.size();
      return std::count(content.begin(), content.begin() + position, '\n');
    }



    void
    RecordingReader::parse_file()
    {
      try
        {
          prm.parse_input(stream, filename, "", false);
        }
      catch (const dealii::ParameterHandler::ExcNoSubsection &e)
        {
          throw explain_rejection(filename,
                                  lines,
                                  line_now(),
                                  Rejection::no_subsection,
                                  dealii_message(e));
        }
      catch (const dealii::ParameterHandler::ExcCannotParseLine &e)
        {
          throw explain_rejection(filename,
                                  lines,
                                  line_now(),
                                  Rejection::cannot_parse,
                                  dealii_message(e));
        }
      catch (const dealii::ParameterHandler::ExcInvalidEntryForPattern &e)
        {
          throw explain_rejection(filename,
                                  lines,
                                  line_now(),
                                  Rejection::invalid_value,
                                  dealii_message(e));
        }
      catch (const dealii::ParameterHandler::ExcUnbalancedSubsections &)
        {
          std::vector<unsigned int>      opened;
          const std::vector<std::string> path =
            path_before(lines, lines.size() + 1, &opened);
          if (path.empty())
            throw InputError(filename,
                             0,
                             "(whole file)",
                             "the numbers of 'subsection' and 'end' lines "
                             "differ",
                             "close every subsection with one 'end'.");
          throw InputError(filename,
                           opened.back(),
                           "subsection " + path.back(),
                           "the subsection opened here is never closed",
                           "add a line 'end' after its last entry.");
        }
      catch (const std::exception &e)
        {
          throw explain_rejection(
            filename, lines, line_now(), Rejection::other, dealii_message(e));
        }
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

    /**
     * Keep each entry's value and line (0 for a --set, which replaces the
     * file's value); refuse an entry the file sets twice.
     */
    void
    keep_entry_lines_and_values(const std::vector<Setting>          &settings,
                                const std::string                   &filename,
                                std::map<std::string, unsigned int> &lines,
                                std::map<std::string, std::string>  &values)
    {
      std::map<std::string, const Setting *> first_setting;
      for (const Setting &s : settings)
        {
          if (s.command_line) // a --set: it replaces the file's value
            {
              lines[s.key]  = 0;
              values[s.key] = s.value;
              continue;
            }
          const auto [it, first] = first_setting.emplace(s.key, &s);
          if (!first)
            throw InputError(filename,
                             s.line,
                             shown_key(s.key) + " = " + s.value,
                             "the entry is set twice: on line " +
                               std::to_string(it->second->line) + " (" +
                               it->second->value + ") and on line " +
                               std::to_string(s.line) + " (" + s.value +
                               "); palpate does not guess which one you "
                               "meant",
                             "delete one of the two lines.");
          lines[s.key]  = s.line;
          values[s.key] = s.value;
        }
    }

    /**
     * Convert the values read into @p parameters; name the entry whose
     * number is out of range if deal.II's conversion refuses one.
     */
    void
    convert_parameters(Parameters::AllParameters  &parameters,
                       dealii::ParameterHandler   &prm,
                       const std::vector<Setting> &settings,
                       const std::string          &filename)
    {
      try
        {
          parameters.parse_parameters(prm);
        }
      catch (const std::exception &e)
        {
          // deal.II's patterns accept numbers that its conversions then
          // refuse: values out of double range, like 1e-320.
          for (const Setting &s : settings)
            for (const std::string &piece : Utilities::split(s.value, ','))
              {
                if (piece.empty())
                  continue;
                errno            = 0;
                char        *end = nullptr;
                const double x   = std::strtod(piece.c_str(), &end);
                if (end != piece.c_str() && errno == ERANGE)
                  throw InputError(
                    s.command_line ? std::string("command line") : filename,
                    s.command_line ? 0 : s.line,
                    shown_key(s.key) + " = " + s.value,
                    "'" + piece + "' is out of the range of numbers palpate " +
                      "computes with (" +
                      (std::abs(x) < 1 ? "too close to zero: below 1e-307" :
                                         "too large: beyond 1e308") +
                      ")",
                    "give a value within the entry's physical range; "
                    "'palpate --print-parameters' shows the default.");
              }
          throw InputError(filename,
                           0,
                           "(whole file)",
                           "deal.II's ParameterHandler could not convert a "
                           "value: " +
                             dealii_message(e),
                           "fix the entry the message names.");
        }
    }
  } // namespace



  Scene::Scene()
  {
    dealii::ParameterHandler prm;
    Parameters::AllParameters::declare_parameters(prm);
    parameters.parse_parameters(prm);
  }



  Scene
  Scene::read(const std::string              &filename,
              const std::vector<std::string> &command_line)
  {
    // The command line's --set entries first: a mistake there is reported
    // as one, whatever the file holds.
    const std::vector<CommandLineSetting> overrides =
      parse_command_line_settings(command_line);
    Scene scene{Unparsed()};
    scene.file_      = filename;
    scene.directory_ = std::filesystem::path(filename).parent_path().string();

    check_is_regular_file(filename);
    std::string content = read_scene_bytes(filename);
    strip_byte_order_mark(content, filename);
    check_plain_text(content, filename);
    const std::vector<std::string> lines = split_lines(content);
    check_no_includes(lines, filename);

    RecordingReader reader(filename, content, lines);
    reader.parse_file();
    scene.command_line_settings_ = reader.apply_command_line(overrides);
    keep_entry_lines_and_values(reader.settings(),
                                filename,
                                scene.entry_lines_,
                                scene.entry_values_);
    convert_parameters(scene.parameters,
                       reader.handler(),
                       reader.settings(),
                       filename);
    scene.validate();
    return scene;
  }



  namespace
  {
    /** The candidates Scene::resolve_path() tries, in order, without
     * repeats. */
    std::vector<std::string>
    path_candidates(const std::string &directory, const std::string &path)
    {
      namespace fs = std::filesystem;
      if (path.empty() || fs::path(path).is_absolute())
        return {path};
      std::vector<std::string> candidates;
      const auto               add = [&](const fs::path &base) {
        const std::string c = (base / path).lexically_normal().string();
        if (std::find(candidates.begin(), candidates.end(), c) ==
            candidates.end())
          candidates.push_back(c);
      };
      add(directory.empty() ? fs::path() : fs::path(directory));
      add(fs::path());
#ifdef PALPATE_SOURCE_DIR
      add(fs::path(PALPATE_SOURCE_DIR) / "parameters");
#endif
      return candidates;
    }
  } // namespace



  std::string
  Scene::resolve_path(const std::string &path) const
  {
    const auto candidates = path_candidates(directory_, path);
    for (const auto &c : candidates)
      {
        // error_code: a name the file system refuses (too long, a loop of
        // links) is not there; the caller's message says so.
        std::error_code error;
        if (std::filesystem::exists(c, error))
          return c;
      }
    return candidates.front();
  }



  std::string
  Scene::where_looked(const std::string &path) const
  {
    const auto  candidates = path_candidates(directory_, path);
    std::string text;
    for (std::size_t i = 0; i < candidates.size(); ++i)
      {
        // Absolute: "../meshes/x.msh" would not say where that was.
        std::error_code error;
        const auto      shown = std::filesystem::absolute(candidates[i], error);
        text +=
          (i == 0                     ? "" :
           i + 1 == candidates.size() ? " or " :
                                        ", ") +
          ("'" + (error ? candidates[i] : shown.lexically_normal().string()) +
           "'");
        // A link to nowhere is there: what is missing is its target.
        if (const std::string link = dangling_link(candidates[i]);
            !link.empty())
          text += " (" + link.substr(link.find("' is ") + 5) + ")";
      }
    return text;
  }



  unsigned int
  Scene::line_of(const std::string &entry) const
  {
    const auto it = entry_lines_.find(entry);
    return it == entry_lines_.end() ? 0 : it->second;
  }



  InputError
  Scene::error(const std::string              &entry,
               const std::string              &problem_alone,
               const std::string              &fix,
               const std::vector<std::string> &with) const
  {
    // A relation between entries (Extent against Grid spacing) is blamed
    // on one of them; if another was set on the command line, the problem
    // says so, or the user would look for it in the file.
    std::string also;
    for (const std::string &other : with)
      for (const std::string &setting : command_line_settings_)
        if (setting.compare(0, other.size() + 1, other + "=") == 0)
          also += (also.empty() ? "" : ", ") + ("--set " + setting);
    const std::string problem =
      also.empty() ? problem_alone :
                     problem_alone + " (with " + also + " on the command line)";
    std::string shown = std::regex_replace(entry, std::regex("/"), " / ");
    const auto  value = entry_values_.find(entry);
    for (const std::string &setting : command_line_settings_)
      if (setting.compare(0, entry.size() + 1, entry + "=") == 0)
        return InputError("command line",
                          0,
                          "--set " + setting + " (scene " +
                            (file_.empty() ? std::string("(default)") : file_) +
                            ")",
                          problem,
                          fix);
    if (value != entry_values_.end())
      shown += " = " + value->second;
    else
      shown += " (default value; the file does not set it)";
    return InputError(file_.empty() ? std::string("(default scene)") : file_,
                      line_of(entry),
                      shown,
                      problem,
                      fix);
  }



  namespace Limits
  {
    // Bounds on the numbers that set a loop count, an allocation or a
    // time (issue 26): without them a typo hangs a run or overflows.
    /** Moduli (Pa): below this round-off decides the force (fat, the
     * softest tissue, is ~1e2 Pa). */
    constexpr double min_modulus = 1e-3;
    /** Haptics / Loop rate (Hz): below this there is no haptic loop. */
    constexpr double min_loop_rate = 1;
    /** Scheduler / Rate (Hz): below, planning lags the hand by seconds. */
    constexpr double min_scheduler_rate = 1;
    /** Haptics / Force limit (N): below, no force is rendered. */
    constexpr double min_force_limit = 1e-3;
    /** Haptics / Maximum force change (N per tick): below, a 1 N force
     * takes more than 10 s to arrive at 1 kHz. */
    constexpr double min_force_change = 1e-4;
    /** Nonlinear solver / Number of increments: each is a Newton solve. */
    constexpr unsigned int max_increments = 1000;
    /** Nonlinear solver / Maximum Newton iterations per increment. */
    constexpr unsigned int max_newton_iterations = 1000;
    /** Nonlinear solver / Maximum line search steps: 2^-60 is below
     * double precision. */
    constexpr unsigned int max_line_search_steps = 60;
    /** Nonlinear solver / Maximum cutbacks: 2^-30 of an increment. */
    constexpr unsigned int max_cutbacks = 30;
    /** Engine / Memory budget (MiB): 1 TiB; beyond, its byte count
     * overflows. */
    constexpr double max_memory_budget = 1 << 20;
    /** Nonlinear solver / Residual and Increment tolerance: below, round-off
     * (1e-16 times the condition) keeps Newton from ever converging. */
    constexpr double min_tolerance = 1e-15;
    /** Nonlinear solver / Residual tolerance: the force's error is about
     * this times the force scale; above, it means nothing. */
    constexpr double max_residual_tolerance = 0.1;
    /** Nonlinear solver / Increment tolerance: the active node within this
     * times the body's diameter of its target. */
    constexpr double max_increment_tolerance = 1e-3;
    /** Nonlinear solver / Maximum increment length (m), unless 0: a path
     * of more than 1000 increments is refused, and 1000 of these are
     * 10 cm, the paper's largest displacement. */
    constexpr double min_increment_length = 1e-4;
    /** Material model / Density (kg/m^3): five times the densest element's
     * (osmium, 22,590); tissue is about 1,000-1,100. */
    constexpr double max_density = 1e5;
    /** Material model / Density (kg/m^3), unless 0: lighter than any
     * tissue (fat is about 900, lung about 300): 1.06 is liver in g/cm^3,
     * and its gravity would be a thousand times too weak. */
    constexpr double min_density = 100;
  } // namespace Limits



  void
  Scene::validate() const
  {
    check_material();
    check_effects();
    check_plugin_entries();
    check_probe();
    check_mesh();
    check_fixed_nodes();
    check_solver_tolerances();
    check_state_space();
    check_newton_counts();
    check_haptics();
    check_shape_output();
  }



  bool
  Scene::sets(const std::string &entry) const
  {
    return line_of(entry) > 0 ||
           std::any_of(command_line_settings_.begin(),
                       command_line_settings_.end(),
                       [&](const std::string &setting) {
                         return setting.compare(0,
                                                entry.size() + 1,
                                                entry + "=") == 0;
                       });
  }



  unsigned int
  Scene::displacement_degree() const
  {
    return Material::create(parameters.material_model)
      ->formulation()
      .degree(parameters.discretization.polynomial_degree);
  }



  void
  Scene::check_material() const
  {
    using namespace Limits;
    const auto &p = parameters;

    // Material: the plug-in checks that its constants describe a solid.
    const auto               &m = p.material_model;
    std::unique_ptr<Material> material;
    try
      {
        material = Material::create(m);
      }
    catch (const Plugins::EntryError &e)
      {
        throw error("Material model/" + m.model_name + "/" + e.entry,
                    e.problem,
                    e.fix);
      }

    // Moduli beyond any solid's (diamond: E = 1.2e12 Pa) only overflow the
    // force scale; soft tissue is 1e2 - 1e7 Pa.
    for (const auto &[entry, value] : material->moduli())
      if (std::abs(value) > max_modulus)
        throw error("Material model/" + m.model_name +
                      (entry.empty() ? "" : "/" + entry),
                    "at most " + Utilities::to_string(max_modulus, 3) +
                      " Pa: stiffer than any solid (diamond is 1.2e12 Pa); "
                      "such moduli only overflow the solver's force scale",
                    "give the modulus in Pa: soft tissue is 1e2 - 1e7 Pa "
                    "(liver: E = 15465 Pa).");
    // The lower bound holds for the stiffness scale (Young's modulus of the
    // small-strain limit, 6 (C10 + C01) for Mooney-Rivlin), not for each
    // constant: a tiny C01 beside a liver's C10 is a valid law.
    if (const double E = material->youngs_modulus(); E > 0 && E < min_modulus)
      {
        const auto        moduli = material->moduli();
        const std::string entry =
          moduli.empty() || moduli.front().first.empty() ?
            "" :
            "/" + moduli.front().first;
        throw error("Material model/" + m.model_name + entry,
                    "the material's small-strain Young's modulus is " +
                      Utilities::to_string(E, 3) + " Pa; at least " +
                      Utilities::to_string(min_modulus, 3) +
                      " Pa: softer than any tissue (fat is about 1e2 Pa), so "
                      "that the forces fall below round-off and Newton "
                      "'converges' on any state",
                    "give the moduli in Pa: soft tissue is 1e2 - 1e7 Pa "
                    "(liver: E = 15465 Pa, or C10 = 2148, C01 = 430).");
      }

    // The largest modulus whose lambda fits with @p nu, to 3 digits rounded
    // down: rounded to nearest, the value named can lie above the bound
    // (6.006e10 Pa for nu = 0.499 would read "6.01e+10"), and the modulus
    // the refusal suggests would be refused in turn.
    const auto largest_modulus = [](const double nu) {
      const double E     = max_modulus * (1 + nu) * (1 - 2 * nu) / nu;
      const double digit = std::pow(10., std::floor(std::log10(E)) - 2);
      return std::floor(E / digit) * digit;
    };
    // A Poisson's ratio a hair below 0.5 passes its own check but makes the
    // first Lame constant astronomical: nu = 0.49999999999999994 gives a
    // 1.7e12 N force for a 1 cm push (lambda 4.6e19 Pa). Held against the
    // same bound as the moduli.
    if (const double nu = material->poissons_ratio(); nu < 0.5)
      {
        const double E      = material->youngs_modulus();
        const double lambda = E * nu / ((1 + nu) * (1 - 2 * nu));
        // With nu <= 0.499 it is the modulus that makes lambda too large
        // (E from 6.1e11 Pa with the liver's nu = 0.49): blaming nu would
        // ask for a fix, nu <= 0.499, that it already meets.
        const auto moduli  = material->moduli();
        const bool modulus = nu > 0 && nu <= 0.499 && !moduli.empty() &&
                             !moduli.front().first.empty();
        if (!(std::abs(lambda) <= max_modulus))
          throw error(
            "Material model/" + m.model_name + "/" +
              (modulus ? moduli.front().first : "Poisson's ratio"),
            (modulus ?
               "E = " + Utilities::to_string_exact(E) + " Pa with nu = " :
               std::string("nu = ")) +
              Utilities::to_string_exact(nu) +
              " makes the first Lame constant lambda = E nu / ((1 + nu)(1 - "
              "2 nu)) = " +
              Utilities::to_string_apart(lambda, max_modulus) +
              " Pa, more than " + Utilities::to_string(max_modulus, 3) +
              " Pa: stiffer than any solid, it only overflows the solver's "
              "force scale",
            modulus ?
              "give the modulus in Pa, at most " +
                Utilities::to_string(largest_modulus(nu), 3) +
                " Pa with this nu: soft tissue is 1e2 - 1e7 Pa (liver: E = "
                "15465 Pa)." :
              "for a nearly incompressible tissue use nu <= 0.499 (linear "
              "elements lock long before 0.5), or Mooney-Rivlin, whose mixed "
              "formulation keeps the volume without locking.");
      }

    // An element pair (Taylor-Hood, P1-P1) fixes the displacement degree.
    if (const Formulation f = material->formulation();
        f.displacement_degree > 0 && sets("Discretization/Polynomial degree") &&
        p.discretization.polynomial_degree != f.displacement_degree)
      throw error("Discretization/Polynomial degree",
                  m.model_name + "'s element pair " + f.element +
                    " has displacements of degree " +
                    std::to_string(f.displacement_degree),
                  "remove this entry (Material model / " + m.model_name +
                    " / Element chooses the degree), or choose the "
                    "element pair with the degree you want.");
  }



  void
  Scene::check_effects() const
  {
    using namespace Limits;
    const auto &p = parameters;

    // Effects: each plug-in checks its entries.
    try
      {
        Effect::create_enabled(p.effects);
      }
    catch (const Plugins::EntryError &e)
      {
        throw error("Effects/" + e.entry, e.problem, e.fix);
      }
  }



  void
  Scene::check_plugin_entries() const
  {
    const auto &p     = parameters;
    const auto  check = [&](const std::string &kind,
                           const std::string &section,
                           const std::string &name,
                           const std::map<std::string, Plugins::Entries> &own) {
      const auto entries = own.find(name);
      try
        {
          Plugins::check_entries(kind,
                                 name,
                                 entries == own.end() ? Plugins::Entries() :
                                                         entries->second);
        }
      catch (const Plugins::EntryError &e)
        {
          throw error(section + "/" + name + "/" + e.entry, e.problem, e.fix);
        }
    };
    check("device", "Haptics", p.haptics.device, p.haptics.own);
    check("trajectory",
          "Haptics/Trajectory",
          p.haptics.trajectory.type,
          p.haptics.trajectory.own);
    if (p.linear_solver.solver != "by size")
      check("linear solver",
            "Linear solver",
            p.linear_solver.solver,
            p.linear_solver.own);
  }



  void
  Scene::check_probe() const
  {
    using namespace Limits;
    const auto &p = parameters;

    // The probe's tip: a radius means something only for a glued tip or a
    // sphere (before Tip existed, Tip radius > 0 meant glued nodes).
    {
      using Tip     = Parameters::ActiveNode::Tip;
      const auto &a = p.boundary_conditions.active_node;
      if (a.tip == Tip::point && a.tip_radius > 0)
        throw error("Boundary conditions/Active node/Tip radius",
                    "Tip radius = " + Utilities::to_string(a.tip_radius, 4) +
                      " m, but Tip = point has no radius",
                    "set Tip = sphere (a rigid sphere in contact with the "
                    "surface: a force that converges with the mesh) or Tip "
                    "= glued nodes (the surface nodes within the radius "
                    "follow the probe), or remove Tip radius.");
      if (a.tip != Tip::point && !(a.tip_radius > 0))
        throw error("Boundary conditions/Active node/Tip radius",
                    "Tip = " +
                      std::string(a.tip == Tip::sphere ? "sphere" :
                                                         "glued nodes") +
                      " needs a positive Tip radius",
                    "set Tip radius in metres, e.g. 0.01 for a probe of "
                    "1 cm radius.");
      if (a.tip != Tip::point && a.tip_radius > max_sphere_radius)
        throw error(
          "Boundary conditions/Active node/Tip radius",
          std::string(a.tip == Tip::sphere ? "a sphere" : "a glued tip") +
            " of " +
            Utilities::to_string_apart(a.tip_radius, max_sphere_radius) +
            " m radius is no probe (at most " +
            Utilities::to_string(max_sphere_radius, 3) + " m)",
          "give the radius in metres (a 1 cm probe: 0.01).");
    }
  }



  void
  Scene::check_mesh() const
  {
    using namespace Limits;
    const auto &p = parameters;

    // Mesh.
    if (p.mesh.source == "file" && p.mesh.file_name.empty())
      throw error("Mesh/File name",
                  "Source = file, but no mesh file is named",
                  "set File name to a .msh, .vtk or .vtu file, or choose "
                  "Source = beam or blob.");
    if (p.mesh.source == "surface" && p.mesh.file_name.empty())
      throw error("Mesh/File name",
                  "Source = surface, but no surface file is named",
                  "set File name to the organ's closed surface (.stl, .obj, "
                  ".ply, .vtk or .vtp).");
    // A file named for a generator is a mistake: the run would silently
    // use a beam or blob instead of the organ the user meant.
    if ((p.mesh.source == "beam" || p.mesh.source == "blob") &&
        !p.mesh.file_name.empty() && sets("Mesh/File name"))
      throw error("Mesh/File name",
                  "a file is named, but Source = " + p.mesh.source +
                    " generates the mesh and ignores it",
                  "set Source = file (a tetrahedral mesh) or Source = "
                  "surface (an organ's surface, meshed by palpate), or "
                  "remove File name.");
    if (p.mesh.scale_factor <= 0)
      throw error("Mesh/Scale factor",
                  "the scale factor must be positive",
                  "set it to the number of metres per mesh-file unit, e.g. "
                  "0.001 for a mesh in millimetres.");
    // No file unit is below a nanometre or above a thousand kilometres;
    // past that the coordinates in metres under- or overflow, and the
    // messages that follow would blame the mesh instead of the scale.
    if (p.mesh.scale_factor < 1e-9 || p.mesh.scale_factor > 1e6)
      throw error("Mesh/Scale factor",
                  "a scale factor of " +
                    Utilities::to_string(p.mesh.scale_factor, 3) +
                    " m per mesh-file unit is no unit of length a mesh is "
                    "written in (1e-9, a nanometre, to 1e6)",
                  "set it to the number of metres per mesh-file unit, e.g. "
                  "0.001 for a mesh in millimetres, 1 for metres.");

    if (p.mesh.source == "beam")
      {
        const double dims[3]  = {p.mesh.beam_length,
                                 p.mesh.beam_width,
                                 p.mesh.beam_height};
        const char  *names[3] = {"Length", "Width", "Height"};
        const char  *words[3] = {"length", "width", "height"};
        for (unsigned int d = 0; d < 3; ++d)
          if (!(dims[d] > 0))
            throw error(std::string("Mesh/Beam/") + names[d],
                        std::string("the beam's ") + words[d] +
                          " must be positive: a beam of zero or negative " +
                          words[d] + " has no volume",
                        std::string("set it in metres, e.g. ") +
                          (d == 0 ? "0.1." : "0.02."));
          else if (dims[d] < min_body_size / 2 || dims[d] > max_body_size)
            // As a mesh file's body (check_size in mesh.cc): past these its
            // elements' volumes under- or overflow and the messages blame
            // the generated mesh.
            throw error(std::string("Mesh/Beam/") + names[d],
                        std::string("a beam ") +
                          Utilities::to_string(dims[d], 3) + " m in " +
                          words[d] + "; a body to palpate is " +
                          Utilities::to_string(min_body_size / 2, 3) + " to " +
                          Utilities::to_string(max_body_size, 3) +
                          " m in each direction",
                        std::string("set it in metres, e.g. ") +
                          (d == 0 ? "0.1." : "0.02."));
        const double nodes = (p.mesh.beam_subdivisions_length + 1.) *
                             (p.mesh.beam_subdivisions_width + 1.) *
                             (p.mesh.beam_subdivisions_height + 1.);
        if (nodes > max_generated_nodes)
          throw error("Mesh/Beam/Subdivisions",
                      "the beam would have " + Utilities::to_string(nodes, 3) +
                        " nodes; at most " +
                        Utilities::to_string(max_generated_nodes, 3) +
                        " are allowed (a state of 1e5 nodes takes minutes, "
                        "far from haptic rates)",
                      "use fewer subdivisions, e.g. 10, 2, 2.");
      }
    // As palpate mesh --fine-size: below 10 micrometres Gmsh works until
    // its time limit and the message blames the limit.
    if (p.mesh.source == "surface" && p.mesh.surface_fine_size > 0 &&
        p.mesh.surface_fine_size < 1e-5)
      throw error("Mesh/Surface/Refinement size",
                  "an element size of " +
                    Utilities::to_string(p.mesh.surface_fine_size, 3) +
                    " m near the probe; at least 1e-5 m (10 micrometres)",
                  "give the size in metres: a third of the sphere's radius "
                  "is a good start, e.g. 0.003 for a 1 cm sphere.");
    if (p.mesh.source == "blob")
      for (unsigned int d = 0; d < 3; ++d)
        {
          if (!(p.mesh.blob_semi_axes[d] > 0))
            throw error(
              "Mesh/Blob/Semi-axes",
              "every semi-axis must be positive: a blob with a zero "
              "or negative semi-axis has no volume",
              "give three lengths in metres, e.g. 0.125, 0.09, 0.07.");
          else if (p.mesh.blob_semi_axes[d] < min_body_size / 4 ||
                   p.mesh.blob_semi_axes[d] > max_body_size / 2)
            throw error(
              "Mesh/Blob/Semi-axes",
              "a semi-axis of " +
                Utilities::to_string(p.mesh.blob_semi_axes[d], 3) +
                " m; a body to palpate is " +
                Utilities::to_string(min_body_size / 2, 3) + " to " +
                Utilities::to_string(max_body_size, 3) +
                " m across, a semi-axis half that",
              "give three lengths in metres, e.g. 0.125, 0.09, 0.07.");
        }
  }



  void
  Scene::check_fixed_nodes() const
  {
    using namespace Limits;
    const auto &p = parameters;

    // Fixed nodes: the region must be well-defined.
    const auto &f = p.boundary_conditions.fixed_nodes;
    if (f.selection == "box")
      for (unsigned int d = 0; d < 3; ++d)
        if (!(f.box_lower_corner[d] < f.box_upper_corner[d]))
          throw error("Boundary conditions/Fixed nodes/Box upper corner",
                      "the box is empty: its upper corner is not above its "
                      "lower corner in every coordinate",
                      "make each coordinate of Box upper corner larger than "
                      "that of Box lower corner.");
    if (f.selection == "half-space" &&
        std::max({std::abs(f.half_space_normal[0]),
                  std::abs(f.half_space_normal[1]),
                  std::abs(f.half_space_normal[2])}) == 0)
      throw error("Boundary conditions/Fixed nodes/Half-space normal",
                  "the normal is the zero vector",
                  "give the direction pointing into the fixed half-space, "
                  "e.g. 0, 0, -1.");
    if (f.selection == "node list" && f.node_ids.empty())
      throw error("Boundary conditions/Fixed nodes/Node ids",
                  "Selection = node list, but the list is empty",
                  "list the node numbers to fix, separated by commas.");
  }



  void
  Scene::check_solver_tolerances() const
  {
    using namespace Limits;
    const auto &p = parameters;

    // Solver tolerances.
    const auto &n = p.nonlinear_solver;
    if (n.residual_tolerance <= 0)
      throw error("Nonlinear solver/Residual tolerance",
                  "the tolerance must be positive",
                  "use e.g. 1e-8.");
    if (n.increment_tolerance <= 0)
      throw error("Nonlinear solver/Increment tolerance",
                  "the tolerance must be positive",
                  "use e.g. 1e-8.");
    if (n.residual_tolerance < min_tolerance ||
        n.residual_tolerance > max_residual_tolerance)
      throw error("Nonlinear solver/Residual tolerance",
                  "between " + Utilities::to_string(min_tolerance, 3) +
                    " and " + Utilities::to_string(max_residual_tolerance, 3) +
                    ": the force is accurate to about this times the force "
                    "scale, so above that it means nothing, and below it "
                    "round-off keeps Newton from ever converging (every "
                    "state a failure point)",
                  "use 1e-8 (the default) or what `palpate study` "
                  "recommends, e.g. 1e-4.");
    if (n.increment_tolerance < min_tolerance ||
        n.increment_tolerance > max_increment_tolerance)
      throw error("Nonlinear solver/Increment tolerance",
                  "between " + Utilities::to_string(min_tolerance, 3) +
                    " and " + Utilities::to_string(max_increment_tolerance, 3) +
                    ": the active node is on its target to this times the "
                    "body's diameter, so above that the probe is not where "
                    "the force is computed, and below it round-off keeps "
                    "Newton from ever converging",
                  "use 1e-8 (the default).");
    if (n.max_increment_length > 0 &&
        n.max_increment_length < min_increment_length)
      throw error("Nonlinear solver/Maximum increment length",
                  "0 (no limit) or at least " +
                    Utilities::to_string(min_increment_length, 3) +
                    " m (0.1 mm): a path needing more than 1000 increments "
                    "is refused as a failure point, and 1000 increments of "
                    "0.1 mm are 10 cm, the paper's largest displacement",
                  "use 0.01 (the default) or the grid spacing.");
    if (p.material_model.density > max_density)
      throw error("Material model/Density",
                  "at most " + Utilities::to_string(max_density, 3) +
                    " kg/m^3, five times the densest element's (osmium, "
                    "22,590): the density is in kg/m^3, and tissue's is "
                    "about 1,000-1,100",
                  "use 1060 (liver) or your tissue's density in kg/m^3.");
    if (p.material_model.density > 0 && p.material_model.density < min_density)
      {
        const double rho = p.material_model.density;
        // g/cm^3 only where that reading gives a tissue's density.
        const bool in_g_per_cm3 = rho >= 0.2 && rho <= 2;
        throw error(
          "Material model/Density",
          "0 (weightless) or at least " + Utilities::to_string(min_density, 3) +
            " kg/m^3: the density is in kg/m^3 and tissue's is "
            "about 1,000-1,100 (lung about 300)" +
            (in_g_per_cm3 ? "; " + Utilities::to_string(rho, 4) +
                              " looks like g/cm^3, which would make gravity a "
                              "thousand times too weak" :
                            std::string()),
          in_g_per_cm3 ? "use " + Utilities::to_string(1000 * rho, 4) +
                           " if you meant g/cm^3 (1060 is liver)." :
                         "use 1060 (liver) or your tissue's density in "
                         "kg/m^3.");
      }
  }



  void
  Scene::check_state_space() const
  {
    using namespace Limits;
    const auto &p = parameters;

    // State space and cloud.
    if (p.state_space.grid_spacing <= 0)
      throw error("State space/Grid spacing",
                  "the grid spacing must be positive",
                  "use e.g. 0.005 (5 mm).");
    if (p.state_space.extent < p.state_space.grid_spacing)
      throw error("State space/Extent",
                  "the grid extent is smaller than one grid spacing, so the "
                  "grid has no cell",
                  "make Extent at least Grid spacing (typically 0.1 m, the "
                  "paper's largest displacement).",
                  {"State space/Grid spacing"});
    {
      // Every grid point costs about 70 bytes of bookkeeping, computed or
      // not: 2e7 points are 1.4 GB.
      const double side =
        2 * std::floor(p.state_space.extent / p.state_space.grid_spacing) + 1;
      if (side * side * side > 2e7)
        throw error("State space/Extent",
                    "the grid would have " + Utilities::to_string(side, 6) +
                      "^3 = " + Utilities::to_string(side * side * side, 3) +
                      " points; at most 2e7 are allowed (about 70 bytes "
                      "each, computed or not)",
                    "reduce Extent or increase Grid spacing (0.1 m with "
                    "0.005 m gives 41^3 = 68921 points).",
                    {"State space/Grid spacing"});
    }
    if (p.state_space.interpolation == "contact patch")
      {
        using Tip = Parameters::ActiveNode::Tip;
        if (p.boundary_conditions.active_node.tip != Tip::sphere)
          throw error("State space/Interpolation",
                      "contact patch solves the contact of a sphere against "
                      "each state's surface, but Boundary conditions / Active "
                      "node / Tip is not sphere",
                      "set Tip = sphere with a Tip radius, or Interpolation "
                      "= tricubic Hermite.",
                      {"Boundary conditions/Active node/Tip"});
        // The patches travel with the states' forces (MPI results too);
        // a store keeps none yet.
        if (!p.state_space.store.empty())
          throw error("State space/Interpolation",
                      "contact patch needs each state's contact patch, and "
                      "a State space / Store keeps forces and shapes only",
                      "leave Store empty (set Store =) with contact patch, "
                      "or use Interpolation = tricubic Hermite with a "
                      "store.",
                      {"State space/Store"});
      }
    if (p.scheduler.cloud_radius < std::sqrt(3.) * p.state_space.grid_spacing)
      throw error(
        "Scheduler/Cloud radius",
        "the cloud cannot hold all 8 corners of the cell the HIP "
        "is in: it must reach at least sqrt(3) h = " +
          Utilities::to_string(std::sqrt(3.) * p.state_space.grid_spacing, 4) +
          " m",
        "increase Cloud radius or decrease State space / Grid "
        "spacing.",
        {"State space/Grid spacing"});
    if (!(p.scheduler.rate >= min_scheduler_rate))
      throw error("Scheduler/Rate",
                  "at least " + Utilities::to_string(min_scheduler_rate, 3) +
                    " Hz: the scheduler re-plans the cloud around the moving "
                    "HIP on each cycle; slower, the states the hand needs are "
                    "planned seconds late and the force fades",
                  "use 100 Hz (the paper's rate).");
    if (p.scheduler.cloud_radius > p.state_space.extent)
      throw error("Scheduler/Cloud radius",
                  "the cloud reaches beyond the state space (State space / "
                  "Extent = " +
                    Utilities::to_string(p.state_space.extent, 4) +
                    " m): the initial cloud alone would be most of the "
                    "grid's points, and the motion would wait for them",
                  "keep the cloud local: a radius of 4-6 grid spacings (the "
                  "default 0.025 m with 0.005 m spacing); at most Extent.",
                  {"State space/Extent"});
    // Unbounded, a look-ahead of 1e9 s would centre the cloud where the
    // HIP would be in 30 years, and the hand would meet missing data.
    if (p.scheduler.look_ahead_time > 2)
      throw error("Scheduler/Look-ahead time",
                  "at most 2 s: the cloud is centred where the HIP would be "
                  "after this time at its current velocity, and a hand keeps "
                  "its velocity for a fraction of a second; farther ahead "
                  "the cloud leaves the HIP and the force fades",
                  "use 0.2 s (the default), or 0 for the paper's cloud "
                  "around the HIP.");
    if (p.scheduler.rate > max_scheduler_rate)
      throw error("Scheduler/Rate",
                  "at most " + Utilities::to_string(max_scheduler_rate, 4) +
                    " Hz: the scheduler re-plans the cloud on each cycle, and "
                    "faster cycles only take time from the solvers",
                  "use 100 Hz (the paper's rate).");
    {
      const unsigned int cores =
        std::max(2u, std::thread::hardware_concurrency());
      if (p.engine.type == "threads" && p.engine.workers > cores)
        throw error("Engine/Workers",
                    "at most " + std::to_string(cores) +
                      " on this machine, its number of cores: each worker is "
                      "a solver thread that needs a core, and more workers "
                      "than cores only take time from the haptic loop",
                    "set Workers to " + std::to_string(cores) +
                      " or less (for more solvers, use several machines: "
                      "Engine / Type = mpi).");
      if (p.nonlinear_solver.assembly_threads > cores)
        throw error("Nonlinear solver/Assembly threads",
                    "at most " + std::to_string(cores) +
                      " on this machine, its number of cores: more threads "
                      "than cores do not assemble faster",
                    "set Assembly threads to 1 (the workers already use the "
                    "cores) or at most " +
                      std::to_string(cores) + ".");
    }
  }



  void
  Scene::check_newton_counts() const
  {
    using namespace Limits;
    const auto &p = parameters;
    const auto &n = p.nonlinear_solver;

    // The Newton solver's loop counts.
    const auto count_bound = [&](const std::string &entry,
                                 const unsigned int value,
                                 const unsigned int bound,
                                 const std::string &why,
                                 const std::string &fix) {
      if (value > bound)
        throw error("Nonlinear solver/" + entry,
                    "at most " + std::to_string(bound) + ": " + why,
                    fix);
    };
    count_bound("Number of increments",
                n.n_increments,
                max_increments,
                "each increment is a Newton solve, and increments shorter "
                "than the grid spacing change no state, they only cost time "
                "(doc/accuracy-vs-time.md)",
                "use 1 (Maximum increment length shortens long paths).");
    count_bound("Maximum Newton iterations",
                n.max_newton_iterations,
                max_newton_iterations,
                "Newton converges in a few iterations or not at all; more "
                "only keep a solver from the states the hand needs",
                "use 25 (the default).");
    count_bound("Maximum line search steps",
                n.max_line_search_steps,
                max_line_search_steps,
                "each halves the step, and 2^-60 of a step is below double "
                "precision",
                "use 16 (the default).");
    count_bound("Maximum cutbacks",
                n.max_cutbacks,
                max_cutbacks,
                "each halves the increment and solves it again; 2^-30 of "
                "an increment moves the probe by nothing",
                "use 2 (the default).");
    if (p.engine.memory_budget > max_memory_budget)
      throw error("Engine/Memory budget",
                  "at most " + Utilities::to_string(max_memory_budget, 7) +
                    " MiB (1 TiB): more than any machine palpate runs on, "
                    "and beyond it the budget's byte count overflows",
                  "give the memory for cached states in MiB, e.g. 1024.");
  }



  void
  Scene::check_haptics() const
  {
    using namespace Limits;
    const auto &p = parameters;

    // Haptics.
    const auto &h = p.haptics;
    if (h.loop_rate <= 0)
      throw error("Haptics/Loop rate",
                  "the rate must be positive",
                  "use 1000 Hz.");
    if (h.loop_rate < min_loop_rate)
      throw error("Haptics/Loop rate",
                  "at least " + Utilities::to_string(min_loop_rate, 3) +
                    " Hz: a haptic loop renders forces at hundreds to "
                    "thousands of ticks per second, and a run waits for "
                    "its ticks",
                  "use 1000 Hz.");
    if (!(h.force_limit >= min_force_limit))
      throw error("Haptics/Force limit",
                  "at least " + Utilities::to_string(min_force_limit, 3) +
                    " N: below, the device renders (nearly) no force at all "
                    "(haptic devices reach 1-40 N)",
                  "set the device's peak force in N, e.g. 8.");
    // The limit is the device's safety: 1e308 N would remove it. No
    // haptic device renders a kilonewton.
    if (h.force_limit > 1000)
      throw error("Haptics/Force limit",
                  "at most 1000 N: the limit protects the hand and the "
                  "device, and haptic devices reach 1-40 N",
                  "set the device's peak force in N, e.g. 8.");
    if (h.max_force_change > h.force_limit)
      throw error("Haptics/Maximum force change",
                  "at most the force limit (" +
                    Utilities::to_string(h.force_limit, 4) +
                    " N) per tick: a larger change is a jump the filter "
                    "would never limit",
                  "use e.g. 0.05 N.");
    if (!(h.max_force_change >= min_force_change))
      throw error("Haptics/Maximum force change",
                  "at least " + Utilities::to_string(min_force_change, 3) +
                    " N per tick: below, a force of 1 N takes more than 10 s "
                    "to arrive at 1 kHz, and the hand feels nothing",
                  "use e.g. 0.05 N.");
    if (h.loop_rate > max_loop_rate)
      throw error("Haptics/Loop rate",
                  "at most " + Utilities::to_string(max_loop_rate, 5) +
                    " Hz: haptic devices run at 1 kHz, the fastest at 10 kHz, "
                    "and the loop preallocates its statistics for every tick",
                  "use 1000 Hz.");
    const auto &t = h.trajectory;
    // At least 0.1 mm: below, a smooth random motion's speed scaling
    // divides by (nearly) zero and its positions are NaN.
    // A circle starts at rest and goes around through the point two radii
    // away, so Radius = Extent leaves the state space (to twice it); a
    // random walk stays within Radius.
    const double across = t.type == "circle" ? 2 : 1;
    if ((t.type == "circle" || t.type == "smooth random") &&
        across * t.radius > p.state_space.extent)
      throw error("Haptics/Trajectory/Radius",
                  // (6 digits: with 3, 0.0501 would say "goes 0.1 m", as
                  // if it fitted.)
                  "a " + t.type + " of radius " +
                    Utilities::to_string_exact(t.radius) + " m goes " +
                    Utilities::to_string_apart(across * t.radius,
                                               p.state_space.extent,
                                               6) +
                    " m from rest and leaves the state space (State space "
                    "/ Extent = " +
                    Utilities::to_string(p.state_space.extent, 3) +
                    " m), where no force is computed",
                  "give the radius in metres, e.g. 0.01, at most " +
                    Utilities::to_string(p.state_space.extent / across, 3) +
                    " m" +
                    (across == 2 ? std::string(" (half the extent: a circle "
                                               "through rest reaches twice "
                                               "its radius).") :
                                   std::string(" (the extent).")),
                  {"State space/Extent"});
    if ((t.type == "circle" || t.type == "smooth random") &&
        !(t.radius >= 1e-4))
      throw error("Haptics/Trajectory/Radius",
                  "a " + t.type +
                    " needs a radius of at least 0.0001 m (0.1 mm; with 0 "
                    "or less every position of the probe is undefined)",
                  "give the radius in metres, e.g. 0.01.");
    if ((t.type == "straight line" || t.type == "circle") &&
        t.direction[0] == 0 && t.direction[1] == 0 && t.direction[2] == 0)
      throw error("Haptics/Trajectory/Direction",
                  "the direction is the zero vector",
                  "give a direction, e.g. 0, 0, -1.");
    // A motion of less than a hundredth of a second is no motion: with 0
    // (or 1e-300) the run ended at once with 0 N and exit 0.
    if (t.type != "replay" && !(t.duration >= 0.01))
      throw error("Haptics/Trajectory/Duration",
                  "the motion would last " +
                    Utilities::to_string(t.duration, 3) +
                    " s: at least 0.01 s (ten ticks of a 1 kHz loop) are "
                    "needed for any motion",
                  "give the motion's length in seconds, e.g. 2.");
    if (t.type != "replay" && t.duration > max_motion_duration)
      throw error("Haptics/Trajectory/Duration",
                  "at most " + Utilities::to_string(max_motion_duration, 4) +
                    " s (one hour): the haptic loop preallocates its "
                    "statistics and force log for every tick of the run, so "
                    "the real-time thread never allocates",
                  "split a longer session into several runs.");
    if (t.type != "replay" && t.speed > max_hip_speed)
      throw error("Haptics/Trajectory/Speed",
                  "at most " + Utilities::to_string(max_hip_speed, 3) +
                    " m/s: a hand on a haptic device moves at most about "
                    "2 m/s, and states for a faster probe can never be "
                    "computed in time",
                  "give the speed in m/s: 0.01 is 1 cm/s, a careful "
                  "palpation; 0.03 m/s is fast.");
    // A motion that moves the probe less than 0.1 mm is no motion: with
    // Speed = 0 (or 1e-300) the run would hold the probe at rest, render
    // 0 N and end with exit 0, as if a motion had been rendered.
    if ((t.type == "straight line" || t.type == "circle" ||
         t.type == "smooth random") &&
        !(t.speed * t.duration >= min_motion_length))
      throw error("Haptics/Trajectory/Speed",
                  "at " + Utilities::to_string(t.speed, 3) + " m/s for " +
                    Utilities::to_string(t.duration, 3) +
                    " s the probe moves " +
                    Utilities::to_string(t.speed * t.duration, 3) +
                    " m: at least " +
                    Utilities::to_string(min_motion_length, 3) +
                    " m (0.1 mm) of motion are needed for the force to "
                    "change",
                  "give the speed in m/s: 0.01 is 1 cm/s, a careful "
                  "palpation.",
                  {"Haptics/Trajectory/Duration"});
    if (t.type == "replay" && t.file_name.empty())
      throw error("Haptics/Trajectory/File name",
                  "Type = replay, but no CSV file is named",
                  "name a CSV file with columns t, x, y, z.");
  }



  void
  Scene::check_shape_output() const
  {
    using namespace Limits;
    const auto &p = parameters;
    if (p.effects.shape_output && p.effects.shape_output_rate <= 0)
      throw error("Effects/Shape output rate",
                  "the rate must be positive",
                  "use 30 Hz.");
    if (p.effects.shape_output &&
        p.effects.shape_output_limit > max_memory_budget)
      throw error("Effects/Shape output limit",
                  "at most " + Utilities::to_string(max_memory_budget, 7) +
                    " MiB (1 TiB): more than any disk palpate writes to, "
                    "and beyond it the byte count overflows (frames were "
                    "left out as if over the limit)",
                  "give the most disk space the frames may take in MiB, "
                  "e.g. 1000.");
    // Below one megabyte not even a dozen frames of a small liver fit:
    // with 0 the run would write no frame and say nothing was wrong.
    if (p.effects.shape_output &&
        !(p.effects.shape_output_limit >= min_shape_output_limit))
      throw error("Effects/Shape output limit",
                  "at least " +
                    Utilities::to_string(min_shape_output_limit, 3) +
                    " MiB: a frame of a 500-node liver is about 85 KiB, so "
                    "a smaller limit writes no frame",
                  "give the most disk space the frames may take in MiB, "
                  "e.g. 1000; to write no frames, set Shape output = false.");
    if (p.effects.shape_output && p.effects.shape_output_rate < 1.0 / 3600)
      throw error("Effects/Shape output rate",
                  "at least one frame an hour (" +
                    Utilities::to_string(1.0 / 3600, 3) +
                    " Hz): a motion lasts at most an hour, so a slower "
                    "rate writes no frame",
                  "use 30 Hz.");
    if (p.effects.shape_output &&
        p.effects.shape_output_rate > max_shape_output_rate)
      throw error("Effects/Shape output rate",
                  "at most " + Utilities::to_string(max_shape_output_rate, 3) +
                    " Hz: each frame is a VTU file of the whole mesh, and a "
                    "screen shows at most 240 frames a second",
                  "use 30 Hz.");
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
                << markdown_escape(describe_pattern(entry.pattern_description))
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
    for (const auto &[name, sub] : declared_tree().subsections)
      print_markdown_section(out, sub, {name});
  }
} // namespace palpate
