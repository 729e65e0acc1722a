// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

#ifndef palpate_scene_scene_impl_h
#define palpate_scene_scene_impl_h

// Not an interface: reading and checking a scene (Scene, print_parameters()),
// shared by its source files, one job each:
//   scene.cc                  the Scene's own members: Scene::read() in
//                             order, where input files are looked for, the
//                             errors that point at an entry, validate()
//   scene_file.cc             the file as text, before deal.II reads it:
//                             what is refused, its lines and statements
//   scene_reader.cc           deal.II's ParameterHandler reading it: the
//                             line of each entry, rejections explained,
//                             entries set twice, the conversion
//   scene_settings.cc         the command line's --set: checked, applied
//   scene_checks_material.cc  the material and the plug-ins' entries, and
//                             the displacement degree the material fixes
//   scene_checks_mesh.cc      the mesh, the fixed nodes and the probe
//   scene_checks_solver.cc    the Newton solver, the state space, the
//                             scheduler and the engine
//   scene_checks_haptics.cc   the haptic loop, the trajectory and the
//                             shape frames
//   parameter_reference.cc    the declared parameters in words, and the
//                             reference print_parameters() prints
// Users of the scene include scene.h, never this header.

#include <palpate/scene/scene.h>

#include <deal.II/base/parameter_handler.h>

#include <functional>
#include <map>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

namespace palpate
{
  // The bounds the checks (scene_checks_*.cc) hold numbers to, beside
  // those scene.h names.
  namespace Limits
  {
    // Bounds on the numbers that set a loop count, an allocation or a
    // time (issue 26): without them a typo hangs a run or overflows.
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



  namespace internal
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

    /** The declared parameter tree, in declaration order
     * (parameter_reference.cc). */
    const DeclaredSection &
    declared_tree();

    /** @p pieces with @p separator between them. */
    std::string
    join(const std::vector<std::string> &pieces, const std::string &separator);

    /** A subsection path as "A / B", or "(top level)". */
    std::string
    path_to_string(const std::vector<std::string> &path);

    /** "did you mean '...'? " for the name in @p names closest to @p word,
     * or "". */
    std::string
    suggestion(const std::string &word, const std::vector<std::string> &names);

    /** What a pattern description means, in words a user understands. */
    std::string
    describe_pattern(const std::string &description);

    /** An entry's key: its path and name, "Section/Entry". */
    std::string
    entry_key(const std::vector<std::string> &path, const std::string &name);

    /** The physical lines of a scene file, without line ends
     * (scene_file.cc). */
    std::vector<std::string>
    split_lines(const std::string &content);

    /** Whether @p line begins with @p keyword (lower case, any case in the
     * line) as a word; @p rest is what follows it, trimmed. */
    bool
    starts_with_keyword(const std::string &line,
                        const std::string &keyword,
                        std::string       &rest);

    /** The statement that ends on line @p last (1-based): its first line
     * and its text, continuation lines joined. */
    std::pair<unsigned int, std::string>
    statement_at(const std::vector<std::string> &lines,
                 const unsigned int              last);

    /** The subsection path in force before line @p line (1-based), and
     * where each of its subsections was opened. */
    std::vector<std::string>
    path_before(const std::vector<std::string> &lines,
                const unsigned int              line,
                std::vector<unsigned int>      *opened_at = nullptr);

    /** Refuse a name that is not a scene file before opening it. */
    void
    check_is_regular_file(const std::string &filename);

    /** The scene file's bytes, or an error that says why not. */
    std::string
    read_scene_bytes(const std::string &filename);

    /** Drop a UTF-8 byte order mark from @p content; refuse UTF-16 text. */
    void
    strip_byte_order_mark(std::string &content, const std::string &filename);

    /** Refuse NUL bytes and control characters. */
    void
    check_plain_text(const std::string &content, const std::string &filename);

    /** Refuse the first 'include' line: a scene is one file. */
    void
    check_no_includes(const std::vector<std::string> &lines,
                      const std::string              &filename);

    /** A `--set ENTRY=VALUE` from the command line, checked against the
     * declared parameters. */
    struct CommandLineSetting
    {
      std::vector<std::string> path; // subsections
      std::string              name, value;
    };

    /** Check the command line's `--set ENTRY=VALUE` strings
     * (scene_settings.cc). */
    std::vector<CommandLineSetting>
    parse_command_line_settings(const std::vector<std::string> &settings);

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

    /** Keep each entry's value and line; refuse an entry the file sets
     * twice (scene_reader.cc). */
    void
    keep_entry_lines_and_values(const std::vector<Setting>          &settings,
                                const std::string                   &filename,
                                std::map<std::string, unsigned int> &lines,
                                std::map<std::string, std::string>  &values);

    /** Convert the values read into @p parameters. */
    void
    convert_parameters(Parameters::AllParameters  &parameters,
                       dealii::ParameterHandler   &prm,
                       const std::vector<Setting> &settings,
                       const std::string          &filename);
  } // namespace internal
} // namespace palpate

#endif
