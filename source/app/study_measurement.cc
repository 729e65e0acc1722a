// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

// What `palpate study` measures for one setting: direct FE solves along
// the trajectories (the reference, and the discretisation knobs' variants),
// the grid states computed as the engine computes them, and the force the
// device would render from them with either interpolation against the
// direct solves, with the cost that setting has (time per state, states
// per cm, precomputation, memory, the speed it keeps up with).

#include <palpate/app/study_impl.h>
#include <palpate/haptics/force_interpolation.h>
#include <palpate/hyperelastic/contact_patch.h>
#include <palpate/hyperelastic/hyperelastic_system.h>
#include <palpate/hyperelastic/patch_contact.h>
#include <palpate/hyperelastic/state.h>
#include <palpate/hyperelastic/state_solver.h>
#include <palpate/state_space/state_cache.h>
#include <palpate/state_space/state_grid.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <functional>
#include <map>
#include <memory>

namespace palpate
{
  namespace internal
  {
    namespace
    {
      /** Relative errors are taken against max(|f_ref|, this) (N): near
       * rest a force of a few mN has no meaningful relative error. The
       * contact-patch benchmark's floor, so that the two compare (a hand
       * tells 7 % of 0.05 N, 3.5 mN, from a force that is not there). */
      constexpr double force_floor = 0.05;

      /**
       * Two solvers on the two cores at once each run this much slower than
       * one alone: they share the memory bandwidth (measured 12.5 -> 19 ms
       * per StVK state on liver501, doc/benchmarks/scaling.md).
       */
      constexpr double two_solver_slowdown = 1.5;

      double
      percentile(std::vector<double> v, const double q)
      {
        if (v.empty())
          return 0;
        std::sort(v.begin(), v.end());
        const double r = q * (v.size() - 1);
        const auto   i = static_cast<std::size_t>(r);
        return i + 1 < v.size() ? v[i] + (r - i) * (v[i + 1] - v[i]) : v[i];
      }

      /**
       * Direct solves at @p x (in trajectory order: each from the last
       * converged one of its trajectory, the first from rest), with the
       * Newton tolerance tightened to @p tolerance.
       */
      std::vector<Sample>
      direct_solves(const Body                             &body,
                    const std::vector<std::vector<Point3>> &paths,
                    const unsigned int                      limit,
                    const double                            tolerance,
                    std::vector<double>                    *state_times,
                    Progress                               &progress,
                    const double                            weight,
                    const std::string                      &what)
      {
        auto p                                = body.scene.parameters;
        p.nonlinear_solver.residual_tolerance = tolerance;
        p.nonlinear_solver.set_reuse(false);
        p.state_space.interpolation = "trilinear";
        StateSolver         solver(body.mesh, body.nodes, p);
        const State         rest = solver.rest_state();
        std::vector<Sample> samples;
        for (const auto &path : paths)
          {
            State previous = rest;
            for (const Point3 &x : path)
              {
                if (samples.size() == limit)
                  return samples;
                Sample s;
                s.x           = x;
                const State a = solver.solve(previous, x);
                s.ok          = a.converged;
                if (a.converged)
                  {
                    s.force    = a.force;
                    s.solution = a.solution;
                    previous   = a;
                    if (state_times != nullptr)
                      state_times->push_back(a.wall_time);
                  }
                samples.push_back(std::move(s));
                progress.step(weight, what);
              }
          }
        return samples;
      }

      /** The grid states of one setting, computed as the engine computes
       * them. */
      struct GridStates
      {
        std::map<unsigned int, std::shared_ptr<const State>> states;
        std::set<unsigned int>                               failed;
        std::vector<double> times, stiffness_times;
      };

      /**
       * Compute the states at @p needed on @p grid with one solver (keeping
       * its factorisation from state to state, as a worker does): each from
       * an axis neighbour one step closer to rest (computed first, down to
       * rest), with the states behind it on the same grid line for the
       * second-/third-order start, as the engines do.
       */
      GridStates
      compute_grid(const Body                      &body,
                   const Parameters::AllParameters &p,
                   const StateGrid                 &grid,
                   const std::set<unsigned int>    &needed,
                   Progress                        &progress,
                   const double                     weight,
                   const std::string               &what)
      {
        StateSolver        solver(body.mesh, body.nodes, p);
        GridStates         g;
        const unsigned int origin = grid.linear({{0, 0, 0}});
        g.states[origin] = std::make_shared<const State>(solver.rest_state());
        const auto get   = [&](const unsigned int q) -> const State   *{
          const auto i = g.states.find(q);
          return i == g.states.end() ? nullptr : i->second.get();
        };
        std::function<void(unsigned int)> ensure = [&](const unsigned int q) {
          if (g.states.count(q) || g.failed.count(q))
            return;
          const GridIndex i = grid.index(q);
          unsigned int    a = 0;
          for (unsigned int d = 1; d < 3; ++d)
            if (std::abs(i[d]) > std::abs(i[a]))
              a = d;
          GridIndex parent = i;
          parent[a] -= (i[a] > 0) - (i[a] < 0);
          ensure(grid.linear(parent));
          // The source: that parent, else any computed axis neighbour.
          unsigned int source = grid.linear(parent);
          if (get(source) == nullptr)
            for (unsigned int d = 0; d < 3 && get(source) == nullptr; ++d)
              for (const int s : {-1, 1})
                {
                  GridIndex n = i;
                  n[d] += s;
                  if (grid.contains(n) && get(grid.linear(n)) != nullptr)
                    {
                      source = grid.linear(n);
                      break;
                    }
                }
          if (get(source) == nullptr)
            {
              g.failed.insert(q);
              return;
            }
          unsigned int b = 0, bb = 0;
          const State *behind = grid.behind(source, q, b) ? get(b) : nullptr;
          const State *behind2 =
            behind != nullptr && grid.behind(b, source, bb) ? get(bb) : nullptr;
          const State s =
            solver.solve(*get(source), grid.position(q), behind, behind2);
          g.times.push_back(s.wall_time);
          g.stiffness_times.push_back(s.stiffness_time);
          if (s.converged)
            {
              State kept = s;
              kept.history.clear();
              g.states[q] = std::make_shared<const State>(std::move(kept));
            }
          else
            g.failed.insert(q);
          progress.step(weight, what);
        };
        // Nearest to rest first.
        std::vector<unsigned int> order(needed.begin(), needed.end());
        std::sort(order.begin(), order.end(), [&](unsigned int x, unsigned y) {
          return Utilities::norm(grid.position(x)) <
                 Utilities::norm(grid.position(y));
        });
        for (const unsigned int q : order)
          ensure(q);
        return g;
      }

      /** Bytes of one state held by the engine. */
      double
      state_bytes(const State &s)
      {
        return sizeof(State) +
               (s.solution.size() + s.multipliers.size()) * sizeof(double);
      }

      /** The node of each DoF (-1: a pressure DoF), for nodal
       * displacements. */
      std::vector<int>
      nodes_of_dofs(const HyperelasticSystem &system)
      {
        const auto &position  = system.dof_positions();
        const auto &component = system.dof_components();
        std::map<std::array<double, 3>, int> number;
        std::vector<int>                     node(position.size(), -1);
        for (std::size_t d = 0; d < position.size(); ++d)
          if (component[d] < 3)
            node[d] = number
                        .emplace(std::array<double, 3>{{position[d][0],
                                                        position[d][1],
                                                        position[d][2]}},
                                 number.size())
                        .first->second;
        return node;
      }

      /** Largest nodal displacement difference (m) of two solutions. */
      double
      shape_difference(const std::vector<int>    &node,
                       const std::vector<double> &a,
                       const std::vector<double> &b)
      {
        const int           n = *std::max_element(node.begin(), node.end()) + 1;
        std::vector<double> e2(n, 0.0);
        for (std::size_t d = 0; d < a.size(); ++d)
          if (node[d] >= 0)
            e2[node[d]] += (a[d] - b[d]) * (a[d] - b[d]);
        return std::sqrt(*std::max_element(e2.begin(), e2.end()));
      }

      /** Fill in the error columns of @p row from force pairs. */
      void
      errors(StudyRow                  &row,
             const std::vector<double> &absolute,
             const std::vector<double> &relative)
      {
        if (absolute.empty())
          return;
        double sum = 0, rsum = 0;
        for (const double e : absolute)
          sum += e;
        for (const double e : relative)
          rsum += e;
        row.err_mean_N   = sum / absolute.size();
        row.err_p95_N    = percentile(absolute, 0.95);
        row.err_max_N    = *std::max_element(absolute.begin(), absolute.end());
        row.err_mean_pct = 100 * rsum / relative.size();
        row.err_p95_pct  = 100 * percentile(relative, 0.95);
        row.err_max_pct =
          100 * *std::max_element(relative.begin(), relative.end());
      }

      /** An interpolation the study measures: its row's name, the kernel
       * that interpolates the forces, whether its states need their
       * stiffness (its state time counts it) and whether the contact
       * patches then give the force. */
      struct Scheme
      {
        const char         *name;
        InterpolateFunction interpolate;
        bool                stiffness, patch;
      };

      /** The interpolations measured: trilinear and Hermite, and with a
       * sphere (@p sphere) the contact patch. */
      std::vector<Scheme>
      schemes(const bool sphere)
      {
        std::vector<Scheme> all = {
          {"trilinear", &interpolate_force, false, false},
          {"Hermite", &interpolate_hermite, true, false}};
        if (sphere)
          all.push_back({"contact patch", &interpolate_force, false, true});
        return all;
      }

      /**
       * The force the haptic loop renders at @p x with Interpolation =
       * contact patch, into @p sample (whose cell is complete): the blend of
       * its corners' patches (PatchContact::blend(), as Interaction does),
       * iterated where the HIP rests until it settles, from the last
       * position's solution (the positions follow their trajectories).
       * False if a corner has no patch.
       */
      bool
      patch_force(const GridStates &g,
                  const Point3     &x,
                  PatchContact     &contact,
                  ForceSample      &sample)
      {
        // The patches of the HIP's tetrahedron, as the haptic loop reads.
        const auto                          w = simplex_weights(sample.local);
        std::array<const ContactPatch *, 8> patches{};
        for (unsigned int c = 0; c < 8; ++c)
          {
            if (w[c] == 0)
              continue;
            const auto i = g.states.find(sample.corners[c]);
            if (i == g.states.end() || !i->second->contact_patch)
              return false;
            patches[c] = i->second->contact_patch.get();
          }
        Point3 previous{{NAN, NAN, NAN}};
        for (unsigned int tick = 0; tick < 200; ++tick)
          {
            contact.blend(patches, w, x, sample.force, &sample.stiffness);
            if (Utilities::distance(sample.force, previous) <=
                1e-9 * Utilities::norm(sample.force))
              break;
            previous = sample.force;
          }
        return true;
      }

      double
      relative_error(const Point3 &f, const Point3 &reference)
      {
        return Utilities::distance(f, reference) /
               std::max(Utilities::norm(reference), force_floor);
      }



      /**
       * How far the shape interpolated on @p grid (the trilinear blend of
       * the corners' displacement fields, @p g) is from each reference
       * solve's, at the positions whose cell's corners all converged.
       */
      std::vector<double>
      shape_errors(const StateGrid           &grid,
                   const GridStates          &g,
                   const std::vector<Point3> &positions,
                   const std::vector<Sample> &reference,
                   const std::vector<int>    &node_of_dof)
      {
        std::vector<double> shape;
        for (std::size_t k = 0; k < positions.size(); ++k)
          {
            if (!reference[k].ok)
              continue;
            GridIndex             lower;
            std::array<double, 3> local;
            if (!grid.locate(positions[k], lower, local))
              continue;
            const auto          c = grid.corners(lower);
            const auto          w = trilinear_weights(local);
            std::vector<double> u(reference[k].solution.size(), 0.0);
            bool                complete = true;
            for (unsigned int j = 0; j < 8 && complete; ++j)
              {
                const auto i = g.states.find(c[j]);
                complete     = i != g.states.end();
                if (complete)
                  for (std::size_t d = 0; d < u.size(); ++d)
                    u[d] += w[j] * i->second->solution[d];
              }
            if (complete)
              shape.push_back(
                shape_difference(node_of_dof, u, reference[k].solution));
          }
        return shape;
      }
    } // namespace



    void
    Study::solve_references()
    {
      // --- Reference: direct solves at every position, tolerance 1e-10.
      reference = direct_solves(*base,
                                paths,
                                positions.size(),
                                1e-10,
                                nullptr,
                                *progress,
                                1,
                                "reference solves");
      for (const auto &s : reference)
        n_reference += s.ok;
      node_of_dof =
        nodes_of_dofs(StateSolver(base->mesh, base->nodes, p0).system());
    }

    void
    Study::grid_setting(const std::string              &knob,
                        const std::string              &value,
                        const Parameters::AllParameters p)
    {
      const StateGrid grid(p.state_space.grid_spacing, p.state_space.extent);
      const auto      corners = cell_corners(grid, positions);
      const auto      needed  = with_neighbours(grid, corners);
      // The stiffness for Hermite; with a sphere, each state's contact
      // patch too, for the contact patch beside them.
      const bool sphere = base->nodes.sphere_tip;
      auto       q      = p;
      q.state_space.interpolation =
        sphere ? "contact patch" : "tricubic Hermite";
      q.nonlinear_solver.compute_stiffness = true;
      const GridStates g =
        compute_grid(*base, q, grid, needed, *progress, 1, knob + " " + value);
      StateCache cache(grid, std::size_t(1) << 40);
      for (const auto &[point, state] : g.states)
        cache.publish(point, state, cache.generation());
      for (const unsigned int point : g.failed)
        cache.publish_failure(point, cache.generation());

      // Cost: state time with and without the stiffness.
      std::vector<double> plain, with;
      for (std::size_t i = 0; i < g.times.size(); ++i)
        {
          with.push_back(g.times[i]);
          plain.push_back(g.times[i] - g.stiffness_times[i]);
        }
      unsigned int region = 0;
      double       bytes  = 0;
      for (const unsigned int c : corners)
        if (const auto i = g.states.find(c); i != g.states.end())
          {
            ++region;
            bytes += state_bytes(*i->second);
          }
        else
          ++region;
      const double per_cm = states_per_cm(grid.spacing());

      // Shape: trilinear blend of the corners' displacement fields.
      const std::vector<double> shape =
        shape_errors(grid, g, positions, reference, node_of_dof);

      for (const Scheme &scheme : schemes(sphere))
        {
          const bool patch = scheme.patch;
          StudyRow   row;
          row.knob               = knob;
          row.value              = value;
          row.interpolation      = scheme.name;
          row.h_mm               = grid.spacing() * 1000;
          row.residual_tolerance = p.nonlinear_solver.residual_tolerance;
          row.max_increment      = p.nonlinear_solver.max_increment_length;
          std::vector<double> absolute, relative;
          PatchContact        contact(base->mesh.n_vertices(), 256);
          for (std::size_t k = 0; k < positions.size(); ++k)
            {
              if (!reference[k].ok)
                continue;
              ++row.samples;
              ForceSample s = scheme.interpolate(grid, cache, positions[k]);
              if (s.complete && patch)
                s.complete = patch_force(g, positions[k], contact, s);
              if (!s.complete)
                continue;
              ++row.covered;
              absolute.push_back(
                Utilities::distance(s.force, reference[k].force));
              relative.push_back(relative_error(s.force, reference[k].force));
            }
          errors(row, absolute, relative);
          if (!shape.empty())
            row.shape_err_mm =
              1000 * *std::max_element(shape.begin(), shape.end());
          row.state_ms =
            1000 * percentile(scheme.stiffness ? with : plain, 0.5);
          row.states            = g.times.size();
          row.failures          = g.failed.size();
          row.states_per_cm     = per_cm;
          row.region_states     = region;
          const double slowdown = workers > 1 ? two_solver_slowdown : 1.0;
          row.precompute_s = region * row.state_ms / 1000 * slowdown / workers;
          row.memory_MiB   = bytes / 1048576.0;
          // The engine keeps up while it computes the corners ahead as
          // fast as the HIP reaches them: workers / (state time) states
          // per second, per_cm states per cm (doc/accuracy-vs-time.md
          // compares it with benchmarks/run max-speed).
          row.speed_mm_s =
            workers / (row.state_ms / 1000 * slowdown) / per_cm * 10;
          result.rows.push_back(row);
        }
      write_csv();
    }

    void
    Study::discretisation(const std::string              &knob,
                          const std::vector<Scene>       &variants,
                          const std::vector<std::string> &names,
                          const std::vector<double>      &cost)
    {
      for (const double radius : {0.0, tip})
        {
          std::vector<std::vector<Sample>> forces;
          std::vector<std::vector<double>> times(variants.size());
          for (unsigned int v = 0; v < variants.size(); ++v)
            {
              Scene s           = variants[v];
              auto &active      = s.parameters.boundary_conditions.active_node;
              active.tip_radius = radius;
              // The study compares a point probe with a rigid tip: the
              // scene's sphere stays a sphere, any other tip of a finite
              // radius is a glued one.
              if (!(radius > 0))
                active.tip = "point";
              else if (!base->nodes.sphere_tip)
                active.tip = "glued nodes";
              const Body body(s);
              forces.push_back(direct_solves(
                body,
                paths,
                std::min<unsigned>(n_disc, positions.size()),
                p0.nonlinear_solver.residual_tolerance,
                &times[v],
                *progress,
                cost[v],
                knob + " " + names[v] +
                  (radius > 0 ? ", tip " + mm(radius) : ", point probe")));
            }
          const auto &finest = forces.back();
          for (unsigned int v = 0; v < variants.size(); ++v)
            {
              StudyRow row;
              row.knob          = knob;
              row.value         = names[v];
              row.interpolation = "direct";
              row.probe         = radius > 0 ? "tip " + mm(radius) : "point";
              row.h_mm          = 0;
              std::vector<double> absolute, relative;
              for (std::size_t k = 0; k < finest.size(); ++k)
                {
                  ++row.samples;
                  if (!finest[k].ok || !forces[v][k].ok)
                    {
                      row.failures += !forces[v][k].ok;
                      continue;
                    }
                  ++row.covered;
                  absolute.push_back(
                    Utilities::distance(forces[v][k].force, finest[k].force));
                  relative.push_back(
                    relative_error(forces[v][k].force, finest[k].force));
                }
              errors(row, absolute, relative);
              row.state_ms = 1000 * percentile(times[v], 0.5);
              row.states   = times[v].size();
              result.rows.push_back(row);
            }
          write_csv();
        }
    }
  } // namespace internal
} // namespace palpate
