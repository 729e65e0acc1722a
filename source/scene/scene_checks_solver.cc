// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

// The checks of how a scene's states are computed (Scene::validate()): the
// Newton solver's tolerances, staging and loop counts and the material's
// density, the state grid and its interpolation, the scheduler's cloud, rate
// and look-ahead, and the engine's workers, assembly threads and memory
// budget.

#include <palpate/scene/scene_impl.h>

#include <algorithm>
#include <cmath>
#include <thread>

namespace palpate
{
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



  namespace
  {
    // Scene::check_state_space(), a step: the scheduler's cloud, rate and
    // look-ahead, the entries that decide which states are planned when.
    void
    check_scheduler(const Scene &scene)
    {
      using namespace Limits;
      const auto &p = scene.parameters;
      if (p.scheduler.cloud_radius < std::sqrt(3.) * p.state_space.grid_spacing)
        throw scene.error(
          "Scheduler/Cloud radius",
          "the cloud cannot hold all 8 corners of the cell the HIP "
          "is in: it must reach at least sqrt(3) h = " +
            Utilities::to_string(std::sqrt(3.) * p.state_space.grid_spacing,
                                 4) +
            " m",
          "increase Cloud radius or decrease State space / Grid "
          "spacing.",
          {"State space/Grid spacing"});
      if (!(p.scheduler.rate >= min_scheduler_rate))
        throw scene.error(
          "Scheduler/Rate",
          "at least " + Utilities::to_string(min_scheduler_rate, 3) +
            " Hz: the scheduler re-plans the cloud around the moving "
            "HIP on each cycle; slower, the states the hand needs are "
            "planned seconds late and the force fades",
          "use 100 Hz (the paper's rate).");
      if (p.scheduler.cloud_radius > p.state_space.extent)
        throw scene.error(
          "Scheduler/Cloud radius",
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
        throw scene.error(
          "Scheduler/Look-ahead time",
          "at most 2 s: the cloud is centred where the HIP would be "
          "after this time at its current velocity, and a hand keeps "
          "its velocity for a fraction of a second; farther ahead "
          "the cloud leaves the HIP and the force fades",
          "use 0.2 s (the default), or 0 for the paper's cloud "
          "around the HIP.");
      if (p.scheduler.rate > max_scheduler_rate)
        throw scene.error(
          "Scheduler/Rate",
          "at most " + Utilities::to_string(max_scheduler_rate, 4) +
            " Hz: the scheduler re-plans the cloud on each cycle, and "
            "faster cycles only take time from the solvers",
          "use 100 Hz (the paper's rate).");
    }



    // Scene::check_state_space(), a step: the threads a run asks for against
    // this machine's cores, the one check that depends on the machine.
    void
    check_cores(const Scene &scene)
    {
      const auto        &p = scene.parameters;
      const unsigned int cores =
        std::max(2u, std::thread::hardware_concurrency());
      if (p.engine.type == "threads" && p.engine.workers > cores)
        throw scene.error(
          "Engine/Workers",
          "at most " + std::to_string(cores) +
            " on this machine, its number of cores: each worker is "
            "a solver thread that needs a core, and more workers "
            "than cores only take time from the haptic loop",
          "set Workers to " + std::to_string(cores) +
            " or less (for more solvers, use several machines: "
            "Engine / Type = mpi).");
      if (p.nonlinear_solver.assembly_threads > cores)
        throw scene.error(
          "Nonlinear solver/Assembly threads",
          "at most " + std::to_string(cores) +
            " on this machine, its number of cores: more threads "
            "than cores do not assemble faster",
          "set Assembly threads to 1 (the workers already use the "
          "cores) or at most " +
            std::to_string(cores) + ".");
    }
  } // namespace



  void
  Scene::check_interpolation() const
  {
    // The interpolation checks what it needs of the rest of the scene
    // (haptics/interpolations/: a contact patch needs a sphere to render).
    // Right after the probe's checks: what it asks of the tip is asked of
    // a tip whose own entries hold.
    Plugins::check_scene("interpolation",
                         parameters.state_space.interpolation,
                         *this);
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
    check_scheduler(*this);
    check_cores(*this);
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

} // namespace palpate
