// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

// deal.II's ParameterHandler reading a scene file (RecordingReader): an
// action on every declared entry records the line that sets it; a line the
// handler rejects is explained by its line, its entry and a likely fix; an
// entry the file sets twice is refused; and the values read are converted
// into the parameters, naming the entry whose number is out of range.

#include <palpate/scene/scene_impl.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdlib>

namespace palpate
{
  namespace internal
  {
    namespace
    {
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

      /**
       * Attach to every declared entry below @p section an action that
       * passes the entry's key ("Section/Entry") and value to @p record.
       */
      void
      record_every_entry(dealii::ParameterHandler &prm,
                         const DeclaredSection    &section,
                         std::vector<std::string> &path,
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
          return InputError(
            filename,
            line,
            "subsection " + rest +
              (path.empty() ? std::string(" (at the top level)") :
                              " (in " + path_to_string(path) + ")"),
            "there is no subsection '" + rest + "' here",
            suggestion(rest, here->subsection_names()) +
              "The subsections here are: " +
              join(here->subsection_names(), ", ") +
              ". 'palpate --print-parameters' lists everything.");
        if (here != nullptr && starts_with_keyword(text, "set", rest))
          {
            const auto equal = rest.find('=');
            if (equal == std::string::npos)
              return InputError(
                filename,
                line,
                text,
                "a 'set' line needs the form 'set Name = value'",
                "add ' = value' after the entry name.");
            const std::string name  = Utilities::trim(rest.substr(0, equal));
            const std::string value = Utilities::trim(rest.substr(equal + 1));
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
                  hint = suggestion(
                    value,
                    Utilities::split(d.substr(selection.size(),
                                              d.size() - selection.size() - 2),
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
    } // namespace



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
  } // namespace internal
} // namespace palpate
