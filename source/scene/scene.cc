// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

#include <palpate/scene/scene.h>

#include <deal.II/base/parameter_handler.h>
#include <deal.II/base/patterns.h>

#include <boost/property_tree/ptree.hpp>
#include <boost/property_tree/xml_parser.hpp>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <regex>
#include <sstream>

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
      if (std::regex_search(description,
                            std::regex(
                              R"(^\[List of <\[Double.*of length 3\.\.\.3)")))
        return "three numbers separated by commas (x, y, z)";
      if (std::regex_search(description,
                            std::regex(R"(^\[List of <\[Integer)")))
        return "whole numbers separated by commas";
      return description;
    }

    /** Whether @p value matches the declared pattern @p description. */
    bool
    matches(const std::string &description, const std::string &value)
    {
      const auto pattern = dealii::Patterns::pattern_factory(description);
      return pattern != nullptr && pattern->match(value);
    }

    /**
     * One logical line of a .prm file: comments removed, continuation lines
     * joined, with the number of the line it starts on.
     */
    struct LogicalLine
    {
      unsigned int number;
      std::string  text;
    };

    std::vector<LogicalLine>
    read_logical_lines(std::istream &in)
    {
      std::vector<LogicalLine> lines;
      std::string              raw;
      unsigned int             number = 0;
      std::string              pending;
      unsigned int             pending_start = 0;
      while (std::getline(in, raw))
        {
          ++number;
          if (!raw.empty() && raw.back() == '\r')
            raw.pop_back();
          // Strip a comment: '#' not preceded by a backslash.
          std::string stripped;
          for (unsigned int i = 0; i < raw.size(); ++i)
            {
              if (raw[i] == '#' && (i == 0 || raw[i - 1] != '\\'))
                break;
              stripped += raw[i];
            }
          if (pending.empty())
            pending_start = number;
          const std::string t = Utilities::trim(stripped);
          if (!t.empty() && t.back() == '\\')
            {
              pending += t.substr(0, t.size() - 1) + " ";
              continue;
            }
          pending += stripped;
          if (!Utilities::trim(pending).empty())
            lines.push_back({pending_start, Utilities::trim(pending)});
          pending.clear();
        }
      if (!Utilities::trim(pending).empty())
        lines.push_back({pending_start, Utilities::trim(pending)});
      return lines;
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

    std::string
    entry_key(const std::vector<std::string> &path, const std::string &name)
    {
      std::string key;
      for (const auto &p : path)
        key += p + "/";
      return key + name;
    }
  } // namespace



  Scene::Scene()
  {
    dealii::ParameterHandler prm;
    Parameters::AllParameters::declare_parameters(prm);
    parameters.parse_parameters(prm);
  }



  Scene
  Scene::read(const std::string &filename)
  {
    Scene scene;
    scene.file_      = filename;
    scene.directory_ = std::filesystem::path(filename).parent_path().string();

    std::ifstream in(filename);
    if (!in)
      throw InputError(filename,
                       0,
                       "(the scene file itself)",
                       "the file cannot be opened: " +
                         std::string(std::filesystem::exists(filename) ?
                                       "it is not readable" :
                                       "it does not exist"),
                       "check the path; shipped scenes are in parameters/, "
                       "e.g. 'palpate parameters/default.prm'.");

    // First pass: check every line against the declared parameters, so
    // that errors can name the line, the entry and a likely fix.
    const DeclaredSection               &root = declared_tree();
    std::vector<const DeclaredSection *> stack{&root};
    std::vector<std::string>             path;
    std::vector<unsigned int>            opened_at;
    for (const LogicalLine &line : read_logical_lines(in))
      {
        std::string rest;
        if (starts_with_keyword(line.text, "subsection", rest))
          {
            const DeclaredSection *sub = stack.back()->find_subsection(rest);
            if (sub == nullptr)
              throw InputError(
                filename,
                line.number,
                "subsection " + rest + " (in " + path_to_string(path) + ")",
                "there is no subsection '" + rest + "' here",
                suggestion(rest, stack.back()->subsection_names()) +
                  "The subsections here are: " +
                  join(stack.back()->subsection_names(), ", ") +
                  ". 'palpate --print-parameters' lists everything.");
            stack.push_back(sub);
            path.push_back(rest);
            opened_at.push_back(line.number);
          }
        else if (starts_with_keyword(line.text, "end", rest) && rest.empty())
          {
            if (path.empty())
              throw InputError(filename,
                               line.number,
                               "end",
                               "'end' without a matching 'subsection'",
                               "remove this line, or add the 'subsection' it "
                               "is meant to close.");
            stack.pop_back();
            path.pop_back();
            opened_at.pop_back();
          }
        else if (starts_with_keyword(line.text, "set", rest))
          {
            const auto equal = rest.find('=');
            if (equal == std::string::npos)
              throw InputError(filename,
                               line.number,
                               line.text,
                               "a 'set' line needs the form 'set Name = value'",
                               "add ' = value' after the entry name.");
            const std::string name  = Utilities::trim(rest.substr(0, equal));
            const std::string value = Utilities::trim(rest.substr(equal + 1));
            const DeclaredEntry *entry = stack.back()->find_entry(name);
            if (entry == nullptr)
              throw InputError(filename,
                               line.number,
                               path_to_string(path) + " / " + name,
                               "there is no entry '" + name + "' in " +
                                 path_to_string(path),
                               suggestion(name, stack.back()->entry_names()) +
                                 "The entries here are: " +
                                 join(stack.back()->entry_names(), ", ") + ".");
            if (!matches(entry->pattern_description, value))
              {
                std::string hint;
                std::smatch m;
                if (std::regex_match(entry->pattern_description,
                                     m,
                                     std::regex(R"(\[Selection (.*) \])")))
                  hint = suggestion(value, Utilities::split(m[1].str(), '|'));
                throw InputError(filename,
                                 line.number,
                                 path_to_string(path) + " / " + name + " = " +
                                   value,
                                 "'" + value +
                                   "' is not allowed here: the "
                                   "entry takes " +
                                   describe_pattern(entry->pattern_description),
                                 hint + "Set " + name +
                                   " to such a value (its default is '" +
                                   entry->default_value + "').");
              }
            scene.entry_lines_[entry_key(path, name)]  = line.number;
            scene.entry_values_[entry_key(path, name)] = value;
          }
        else if (starts_with_keyword(line.text, "include", rest))
          throw InputError(filename,
                           line.number,
                           line.text,
                           "scene files cannot include other files",
                           "copy the entries you need into this file.");
        else
          throw InputError(filename,
                           line.number,
                           line.text,
                           "this line is not 'subsection Name', 'end' or "
                           "'set Name = value'",
                           "fix the line or comment it out with '#'.");
      }
    if (!path.empty())
      throw InputError(filename,
                       opened_at.back(),
                       "subsection " + path.back(),
                       "the subsection opened here is never closed",
                       "add a line 'end' after its last entry.");

    // Second pass: the file is well-formed, let deal.II read the values.
    dealii::ParameterHandler prm;
    Parameters::AllParameters::declare_parameters(prm);
    try
      {
        std::ifstream values(filename);
        prm.parse_input(values, filename, "", false);
      }
    catch (const std::exception &e)
      {
        throw InputError(filename,
                         0,
                         "(whole file)",
                         std::string("deal.II's ParameterHandler rejected "
                                     "the file: ") +
                           e.what(),
                         "fix the entry the message names.");
      }
    scene.parameters.parse_parameters(prm);
    scene.validate();
    return scene;
  }



  std::string
  Scene::resolve_path(const std::string &path) const
  {
    if (path.empty() || std::filesystem::path(path).is_absolute() ||
        directory_.empty())
      return path;
    return (std::filesystem::path(directory_) / path)
      .lexically_normal()
      .string();
  }



  unsigned int
  Scene::line_of(const std::string &entry) const
  {
    const auto it = entry_lines_.find(entry);
    return it == entry_lines_.end() ? 0 : it->second;
  }



  InputError
  Scene::error(const std::string &entry,
               const std::string &problem,
               const std::string &fix) const
  {
    std::string shown = std::regex_replace(entry, std::regex("/"), " / ");
    const auto  value = entry_values_.find(entry);
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



  void
  Scene::validate() const
  {
    const auto &p = parameters;

    // Material: the moduli of the model in use must describe a solid.
    const auto &m = p.material_model;
    if (m.model_name == "St.Venant-Kirchhoff" && m.stvk_poissons_ratio >= 0.5)
      throw error("Material model/St.Venant-Kirchhoff/Poisson's ratio",
                  "nu = 0.5 makes the Lame parameter lambda infinite",
                  "use nu < 0.5 (e.g. 0.49, the paper's value), or the "
                  "incompressible Mooney-Rivlin model.");
    if (m.model_name == "Neo-Hookean" && m.nh_poissons_ratio >= 0.5)
      throw error("Material model/Neo-Hookean/Poisson's ratio",
                  "nu = 0.5 makes the Lame parameter lambda infinite",
                  "use nu < 0.5, or the incompressible Mooney-Rivlin model.");
    if ((m.model_name == "St.Venant-Kirchhoff" &&
         m.stvk_poissons_ratio <= -1) ||
        (m.model_name == "Neo-Hookean" && m.nh_poissons_ratio <= -1))
      throw error(m.model_name == "Neo-Hookean" ?
                    "Material model/Neo-Hookean/Poisson's ratio" :
                    "Material model/St.Venant-Kirchhoff/Poisson's ratio",
                  "nu = -1 makes the shear modulus E/(2(1+nu)) infinite",
                  "use -1 < nu < 0.5; soft tissue has nu close to 0.5.");
    if (m.model_name == "St.Venant-Kirchhoff" && m.stvk_youngs_modulus <= 0)
      throw error("Material model/St.Venant-Kirchhoff/Young's modulus",
                  "Young's modulus must be positive",
                  "set it in Pa, e.g. 15465 for liver.");
    if (m.model_name == "Neo-Hookean" && m.nh_youngs_modulus <= 0)
      throw error("Material model/Neo-Hookean/Young's modulus",
                  "Young's modulus must be positive",
                  "set it in Pa, e.g. 15465 for liver.");
    if (m.model_name == "Mooney-Rivlin" && m.mr_c10 + m.mr_c01 <= 0)
      throw error("Material model/Mooney-Rivlin/C10",
                  "the shear modulus 2 (C10 + C01) must be positive",
                  "set C10 (and C01) in Pa; for Young's modulus E of an "
                  "incompressible solid, C10 + C01 = E/6.");

    // Mooney-Rivlin: the element pair fixes the displacement degree.
    if (m.model_name == "Mooney-Rivlin" &&
        line_of("Discretization/Polynomial degree") > 0)
      {
        const unsigned int pair_degree = m.mr_element == "Taylor-Hood" ? 2 : 1;
        if (p.discretization.polynomial_degree != pair_degree)
          throw error(
            "Discretization/Polynomial degree",
            "Mooney-Rivlin's element pair " + m.mr_element +
              " has displacements of degree " + std::to_string(pair_degree),
            "remove this entry (Material model / Mooney-Rivlin / Element chooses the "
            "degree), or choose the element pair with the degree you want.");
      }
    if (m.model_name == "Mooney-Rivlin" &&
        m.mr_incompressibility == "penalty" && m.mr_bulk_modulus <= 0)
      throw error(
        "Material model/Mooney-Rivlin/Bulk modulus",
        "the bulk modulus must be positive",
        "set it in Pa, typically 1000 times C10 + C01 for soft tissue.");

    // Mesh.
    if (p.mesh.source == "file" && p.mesh.file_name.empty())
      throw error("Mesh/File name",
                  "Source = file, but no mesh file is named",
                  "set File name to a .msh, .vtk or .vtu file, or choose "
                  "Source = beam or blob.");
    if (p.mesh.scale_factor <= 0)
      throw error("Mesh/Scale factor",
                  "the scale factor must be positive",
                  "set it to the number of metres per mesh-file unit, e.g. "
                  "0.001 for a mesh in millimetres.");

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
        Utilities::norm(f.half_space_normal) == 0)
      throw error("Boundary conditions/Fixed nodes/Half-space normal",
                  "the normal is the zero vector",
                  "give the direction pointing into the fixed half-space, "
                  "e.g. 0, 0, -1.");
    if (f.selection == "node list" && f.node_ids.empty())
      throw error("Boundary conditions/Fixed nodes/Node ids",
                  "Selection = node list, but the list is empty",
                  "list the node numbers to fix, separated by commas.");

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
                  "paper's largest displacement).");
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
                    "0.005 m gives 41^3 = 68921 points).");
    }
    if (p.scheduler.cloud_radius < std::sqrt(3.) * p.state_space.grid_spacing)
      throw error(
        "Scheduler/Cloud radius",
        "the cloud cannot hold all 8 corners of the cell the HIP "
        "is in: it must reach at least sqrt(3) h = " +
          Utilities::to_string(std::sqrt(3.) * p.state_space.grid_spacing, 4) +
          " m",
        "increase Cloud radius or decrease State space / Grid "
        "spacing.");
    if (p.scheduler.rate <= 0)
      throw error("Scheduler/Rate", "the rate must be positive", "use 100 Hz.");

    // Haptics.
    const auto &h = p.haptics;
    if (h.loop_rate <= 0)
      throw error("Haptics/Loop rate",
                  "the rate must be positive",
                  "use 1000 Hz.");
    if (h.force_limit <= 0)
      throw error("Haptics/Force limit",
                  "the force limit must be positive",
                  "set the device's peak force in N, e.g. 8.");
    if (h.max_force_change <= 0)
      throw error("Haptics/Maximum force change",
                  "the force change per tick must be positive",
                  "use e.g. 0.05 N.");
    const auto &t = h.trajectory;
    if ((t.type == "straight line" || t.type == "circle") &&
        Utilities::norm(t.direction) == 0)
      throw error("Haptics/Trajectory/Direction",
                  "the direction is the zero vector",
                  "give a direction, e.g. 0, 0, -1.");
    if (t.type == "replay" && t.file_name.empty())
      throw error("Haptics/Trajectory/File name",
                  "Type = replay, but no CSV file is named",
                  "name a CSV file with columns t, x, y, z.");
    if (p.effects.shape_output && p.effects.shape_output_rate <= 0)
      throw error("Effects/Shape output rate",
                  "the rate must be positive",
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
        out << "# Every scene parameter of palpate, at its default value.\n"
            << "# Generated by 'palpate --print-parameters'.\n";
        prm.print_parameters(out,
                             dealii::ParameterHandler::PRM |
                               dealii::ParameterHandler::KeepDeclarationOrder);
        return;
      }

    out << "# Scene parameters\n\n"
        << "Every entry a scene file (`.prm`) can set, with its default, the "
           "values it accepts and its meaning (units in brackets or in the "
           "text). A scene that sets nothing gets these defaults: the "
           "built-in organ-like blob, St.Venant-Kirchhoff, no effects.\n\n"
        << "This page is generated by `palpate --print-parameters markdown "
           "> doc/parameters.md`; the test `scene/parameter_reference` fails "
           "when it is out of date.\n";
    for (const auto &[name, sub] : declared_tree().subsections)
      print_markdown_section(out, sub, {name});
  }
} // namespace palpate
