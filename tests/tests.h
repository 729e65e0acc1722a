// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

// palpate's test header (Debian's deal.II does not install deal.II's own
// tests.h). Tests write their results with deallog after initlog(); the
// deal.II harness compares the file "output" with the test's .output file
// using numdiff.

#ifndef palpate_tests_h
#define palpate_tests_h

#include <palpate/base/environment.h>
#include <palpate/hyperelastic/hyperelastic_system.h>
#include <palpate/hyperelastic/linear_solver.h>
#include <palpate/hyperelastic/state_solver.h>
#include <palpate/mesh/mesh.h>
#include <palpate/mesh/node_selection.h>
#include <palpate/scene/scene.h>

#include <deal.II/base/logstream.h>

#include <sys/wait.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "wait.h"

using dealii::deallog;

/** The project's source tree, its example organs (meshes/, README there)
 * and the palpate program. */
static const std::string palpate_source_dir = PALPATE_SOURCE_DIR;
static const std::string palpate_meshes_dir = PALPATE_SOURCE_DIR "/meshes";
static const std::string palpate_executable = PALPATE_EXECUTABLE;

/** A check's outcome as the .output files print it: "yes", or "NO" (which
 * stands out in a diff). */
inline const char *
ok(const bool passed)
{
  return passed ? "yes" : "NO";
}

/** Send deallog to the file "output", with @p precision digits. */
inline void
initlog(const unsigned int precision = 6)
{
  static std::ofstream logfile("output");
  deallog.attach(logfile, false);
  deallog.depth_console(0);
  deallog << std::setprecision(precision);
  logfile << std::setprecision(precision);
}

/** The scenes palpate ships (parameters/*.prm), sorted: found on disk, so
 * that a newly shipped scene is tested too. */
inline std::vector<std::filesystem::path>
shipped_scenes()
{
  std::vector<std::filesystem::path> scenes;
  for (const auto &f :
       std::filesystem::directory_iterator(palpate_source_dir + "/parameters"))
    if (f.path().extension() == ".prm")
      scenes.push_back(f.path());
  std::sort(scenes.begin(), scenes.end());
  return scenes;
}

/** What running the palpate program produced. */
struct ProgramRun
{
  int         exit_status;
  std::string output; // stdout and stderr, interleaved
};

/** Run `palpate ARGS` in the current directory and capture everything. */
inline ProgramRun
run_palpate(const std::string &arguments)
{
  const std::string command = palpate_executable + " " + arguments + " 2>&1";
  FILE             *pipe    = popen(command.c_str(), "r");
  ProgramRun        run{-1, ""};
  if (pipe == nullptr)
    return run;
  std::array<char, 4096> buffer;
  std::size_t            n;
  while ((n = fread(buffer.data(), 1, buffer.size(), pipe)) > 0)
    run.output.append(buffer.data(), n);
  const int status = pclose(pipe);
  run.exit_status  = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return run;
}

/** A scene with its mesh and its fixed and active nodes. */
struct Body
{
  explicit Body(const palpate::Scene &s)
    : scene(s)
    , mesh(palpate::Mesh::create(scene))
    , nodes(palpate::NodeSelection::create(scene, mesh))
  {}

  palpate::Scene         scene;
  palpate::Mesh          mesh;
  palpate::NodeSelection nodes;
};

/**
 * The probe's force (N) with the active node held at rest, and the sum of
 * every nodal reaction (fixed nodes and probe, N): zero unless a load acts.
 */
inline std::pair<palpate::Utilities::Point3, palpate::Utilities::Point3>
force_and_reactions_at_rest(const palpate::Scene &scene)
{
  const palpate::Mesh          mesh = palpate::Mesh::create(scene);
  const palpate::NodeSelection nodes =
    palpate::NodeSelection::create(scene, mesh);
  palpate::StateSolver solver(mesh, nodes, scene.parameters);
  const palpate::State s = solver.solve(solver.rest_state(), {{0, 0, 0}});
  AssertThrow(s.converged, dealii::ExcInternalError());
  const auto                 r = solver.system().nodal_residual(s.solution);
  const auto                &component = solver.system().dof_components();
  palpate::Utilities::Point3 sum{{0, 0, 0}};
  for (std::size_t d = 0; d < r.size(); ++d)
    if (component[d] < 3)
      sum[component[d]] += r[d];
  return {s.force, sum};
}

/**
 * The force an interaction renders at @p x once its rate limiter has
 * settled (Haptics / Maximum force change): force(x) called until two
 * calls agree to 1e-13 of the force (a zero force: exactly), at most
 * @p calls times. Not exactly: with contact patches each call takes one
 * more step of the sphere's contact problem from the last call's solution,
 * and once converged (a dozen calls) the force jitters at round-off
 * (1e-17 N) and two calls never agree exactly. A template, so that
 * tests.h needs no haptics header.
 */
template <typename Interaction>
palpate::Utilities::Point3
settled_force(Interaction                      &interaction,
              const palpate::Utilities::Point3 &x,
              const unsigned int                calls = 100000)
{
  palpate::Utilities::Point3 f = interaction.force(x);
  for (unsigned int i = 0; i < calls; ++i)
    {
      const palpate::Utilities::Point3 g = interaction.force(x);
      if (palpate::Utilities::distance(f, g) <=
          1e-13 * palpate::Utilities::norm(g))
        return g;
      f = g;
    }
  return f;
}

/** A shipped scene from parameters/, e.g. "liver-stvk.prm". */
inline palpate::Scene
shipped_scene(const std::string &name)
{
  return palpate::Scene::read(palpate_source_dir + "/parameters/" + name);
}

/**
 * The shipped beam with a small state space, for tests of the engine and
 * the interaction: a 2 mm grid of +-6 mm, a 4.5 mm cloud (57 points around
 * the rest position), 2 solver threads.
 */
inline palpate::Scene
small_beam_scene()
{
  palpate::Scene scene       = shipped_scene("beam.prm");
  auto          &p           = scene.parameters;
  p.state_space.grid_spacing = 0.002;
  p.state_space.extent       = 0.006;
  p.scheduler.cloud_radius   = 0.0045;
  p.engine.workers           = 2;
  return scene;
}

/**
 * The indenter tests' set-up: the beam scene @p scene lying clamped on its
 * bottom face (boundary id 4), touched in the middle of its top face by a
 * sphere of radius @p radius (Tip = sphere).
 */
inline void
touch_beam_with_sphere(palpate::Scene &scene, const double radius)
{
  auto &p                                        = scene.parameters;
  p.boundary_conditions.fixed_nodes.boundary_ids = {4};
  p.boundary_conditions.active_node.point        = {{0.05, 0, 0.01}};
  p.boundary_conditions.active_node.tip          = "sphere";
  p.boundary_conditions.active_node.tip_radius   = radius;
}

/**
 * The contact-patch tests' beam: @p scene (touched by a sphere) meshed with
 * 2.5 mm elements, so that a 1 cm sphere touches several nodes and its force
 * is the tissue's rather than one node's; Neo-Hookean, because
 * St.Venant-Kirchhoff softens under the compression a sphere makes and
 * inverts these elements 2.5 mm deep; State space / Interpolation = contact
 * patch with the condensed contact solver.
 */
inline void
beam_with_contact_patches(palpate::Scene &scene)
{
  auto &p                              = scene.parameters;
  p.mesh.beam_subdivisions_length      = 40;
  p.mesh.beam_subdivisions_width       = 8;
  p.mesh.beam_subdivisions_height      = 8;
  p.material_model.model_name          = "Neo-Hookean";
  p.state_space.interpolation          = "contact patch";
  p.nonlinear_solver.condensed_contact = true;
}

/** Every linear solver registered (LinearSolverRegistry, in name order)
 * with the METIS ordering, and MUMPS with AMD too, for the solver tests. */
inline std::vector<std::pair<std::string, std::string>>
every_linear_solver()
{
  std::vector<std::pair<std::string, std::string>> solvers;
  for (const auto &plugin : palpate::LinearSolverRegistry::plugins())
    {
      solvers.emplace_back(plugin.name, "METIS");
      if (plugin.name == "MUMPS")
        solvers.emplace_back(plugin.name, "AMD");
    }
  return solvers;
}

/** Whether every component of @p f is finite. */
inline bool
all_finite(const std::array<double, 3> &f)
{
  return std::isfinite(f[0]) && std::isfinite(f[1]) && std::isfinite(f[2]);
}

/** The whole text of the file @p name ("" if it cannot be read). */
inline std::string
read_file(const std::string &name)
{
  std::ifstream     in(name);
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

/** Write @p text to the file @p name. */
inline void
write_file(const std::string &name, const std::string &text)
{
  std::ofstream(name) << text;
}

/** The rows of numbers of the CSV file @p name after its header line (a
 * force log: t, x, y, z, fx, fy, fz). */
inline std::vector<std::vector<double>>
read_csv_rows(const std::string &name)
{
  std::vector<std::vector<double>> rows;
  std::ifstream                    in(name);
  std::string                      line;
  std::getline(in, line); // the header
  while (std::getline(in, line))
    {
      std::istringstream  fields(line);
      std::string         field;
      std::vector<double> values;
      while (std::getline(fields, field, ','))
        values.push_back(std::stod(field));
      rows.push_back(values);
    }
  return rows;
}

/**
 * The shipped beam set up for a short interaction with a force log (a
 * 2 mm grid of +-1 cm, a 4 mm initial cloud), followed by @p more (the
 * subsections a test adds: its device, trajectory, output directory).
 */
inline std::string
beam_interaction(const std::string &more)
{
  return read_file(palpate_source_dir + "/parameters/beam.prm") + R"(
subsection Effects
  set Force log = true
end
subsection State space
  set Grid spacing = 0.002
  set Extent       = 0.01
end
subsection Scheduler
  set Cloud radius = 0.004
end
)" + more;
}

/** The seven-point Laplacian plus 0.1 I on an m^3 grid, full pattern: a
 * symmetric positive definite test matrix for the linear solvers. */
struct Laplacian
{
  palpate::SparsityCSR pattern;
  std::vector<double>  values;

  explicit Laplacian(const unsigned int m)
  {
    pattern.n_rows = m * m * m;
    pattern.row_start.push_back(0);
    for (unsigned int z = 0; z < m; ++z)
      for (unsigned int y = 0; y < m; ++y)
        for (unsigned int x = 0; x < m; ++x)
          {
            const unsigned int i = (z * m + y) * m + x;
            // Sorted columns: -m^2, -m, -1, 0, +1, +m, +m^2.
            const auto add = [&](const unsigned int j, const double a) {
              pattern.column.push_back(j);
              values.push_back(a);
            };
            if (z > 0)
              add(i - m * m, -1);
            if (y > 0)
              add(i - m, -1);
            if (x > 0)
              add(i - 1, -1);
            add(i, 6.1);
            if (x + 1 < m)
              add(i + 1, -1);
            if (y + 1 < m)
              add(i + m, -1);
            if (z + 1 < m)
              add(i + m * m, -1);
            pattern.row_start.push_back(pattern.column.size());
          }
  }
};

#endif
