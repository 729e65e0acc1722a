// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

#ifndef palpate_scene_scene_h
#define palpate_scene_scene_h

#include <palpate/base/exceptions.h>
#include <palpate/scene/parameters.h>

#include <iosfwd>
#include <map>
#include <string>
#include <vector>

namespace palpate
{
  /**
   * Where a number in a scene could exhaust the machine, the largest value
   * Scene::validate() accepts. Each error message says why.
   */
  namespace Limits
  {
    /** Haptics / Loop rate (Hz): devices run at 1 kHz, the fastest at 10. */
    constexpr double max_loop_rate = 10000;
    /** Motion duration (s): the loop preallocates per-tick statistics. */
    constexpr double max_motion_duration = 3600;
    /** Trajectory speed (m/s): a hand moves at most about 2 m/s. */
    constexpr double max_hip_speed = 10;
    /** Trajectory speed times duration, or a replay's farthest position
     * (m): a shorter motion is none. */
    constexpr double min_motion_length = 1e-4;
    /** A replay recording's length (s): ten ticks of a 1 kHz loop. */
    constexpr double min_replay_duration = 0.01;
    /** Scheduler / Rate (Hz). */
    constexpr double max_scheduler_rate = 1000;
    /** Effects / Shape output rate (Hz): one VTU file per frame. */
    constexpr double max_shape_output_rate = 240;
    /** Effects / Shape output limit (MiB): below, no frame fits. */
    constexpr double min_shape_output_limit = 1;
    /** Elastic moduli (Pa): diamond's Young's modulus is 1.2e12 Pa. */
    constexpr double max_modulus = 1e13;
    /** Moduli (Pa): below this round-off decides the force (fat, the
     * softest tissue, is ~1e2 Pa). */
    constexpr double min_modulus = 1e-3;
    /** Nodes of a generated mesh (beam). */
    constexpr double max_generated_nodes = 1e5;
    /** Active node / Tip radius of a sphere (m): a probe, not a wall. */
    constexpr double max_sphere_radius = 0.1;
    /** A body to palpate is this many metres across, at least and at most
     * (the diagonal of its bounding box; a mesh in the wrong unit is
     * outside). */
    constexpr double min_body_size = 0.002, max_body_size = 2;
    /** An organ is this many metres across, at least and at most: a body
     * within the limits above but outside these is likely in the wrong
     * unit (the scene report warns), and unit advice aims within them. */
    constexpr double min_organ_size = 0.02, max_organ_size = 1;

    /**
     * "the body is S m across (the diagonal of its bounding box); a body to
     * palpate is between 0.002 and 2 m", for a body of @p size (m) outside
     * those limits: every message that refuses a body's size (a scene's
     * mesh, `palpate mesh`'s surface) states one range, from the
     * constants, and a size just past a limit does not read as the limit.
     */
    std::string
    body_size_problem(const double size);
  } // namespace Limits

  /**
   * A scene as read from a `.prm` file: its parameters, plus where each one
   * came from, so that any later check (a missing mesh file, a region that
   * selects no node) can point at the file, the line and the entry.
   */
  class Scene
  {
  public:
    /** A scene with every parameter at its declared default. */
    Scene();

    /**
     * Read, check and parse a scene file. Every problem (unknown
     * subsection or entry, a value that does not match the entry's pattern,
     * unbalanced subsections, a value that is allowed by its pattern but
     * makes no sense, like nu = 0.5) is reported as an InputError naming the
     * file, line, entry and a fix, with a "did you mean" suggestion for
     * misspelled names.
     *
     * @p settings are "ENTRY=VALUE" strings from the command line
     * (`--set 'Material model/Model name=Neo-Hookean'`, the entry's path
     * with '/' between subsections): a variant of the scene without
     * copying it. Each replaces the file's value for its entry (or the
     * default); an unknown entry, a value its pattern refuses or an entry
     * set twice on the command line is an InputError naming the --set.
     */
    static Scene
    read(const std::string              &filename,
         const std::vector<std::string> &settings = {});

    /** The entries the command line set (`--set`), as "ENTRY=VALUE" with
     * the entry's full path, in the order given. */
    const std::vector<std::string> &
    command_line_settings() const
    {
      return command_line_settings_;
    }

    /** The parameters. */
    Parameters::AllParameters parameters;

    /** The scene file as given by the user ("" for the defaults). */
    const std::string &
    file() const
    {
      return file_;
    }

    /**
     * An input file's path written in the scene (a mesh, a surface, a
     * recorded trajectory), resolved. A relative path is looked up, in
     * this order, against the scene file's directory (so a scene runs from
     * anywhere), the current directory, and the directory of the shipped
     * scenes, parameters/ of the palpate source tree (so a scene copied out
     * of parameters/ still finds the example organs its '../meshes/...'
     * names). The first candidate that exists is returned; if none does,
     * the first (the scene file's directory), and where_looked() says
     * where the others were.
     */
    std::string
    resolve_path(const std::string &path) const;

    /**
     * The places resolve_path() looked for @p path, for a message:
     * "'A', 'B' or 'C'".
     */
    std::string
    where_looked(const std::string &path) const;

    /**
     * The line that sets @p entry ("Material model/Model name"), or 0 if
     * the scene file does not set it (the default applies).
     */
    unsigned int
    line_of(const std::string &entry) const;

    /**
     * An InputError about @p entry of this scene: the file and line are
     * filled in, and the entry is shown as "A / B / name = value" when the
     * file sets it, or as "A / B / name (default 'value')" when not. For
     * a relation between entries, @p with names the others: those set by
     * --set are named in the problem.
     */
    InputError
    error(const std::string              &entry,
          const std::string              &problem,
          const std::string              &fix,
          const std::vector<std::string> &with = {}) const;

    /** Check relations between parameters that no single pattern can. */
    void
    validate() const;

    /**
     * The degree of the displacements: the one the material's element
     * pair fixes (Taylor-Hood: 2, P1-P1: 1), else Discretization /
     * Polynomial degree. It sizes the problem and makes the edge
     * midpoints contact nodes (Polynomial degree alone said 1 for a
     * Taylor-Hood scene, and the sphere's check measured P1 edges).
     */
    unsigned int
    displacement_degree() const;

    /** Whether the scene file or the command line (--set) sets @p entry
     * ("Mesh/File name"), rather than leaving its default. */
    bool
    sets(const std::string &entry) const;

  private:
    /** validate(): the material plug-in's constants, their bounds, and the
     * element pair's degree. */
    void
    check_material() const;

    /** validate(): each enabled effect plug-in's entries. */
    void
    check_effects() const;
    /** The own entries of the chosen mesh source, fixed region, probe tip,
     * interpolation, device, trajectory and linear solver plug-ins
     * (Plugins::check_entries). */
    void
    check_plugin_entries() const;

    /** validate(): the probe tip's entries, its radius and what it needs
     * of the scene (Plugins::check_scene()). */
    void
    check_probe() const;

    /** validate(): what the interpolation needs of the scene (a contact
     * patch: a sphere to render; Plugins::check_scene()). */
    void
    check_interpolation() const;

    /** validate(): the mesh source's entries (Plugins::check_scene()), and
     * the scale. */
    void
    check_mesh() const;

    /** validate(): the fixed-node region's entries
     * (Plugins::check_scene()). */
    void
    check_fixed_nodes() const;

    /** validate(): the Newton solver's tolerances and staging. */
    void
    check_solver_tolerances() const;

    /** validate(): the state grid, the cloud, the scheduler and the engine. */
    void
    check_state_space() const;

    /** validate(): the Newton solver's loop counts, and the engine's
     * memory budget. */
    void
    check_newton_counts() const;

    /** validate(): the haptic loop and the trajectory. */
    void
    check_haptics() const;

    /** validate(): the shape interpolator's frames (rate and disk limit). */
    void
    check_shape_output() const;

    /** A scene whose parameters are not parsed yet (for read()). */
    struct Unparsed
    {};
    explicit Scene(Unparsed)
    {}

    std::string                         file_;
    std::string                         directory_;
    std::map<std::string, unsigned int> entry_lines_;
    std::map<std::string, std::string>  entry_values_;
    std::vector<std::string>            command_line_settings_;
  };

  /** Output formats for print_parameters(). */
  enum class ParameterFormat
  {
    /** A complete `.prm` file with every entry at its default, documented. */
    prm,
    /** The Markdown reference in doc/parameters.md. */
    markdown
  };

  /** Print every declared parameter with its default and documentation. */
  void
  print_parameters(std::ostream &out, const ParameterFormat format);
} // namespace palpate

#endif
