// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

// What `palpate study` varies, one knob at a time from the scene's
// settings: the knobs' values (grid spacing, Newton tolerance, staging
// increment), the finer mesh and the element order of the discretisation
// knobs and the probe they use, and the sweeps that measure each value
// (study_measurement.cc measures one setting).

#include <palpate/app/study_impl.h>
#include <palpate/base/exceptions.h>
#include <palpate/hyperelastic/material.h>
#include <palpate/mesh/mesh_source.h>

#include <algorithm>
#include <filesystem>
#include <iomanip>
#include <sstream>

namespace palpate
{
  namespace internal
  {
    namespace
    {
      std::string
      scientific(const double x)
      {
        std::ostringstream s;
        s << std::scientific << std::setprecision(0) << x;
        return s.str();
      }
    } // namespace



    void
    Study::choose_knob_values()
    {
      // --- The knobs and their values, one at a time from the scene's.
      h0       = p0.state_space.grid_spacing;
      spacings = quick ? std::vector<double>{0.005, 0.01, 0.02} :
                         std::vector<double>{0.0025, 0.005, 0.01, 0.02};
      // A spacing beyond half the extent leaves the positions' cells outside
      // the grid.
      spacings.erase(std::remove_if(spacings.begin(),
                                    spacings.end(),
                                    [&](const double h) {
                                      return h > 0.5 * p0.state_space.extent;
                                    }),
                     spacings.end());
      if (std::find(spacings.begin(), spacings.end(), h0) == spacings.end())
        spacings.push_back(h0);
      std::sort(spacings.begin(), spacings.end());
      tolerances = quick ? std::vector<double>{1e-4} :
                           std::vector<double>{1e-3, 1e-4, 1e-6};
      increments = quick ? std::vector<double>{0.0025} :
                           std::vector<double>{0.001, 0.0025};
      tolerances.erase(std::remove(tolerances.begin(),
                                   tolerances.end(),
                                   p0.nonlinear_solver.residual_tolerance),
                       tolerances.end());
      increments.erase(std::remove(increments.begin(),
                                   increments.end(),
                                   p0.nonlinear_solver.max_increment_length),
                       increments.end());
    }

    void
    Study::choose_finer_mesh()
    {
      // The finer mesh for the mesh knob.
      {
        Scene       f = scene;
        auto       &m = f.parameters.mesh;
        std::string why_not;
        if (!options.finer_mesh.empty())
          {
            m.source = "file";
            m.file_name =
              std::filesystem::absolute(options.finer_mesh).string();
            finer_name = std::filesystem::path(options.finer_mesh).stem();
            finer      = f;
            // Read it and select its nodes now: a file that is not a mesh
            // of this organ is an input error before the reference solves,
            // not after them.
            try
              {
                const Body check(f);
                // Not finer than the scene's: the mesh knob would measure
                // no refinement (0 % differences), which looks like a result.
                const Mesh scene_mesh = Mesh::create(scene);
                if (check.mesh.n_vertices() <= scene_mesh.n_vertices())
                  out << "warning: --finer-mesh " << options.finer_mesh
                      << " has " << check.mesh.n_vertices()
                      << " nodes, not more than the scene's mesh ("
                      << scene_mesh.n_vertices()
                      << "): the mesh knob then measures no refinement. Give a "
                         "finer mesh of the same organ.\n";
              }
            catch (const InputError &e)
              {
                // The file's own problem, but named as what it is here.
                throw InputError(
                  e.file(),
                  e.line(),
                  "--finer-mesh (" + e.entry() + ")",
                  e.problem(),
                  "give a finer mesh of the same organ, in the "
                  "scene's file unit (its Scale factor applies): "
                  "the study solves the scene on it to measure "
                  "the mesh's error.");
              }
          }
        else if (const auto names =
                   MeshSource::create(scene)->make_finer(m, scene))
          {
            // The scene's mesh source knows a finer mesh of the body.
            if (!names->coarse_name.empty())
              coarse_name = names->coarse_name;
            finer_name = names->finer_name;
            finer      = f;
          }
      }
    }

    void
    Study::choose_probe()
    {
      // The probe: the scene's, and a rigid tip of 25 mm (or the scene's
      // tip) for the discretisation knobs, where a point probe has no
      // mesh-converged force.
      tip     = p0.boundary_conditions.active_node.tip_radius > 0 ?
                  p0.boundary_conditions.active_node.tip_radius :
                  0.025;
      n_disc  = quick ? 8 : 40;
      p2_knob = !quick || p0.material_model.model_name != "Mooney-Rivlin";
    }

    bool
    Study::skipped(const std::string &knob) const
    {
      return std::find(options.skip.begin(), options.skip.end(), knob) !=
             options.skip.end();
    }



    void
    Study::measure_grid_knobs()
    {
      if (!skipped("grid"))
        for (const double h : spacings)
          {
            auto p                     = p0;
            p.state_space.grid_spacing = h;
            grid_setting("grid", mm(h), p);
          }
      if (!skipped("tolerance"))
        for (const double t : tolerances)
          {
            auto p                                = p0;
            p.nonlinear_solver.residual_tolerance = t;
            grid_setting("tolerance", scientific(t), p);
          }
      if (!skipped("increment"))
        for (const double l : increments)
          {
            auto p                                  = p0;
            p.nonlinear_solver.max_increment_length = l;
            grid_setting("increment", mm(l), p);
          }

      // The knobs together: the fastest grid setting that passes, with the
      // loosest tolerance that passes at the scene's spacing with the same
      // interpolation.
      {
        const StudyRow *best_grid = nullptr;
        double          loosest   = p0.nonlinear_solver.residual_tolerance;
        for (const auto &row : result.rows)
          if (passes(row, result.threshold_pct) && row.knob == "grid" &&
              (best_grid == nullptr || row.speed_mm_s > best_grid->speed_mm_s))
            best_grid = &row;
        if (best_grid != nullptr)
          for (const auto &row : result.rows)
            if (passes(row, result.threshold_pct) && row.knob == "tolerance" &&
                row.interpolation == best_grid->interpolation)
              loosest = std::max(loosest, row.residual_tolerance);
        if (best_grid != nullptr && !skipped("combined") &&
            (best_grid->h_mm / 1000 != h0 ||
             loosest != p0.nonlinear_solver.residual_tolerance))
          {
            auto p                                = p0;
            p.state_space.grid_spacing            = best_grid->h_mm / 1000;
            p.nonlinear_solver.residual_tolerance = loosest;
            const std::string value =
              mm(p.state_space.grid_spacing) + ", " + scientific(loosest);
            grid_setting("combined", value, p);
          }
      }
    }

    void
    Study::measure_discretisation_knobs()
    {
      if (finer && !skipped("mesh"))
        discretisation("mesh",
                       {scene, *finer},
                       {coarse_name, finer_name},
                       {1, finer_cost});
      if (p2_knob && !skipped("element"))
        {
          // An incompressible plug-in's element pair fixes the degree: the
          // knob is its Element entry (P1-P1 -> Taylor-Hood).
          Scene      p2   = scene;
          auto      &m    = p2.parameters.material_model;
          const auto f    = Material::create(m)->formulation();
          const bool pair = f.displacement_degree > 0;
          if (pair)
            m.set(m.model_name, "Element", "Taylor-Hood");
          else
            p2.parameters.discretization.polynomial_degree = 2;
          const std::string low  = pair ? "P1-P1" : "P1";
          const std::string high = pair ? "Taylor-Hood P2-P1" : "P2";
          if (f.degree(p0.discretization.polynomial_degree) == 1)
            discretisation("element", {scene, p2}, {low, high}, {1, p2_cost});
        }
    }
  } // namespace internal
} // namespace palpate
