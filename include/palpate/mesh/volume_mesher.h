// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

#ifndef palpate_mesh_volume_mesher_h
#define palpate_mesh_volume_mesher_h

#include <palpate/mesh/mesh_quality.h>
#include <palpate/mesh/surface.h>
#include <palpate/mesh/surface_repair.h>

#include <string>
#include <vector>

namespace palpate
{
  /**
   * How far a uniform mesh's node count may be from the count asked for
   * (a fraction: 0.1 is 10 %). Gmsh's count follows the element size only
   * roughly, so mesh_volume() meshes again at a corrected size until the
   * count is this close.
   */
  constexpr double target_nodes_tolerance = 0.1;

  /** What mesh_volume() made. */
  struct VolumeMeshing
  {
    unsigned int nodes = 0, tetrahedra = 0, surface_triangles = 0;
    /** The element size the mesher was given (m). */
    double size = 0;
    /** Gmsh runs: one per meshing pass, more where Gmsh could not
     * parametrise the surface's patches and was given smaller ones. */
    unsigned int attempts = 0;
    /** Meshings at different element sizes (the size is corrected toward
     * the target count after each). */
    unsigned int passes = 0;
    /** The node count asked for. */
    unsigned int target_nodes = 0;
    /** The mesh is graded (MeshGrading): the target sets its coarse size
     * only, and its count is not corrected. */
    bool graded = false;
    /** The node count is within target_nodes_tolerance of the target. */
    bool target_nodes_met = false;
    /** The passes stopped early because another would likely have
     * overrun the time limit. */
    bool stopped_by_time_limit = false;
    /** Wall-clock time of the meshing (s). */
    double seconds = 0;
  };

  /**
   * A volume mesh graded toward where the probe works: elements of
   * @p fine_size (m) within @p radius (m) of @p center, growing by
   * @p growth metres of element size per metre of distance beyond it, up
   * to the mesh's coarse size. fine_size = 0: a uniform mesh. A contact
   * of a probe needs elements well below its radius where it touches,
   * and nothing of the kind elsewhere: grading buys that accuracy at a
   * fraction of the nodes of a uniformly fine mesh.
   */
  struct MeshGrading
  {
    double            fine_size = 0;
    Utilities::Point3 center    = {{0, 0, 0}};
    double            radius    = 0;
    double            growth    = 0.3;
  };

  /**
   * Remesh the closed, repaired @p surface (metres) to elements of about
   * the size that gives @p target_nodes nodes, tetrahedralise it with Gmsh
   * (its API: surface classification, reparametrisation, Frontal-Delaunay
   * surfaces and Delaunay volumes, then optimisation) and write the volume
   * mesh to @p out_msh as Gmsh 2.2 ASCII in metres (physical volume 1,
   * boundary triangles with boundary id 1). A uniform mesh whose count is
   * more than target_nodes_tolerance off is made again at a corrected
   * size (up to four passes in all); the closest pass is kept, and the
   * result says whether it is within the tolerance.
   *
   * Gmsh runs in a child process that is killed after @p time_limit
   * seconds, so a bad surface can never hang palpate. Failures (the limit,
   * a surface Gmsh cannot mesh, e.g. with self-intersections left after
   * remeshing) throw an InputError naming @p surface_name and the fix.
   */
  VolumeMeshing
  mesh_volume(const Surface     &surface,
              const unsigned int target_nodes,
              const double       time_limit,
              const std::string &out_msh,
              const std::string &surface_name,
              const MeshGrading &grading = {});

  /** Everything `palpate mesh` (and Mesh / Source = surface) did. */
  struct SurfaceMeshReport
  {
    /** The surface as read (after the scale factor). */
    std::string                      format;
    unsigned int                     vertices = 0, triangles = 0;
    double                           diameter = 0, area = 0;
    std::array<Utilities::Point3, 2> box;
    SurfaceRepair                    repairs;
    /** The repaired surface's volume (m^3). */
    double volume = 0;
    /** Intersecting triangle pairs of the input, and where the first is. */
    unsigned int      self_intersections = 0;
    Utilities::Point3 intersection{{0, 0, 0}};
    VolumeMeshing     meshing;
    /** The volume mesh's volume (m^3) and quality. */
    double      mesh_volume = 0;
    MeshQuality quality;

    /** The report, a line each, indented by two spaces. */
    std::vector<std::string>
    lines() const;
  };

  /**
   * The whole way from a surface file to a volume mesh: read @p surface_file
   * (coordinates times @p scale, metres per file unit), check that the body
   * has an organ's size (else an InputError on @p scale_entry that names
   * the likely unit), repair it, count its self-intersections, mesh it
   * (mesh_volume()) to @p out_msh and measure the result's quality.
   */
  SurfaceMeshReport
  mesh_surface_file(const std::string &surface_file,
                    const double       scale,
                    const std::string &scale_entry,
                    const unsigned int target_nodes,
                    const double       time_limit,
                    const std::string &out_msh,
                    const MeshGrading &grading = {});

  /**
   * Advice for a body @p size metres across at @p factor metres per file
   * unit: which unit the file most likely uses and the factor to set
   * ("it looks like millimetres: set 0.001"), or "" if the size is an
   * organ's (Limits::min_organ_size to max_organ_size).
   */
  std::string
  unit_advice(const double size, const double factor);
} // namespace palpate

#endif
