// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

#ifndef palpate_scene_parameters_h
#define palpate_scene_parameters_h

#include <palpate/base/plugins.h>
#include <palpate/base/utilities.h>

#include <map>
#include <string>
#include <vector>

namespace dealii
{
  class ParameterHandler;
}

/**
 * The scene: everything a `.prm` file says. One struct per subsection, each
 * with `declare_parameters()` (the single place where names, defaults,
 * patterns and documentation live) and `parse_parameters()`, as in step-44.
 * The structs hold plain values only, so any part of palpate can include
 * this header without pulling in deal.II.
 */
namespace palpate
{
  namespace Parameters
  {
    using Utilities::Point3;

    /** `subsection Mesh`: where the body's tetrahedral mesh comes from. */
    struct Mesh
    {
      /** The mesh source plug-in's name (MeshSourceRegistry,
       * mesh/mesh_source.h), e.g. "file". */
      std::string source;
      /** Each mesh source plug-in's own entries (plug-in name -> its
       * subsection's values); the built-in sources have none: they read
       * the entries below. */
      std::map<std::string, Plugins::Entries> own;
      /** Mesh file (.msh Gmsh 2.2 or v1, .vtk, .vtu) as written in the scene.
       */
      std::string file_name;
      /** Metres per mesh-file length unit. */
      double scale_factor;

      /** Beam generator: edge lengths in metres and subdivisions. */
      double       beam_length, beam_width, beam_height;
      unsigned int beam_subdivisions_length, beam_subdivisions_width,
        beam_subdivisions_height;

      /** Blob generator: semi-axes in metres and refinement count. */
      Point3       blob_semi_axes;
      unsigned int blob_refinements;

      /** Source = surface: the volume mesh's target node count, the
       * meshing time limit (s) and where the volume meshes are kept. */
      unsigned int surface_target_nodes;
      double       surface_time_limit;
      std::string  surface_mesh_directory;
      /** Source = surface: the element size (m) within the radius (m) of
       * Active node / Point; 0: a uniform mesh. */
      double surface_fine_size   = 0;
      double surface_fine_radius = 0.02;

      /** Whether every entry is the same: the mesh built from @p other would
       * be this one's (Interaction::change_parameters() refuses a change).
       * A new entry must be compared here too. */
      bool
      operator==(const Mesh &other) const;
      bool
      operator!=(const Mesh &other) const
      {
        return !(*this == other);
      }

      static void
      declare_parameters(dealii::ParameterHandler &prm);
      void
      parse_parameters(dealii::ParameterHandler &prm);
    };

    /** `subsection Boundary conditions / subsection Fixed nodes`. */
    struct FixedNodes
    {
      /** The fixed region plug-in's name (FixedRegionRegistry,
       * mesh/fixed_region.h), e.g. "box". */
      std::string selection;
      /** Each fixed region plug-in's own entries (plug-in name -> its
       * subsection's values); the built-in regions have none: they read
       * the entries below. */
      std::map<std::string, Plugins::Entries> own;
      /** Boundary ids whose faces' nodes are fixed. */
      std::vector<unsigned int> boundary_ids;
      /** Axis-aligned box, in metres (scaled mesh coordinates). */
      Point3 box_lower_corner, box_upper_corner;
      /** Half-space {x : (x - point) . normal >= 0}, metres. */
      Point3 half_space_point, half_space_normal;
      /** Node numbers as the mesh file numbers them. */
      std::vector<long> node_ids;
      /** Whether only surface nodes inside the region are fixed. */
      bool surface_nodes_only;
      /** "elimination" or "multipliers". */
      std::string treatment;

      static void
      declare_parameters(dealii::ParameterHandler &prm);
      void
      parse_parameters(dealii::ParameterHandler &prm);
    };

    /** `subsection Boundary conditions / subsection Active node`. */
    struct ActiveNode
    {
      /** "nearest surface node" or "node id". */
      std::string selection;
      /** The point the active node is nearest to, metres. */
      Point3 point;
      /** Node number as the mesh file numbers it. */
      long node_id;
      /** Displacement of the active node for a static solve, metres. */
      Point3 prescribed_displacement;
      /** The probe tip plug-in's name (ProbeTipRegistry,
       * mesh/probe_tip.h): what touches the organ, e.g. "sphere". */
      std::string tip;
      /** Each probe tip plug-in's own entries (plug-in name -> its
       * subsection's values); the built-in tips have none: they read
       * Tip radius. */
      std::map<std::string, Plugins::Entries> own;
      /** Radius of the glued tip or of the sphere (m). */
      double tip_radius;

      static void
      declare_parameters(dealii::ParameterHandler &prm);
      void
      parse_parameters(dealii::ParameterHandler &prm);
    };

    /** `subsection Boundary conditions`. */
    struct BoundaryConditions
    {
      FixedNodes fixed_nodes;
      ActiveNode active_node;

      static void
      declare_parameters(dealii::ParameterHandler &prm);
      void
      parse_parameters(dealii::ParameterHandler &prm);
    };

    /** `subsection Material model`: the constitutive law and its data. */
    struct MaterialModel
    {
      /** The name of a registered material plug-in
       * ("St.Venant-Kirchhoff", "Neo-Hookean", "Mooney-Rivlin", ...). */
      std::string model_name;
      /** Mass density, kg/m^3 (used by gravity only). */
      double density;

      /** Every registered model's entries (subsection Material model /
       * NAME), as the scene set them or by default; only model_name's are
       * used. Material::create() builds the material from them. */
      std::map<std::string, std::map<std::string, std::string>> models;

      /** Set the entry @p entry of model @p model (tests, the study);
       * the other entries keep their values (or defaults). */
      void
      set(const std::string &model,
          const std::string &entry,
          const std::string &value);
      void
      set(const std::string &model, const std::string &entry, double value);

      /** The value of entry @p entry of model @p model (its default if
       * the scene did not set it). */
      std::string
      get(const std::string &model, const std::string &entry) const;
      double
      get_double(const std::string &model, const std::string &entry) const;

      static void
      declare_parameters(dealii::ParameterHandler &prm);
      void
      parse_parameters(dealii::ParameterHandler &prm);
    };

    /** `subsection Discretization`: finite element and quadrature. */
    struct Discretization
    {
      /** Polynomial degree of the displacement (1 or 2). */
      unsigned int polynomial_degree;
      /** Points per direction of the simplex Gauss rule; 0 = exact default. */
      unsigned int quadrature_order;

      static void
      declare_parameters(dealii::ParameterHandler &prm);
      void
      parse_parameters(dealii::ParameterHandler &prm);
    };

    /** `subsection Effects`: what the scene simulates; all off by default. */
    struct Effects
    {
      /** The load effects (plug-ins: gravity, surface traction, ...):
       * which are on (`Effects / NAME = true`), by name. */
      std::map<std::string, bool> switches;
      /** Each load effect's own entries, as the scene set them or by
       * default (Effect::create_enabled() builds the effects from them). */
      std::map<std::string, std::map<std::string, std::string>> loads;

      /** Whether the load effect @p name is on. */
      bool
      on(const std::string &name) const;

      /** Switch the load effect @p name on or off (tests, programs). */
      void
      turn_on(const std::string &name, const bool on = true);

      /** Set the entry @p entry of the load effect @p effect. */
      void
      set(const std::string &effect,
          const std::string &entry,
          const std::string &value);

      /** Shape (whole displacement field) interpolation for rendering. */
      bool   shape_output;
      double shape_output_rate;
      /** The most the shape frames may write (MiB): a long run cannot
       * fill the disk. */
      double shape_output_limit;
      /** VTU export of computed states. */
      bool vtu_export;
      /** CSV log of the force at the active node. */
      bool force_log;

      static void
      declare_parameters(dealii::ParameterHandler &prm);
      void
      parse_parameters(dealii::ParameterHandler &prm);
    };

    /** `subsection Nonlinear solver`: staging, Newton, line search. */
    struct NonlinearSolver
    {
      unsigned int n_increments;
      double       max_increment_length;
      unsigned int max_newton_iterations;
      double       residual_tolerance;
      double       increment_tolerance;
      bool         line_search;
      unsigned int max_line_search_steps;
      unsigned int max_cutbacks;
      unsigned int assembly_threads;
      /** Solve Newton steps by GMRES preconditioned with a kept
       * factorisation, refactorising only when GMRES needs more than
       * max_krylov_iterations. */
      bool reuse_factorization;
      /** Reuse factorization = by size: reuse_factorization is decided by
       * the solver from the system's size (from reuse_from equations). */
      bool                          reuse_by_size = false;
      static constexpr unsigned int reuse_from    = 1500;
      unsigned int                  max_krylov_iterations;
      /** Contact solver = condensed: with a sphere, the factorised tangent
       * leaves the contact out and each Newton step solves the contact on
       * the candidates' compliance (a small dense problem); false: the
       * contact rows are in the factorised tangent (the reference). */
      bool condensed_contact = false;
      /** Anderson depth: with Contact solver = condensed, how many earlier
       * quasi-Newton steps are combined into each new one
       * (AndersonAcceleration; 0: none). */
      unsigned int anderson_depth = 4;
      /** With Contact solver = condensed and a contact patch per state:
       * the relative residual below which the Newton solve makes its
       * factors with the patch's Schur complement, so that they serve its
       * last steps and give the patch (not an entry; 0: the patch from a
       * partial factorisation of the converged tangent of its own, the
       * path benchmarks/run organ-speed compares against). */
      double patch_factor_residual = 1e-4;
      /** With a sphere: a target whose sphere clears the body's free
       * equilibrium (once a state without contact force showed it) is that
       * equilibrium, without Newton steps (not an entry; false: every
       * state walks from its neighbour, the path benchmarks/run
       * organ-speed compares against). */
      bool free_start = true;
      /** With Anderson depth > 0: the acceleration's history spans changes
       * of the set of nodes touching the sphere, and a step it fails is
       * retried plain before new factors are made (not an entry; false: a
       * new history at every change of that set, the path
       * benchmarks/run organ-speed compares against). */
      bool anderson_across_contact_changes = true;

      /** Fix reuse_factorization to @p on (no choice by size). */
      void
      set_reuse(const bool on)
      {
        reuse_factorization = on;
        reuse_by_size       = false;
      }

      /** Whether a system of @p n_equations reuses factorisations. */
      bool
      reuse_for(const unsigned int n_equations) const
      {
        return reuse_by_size ? n_equations >= reuse_from : reuse_factorization;
      }
      /** Compute the active-node stiffness of every converged state (not an
       * entry: on when State space / Interpolation needs it). */
      bool compute_stiffness = false;

      static void
      declare_parameters(dealii::ParameterHandler &prm);
      void
      parse_parameters(dealii::ParameterHandler &prm);
    };

    /** `subsection Linear solver`: the sparse direct solver. */
    struct LinearSolver
    {
      /** "by size" (MUMPS below Parameters::LinearSolver::single_from
       * equations, MUMPS single from there on), "MUMPS", "MUMPS single",
       * "UMFPACK", "KLU", "Amesos MUMPS" or "Amesos KLU". */
      std::string solver;
      /** Each linear solver plug-in's own entries (plug-in name -> its
       * subsection's values; LinearSolverRegistry). */
      std::map<std::string, Plugins::Entries> own;
      /** MUMPS fill-reducing ordering: "by size" (AMF below
       * Parameters::LinearSolver::metis_from equations, METIS from there
       * on), "AMF", "METIS", "AMD", "QAMD", "PORD", "SCOTCH" or "automatic"
       * (MUMPS's choice). */
      std::string ordering;

      /** With "by size": the number of equations from which METIS's
       * nested dissection beats AMF (measured on the liver meshes). */
      static constexpr unsigned int metis_from = 5000;

      /** With "by size": the number of equations from which single-precision
       * factors (MUMPS single, in GMRES) beat double ones (measured on the
       * liver meshes: states 9-13 % faster at 5,358-6,965 equations,
       * 30-43 % at 16,980, the same forces to 1e-9). */
      static constexpr unsigned int single_from = 5000;

      /** The solver used for a system of @p n_equations: solver, or with
       * "by size" the one chosen for that size. */
      std::string
      solver_for(const unsigned int n_equations) const
      {
        if (solver != "by size")
          return solver;
        return n_equations >= single_from ? "MUMPS single" : "MUMPS";
      }

      /** The ordering used for a system of @p n_equations: ordering, or
       * with "by size" the one chosen for that size. */
      std::string
      ordering_for(const unsigned int n_equations) const
      {
        if (ordering != "by size")
          return ordering;
        return n_equations >= metis_from ? "METIS" : "AMF";
      }

      static void
      declare_parameters(dealii::ParameterHandler &prm);
      void
      parse_parameters(dealii::ParameterHandler &prm);
    };

    /** `subsection State space`: the regular grid of active-node positions. */
    struct StateSpace
    {
      /** Distance between neighbouring grid points, metres. */
      double grid_spacing;
      /** Half-width of the grid along each axis, metres. */
      double extent;
      /** The interpolation plug-in's name (InterpolationRegistry,
       * haptics/interpolation.h): how the haptic loop interpolates the
       * force between grid points, e.g. "trilinear". */
      std::string interpolation;
      /** Each interpolation plug-in's own entries (plug-in name -> its
       * subsection's values); the built-in ones have none. */
      std::map<std::string, Plugins::Entries> own;
      /** The HDF5 state store ("" for none). */
      std::string store;

      /** What each state keeps for the interpolation (the stiffness, a
       * contact patch), as its plug-in declares it; nothing if no
       * interpolation has that name. */
      Plugins::StateContents
      state_contents() const;

      static void
      declare_parameters(dealii::ParameterHandler &prm);
      void
      parse_parameters(dealii::ParameterHandler &prm);
    };

    /** `subsection Scheduler`: the cloud of states kept around the HIP. */
    struct Scheduler
    {
      double cloud_radius;
      double rate;
      double look_ahead_time;

      static void
      declare_parameters(dealii::ParameterHandler &prm);
      void
      parse_parameters(dealii::ParameterHandler &prm);
    };

    /** `subsection Engine`: who computes states. */
    struct Engine
    {
      /** "threads" or "mpi". */
      std::string  type;
      unsigned int workers;
      /** Memory for whole states in the cache, MiB (per server under
       * MPI). */
      double memory_budget;
      /** MPI: seconds of silence after which a server is lost. */
      double server_timeout;
      /** MPI: seconds one task may take before its server is lost. */
      double task_timeout;

      static void
      declare_parameters(dealii::ParameterHandler &prm);
      void
      parse_parameters(dealii::ParameterHandler &prm);
    };

    /** `subsection Haptics / subsection Trajectory`: the simulated device. */
    struct Trajectory
    {
      /** The plug-in's name ("straight line", "circle", "smooth random",
       * "replay", or one registered elsewhere: TrajectoryRegistry). */
      std::string type;
      /** Each trajectory plug-in's own entries (plug-in name -> its
       * subsection's values), as MaterialModel keeps the models'. */
      std::map<std::string, Plugins::Entries> own;
      // The entries every trajectory may read:
      Point3       direction;
      double       speed;
      double       duration;
      double       radius;
      unsigned int seed;
      std::string  file_name;
      /** "after initial cloud", "after rest neighbourhood" or
       * "immediately". */
      std::string start;
      /** The longest wait for the initial cloud before the motion starts
       * anyway (s). */
      double initial_cloud_time_limit;

      static void
      declare_parameters(dealii::ParameterHandler &prm);
      void
      parse_parameters(dealii::ParameterHandler &prm);
    };

    /** `subsection Haptics`: the real-time loop and the device. */
    struct Haptics
    {
      double loop_rate;
      /** The device plug-in's name (DeviceRegistry). */
      std::string device;
      /** Each device plug-in's own entries (plug-in name -> its
       * subsection's values). */
      std::map<std::string, Plugins::Entries> own;
      double                                  force_limit;
      double                                  max_force_change;
      Trajectory                              trajectory;

      static void
      declare_parameters(dealii::ParameterHandler &prm);
      void
      parse_parameters(dealii::ParameterHandler &prm);
    };

    /** `subsection Output`. */
    struct Output
    {
      /** Directory for all files palpate writes, relative to the cwd. */
      std::string directory;
      /** Machine-readable run summary formats: subset of {csv, json}. */
      std::vector<std::string> summary_formats;
      /** Whether reports include wall-clock times. */
      bool print_timings;

      static void
      declare_parameters(dealii::ParameterHandler &prm);
      void
      parse_parameters(dealii::ParameterHandler &prm);
    };

    /** `subsection Run`: what `palpate SCENE.prm` does. */
    struct Run
    {
      /** "interaction", "static solve" or "set-up only". */
      std::string mode;

      static void
      declare_parameters(dealii::ParameterHandler &prm);
      void
      parse_parameters(dealii::ParameterHandler &prm);
    };

    /**
     * All parameters of a scene (step-44's AllParameters). The single
     * place where the top-level subsections are declared and parsed.
     */
    struct AllParameters
    {
      Run                run;
      Mesh               mesh;
      BoundaryConditions boundary_conditions;
      MaterialModel      material_model;
      Discretization     discretization;
      Effects            effects;
      NonlinearSolver    nonlinear_solver;
      LinearSolver       linear_solver;
      StateSpace         state_space;
      Scheduler          scheduler;
      Engine             engine;
      Haptics            haptics;
      Output             output;

      static void
      declare_parameters(dealii::ParameterHandler &prm);
      void
      parse_parameters(dealii::ParameterHandler &prm);
    };
  } // namespace Parameters
} // namespace palpate

#endif
