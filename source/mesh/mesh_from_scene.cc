// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

#include <palpate/base/exceptions.h>
#include <palpate/mesh/fixed_region.h>
#include <palpate/mesh/mesh.h>
#include <palpate/mesh/mesh_source.h>
#include <palpate/scene/scene.h>

#include <unistd.h>

#include <cmath>
#include <limits>

namespace palpate
{
  namespace
  {
    /** A scale factor to suggest for a mesh read in the wrong unit. */
    struct ScaleSuggestion
    {
      double       factor = 0;
      unsigned int fits = 0, of = 0;
    };

    /**
     * The factor to suggest when the body is not 2 mm - 2 m across: one
     * with which the scene's places meet the body (the probe's point near
     * a node; the fixed nodes' box or half-space holding some nodes but
     * not all), a unit (a power of ten) or the scene's factor times one if
     * such a factor does it, else any (to three digits); of those the one
     * that makes the body closest to a liver's 0.25 m. The scene's places
     * come first because the size alone misleads: for a millimetre mesh a
     * factor making it 0.25 m exactly (0.02743), or the scene's factor over
     * 100 (0.00039146), misses the fixed nodes, which only 0.001 fits.
     */
    ScaleSuggestion
    suggest_scale_factor(const Scene &scene, const Mesh &mesh)
    {
      const double factor = scene.parameters.mesh.scale_factor;
      const double size   = mesh.diameter();
      const auto  &x      = mesh.vertices();
      const auto  &bc     = scene.parameters.boundary_conditions;
      const auto   region = FixedRegion::create(scene);
      // Whether 0 < k < n vertices at scale s lie in the fixed region.
      const auto splits = [&](const double s) {
        std::size_t k = 0;
        for (const auto &v : x)
          k += region->contains(Utilities::scaled(v, s));
        return k > 0 && k < x.size();
      };
      const auto fits = [&](const double f) {
        const double s = f / factor;
        unsigned int n = 0;
        if (bc.active_node.selection != "node id")
          {
            double nearest = std::numeric_limits<double>::infinity();
            for (const auto &v : x)
              nearest = std::min(nearest,
                                 Utilities::distance(Utilities::scaled(v, s),
                                                     bc.active_node.point));
            n += nearest <= 0.05 * size * s;
          }
        if (region->is_place())
          n += splits(s);
        return n;
      };
      ScaleSuggestion best;
      best.of = (bc.active_node.selection != "node id") + region->is_place();
      const auto consider = [&](const double f) {
        const double scaled = size * f / factor;
        if (!(scaled >= Limits::min_body_size &&
              scaled <= Limits::max_body_size))
          return;
        const unsigned int n = fits(f);
        if (best.factor == 0 || n > best.fits ||
            (n == best.fits &&
             std::abs(std::log(scaled / 0.25)) <
               std::abs(std::log(size * best.factor / factor / 0.25))))
          best = {f, n, best.of};
      };
      for (int k = -9; k <= 9; ++k)
        {
          consider(factor * std::pow(10.0, k));
          consider(std::pow(10.0, k));
        }
      // A file in no unit (the SOFA liver): any factor, to three digits.
      // (A power of ten up to 1e22 is exact, and so is dividing the
      // rounded digits by it: the double a user gets by typing the three
      // digits.)
      const auto three_digits = [](const double v) {
        const int e = static_cast<int>(std::floor(std::log10(v))) - 2;
        return e < 0 ? std::round(v * std::pow(10.0, -e)) / std::pow(10.0, -e) :
                       std::round(v / std::pow(10.0, e)) * std::pow(10.0, e);
      };
      if (best.fits < best.of)
        for (int k = -900; k <= 900; ++k)
          consider(three_digits(factor * std::pow(10.0, k / 100.0)));
      return best;
    }



    /** The mesh a scene describes, before the memory check. */
    Mesh
    create_unchecked(const Scene &scene)
    {
      // A body palpate can touch is between a few millimetres (a small
      // sample) and about a metre (the largest organs) across: anything else
      // is a mesh read in the wrong unit, and would run with nonsense
      // forces and a state space of the wrong size.
      const auto check_size = [](const Scene &scene, const Mesh &mesh) {
        const double size = mesh.diameter();
        if (size >= Limits::min_body_size && size <= Limits::max_body_size)
          return;
        const double factor    = scene.parameters.mesh.scale_factor;
        const auto   suggested = suggest_scale_factor(scene, mesh);
        const double best      = suggested.factor;
        throw scene.error(
          "Mesh/Scale factor",
          "with this scale factor " + Limits::body_size_problem(size) +
            ": the mesh file's unit is not the one the scale factor assumes",
          "set Scale factor to the metres per mesh-file unit: 0.001 for "
          "millimetres, 0.01 for centimetres; here " +
            Utilities::to_string(best, 6) + " makes the body " +
            Utilities::to_string(size * best / factor, 3) + " m across" +
            (suggested.of == 0 ?
               std::string() :
               ", where " + std::to_string(suggested.fits) +
                 " of the scene's " + std::to_string(suggested.of) +
                 " places (the probe's point, the fixed nodes' region) "
                 "meet it") +
            ", and " + Utilities::to_string(factor * 0.25 / size, 4) +
            " makes it 0.25 m (a liver).");
      };
      const auto source = MeshSource::create(scene);
      Mesh       mesh   = source->create_mesh(scene);
      if (source->from_file())
        check_size(scene, mesh);
      return mesh;
    }
  } // namespace



  namespace
  {
    /**
     * That one direct solve on @p mesh fits in this machine's memory: an
     * InputError naming the mesh (or the element degree) otherwise, before
     * anything large is allocated. A 205,379-node mesh was accepted and the
     * solve grew past 15 GB without a word.
     *
     * The estimate: MUMPS's factor of a 3-D finite element matrix has about
     * unknowns^(4/3) entries under nested dissection (the separators of a
     * 3-D mesh); measured on this project's livers with P1 (1,921, 7,877
     * and 11,499 nodes: 41, 211 and 434 MB above the program's 170 MB),
     * 310-410 bytes per unknowns^(4/3). 500 bytes are assumed, so the
     * refusal errs towards letting a mesh through. P2 adds a node on every
     * edge (about nodes + tetrahedra edges).
     */
    void
    check_memory(const Scene &scene, const Mesh &mesh)
    {
      const unsigned int degree = scene.displacement_degree();
      const double       nodes  = mesh.n_vertices();
      const double dof_nodes = degree >= 2 ? 2 * nodes + mesh.n_cells() : nodes;
      const double unknowns  = 3 * dof_nodes;
      const double bytes     = 170e6 + 500 * std::pow(unknowns, 4.0 / 3.0);
      const double memory =
        double(sysconf(_SC_PHYS_PAGES)) * double(sysconf(_SC_PAGE_SIZE));
      if (!(memory > 0) || bytes <= memory)
        return;
      const auto gib = [](const double b) {
        return Utilities::to_string(b / 1073741824.0, 3) + " GiB";
      };
      const std::string problem =
        "the mesh has " + std::to_string(mesh.n_vertices()) + " nodes and " +
        std::to_string(mesh.n_cells()) + " tetrahedra; with degree " +
        std::to_string(degree) + " elements that is about " +
        Utilities::to_string(unknowns, 3) +
        " unknowns, and one direct solve would need about " + gib(bytes) +
        " of memory (an estimate), more than this machine's " + gib(memory);
      const std::string fix =
        "use a coarser mesh: palpate mesh SURFACE OUT.msh --nodes 4000 makes "
        "one of about 4,000 nodes (enough for a liver's force to converge "
        "with a sphere probe)" +
        std::string(degree >= 2 ? ", or degree 1 elements" : "") + ".";
      throw scene.error(degree >= 2 ? "Discretization/Polynomial degree" :
                                      "Mesh/File name",
                        problem,
                        fix);
    }
  } // namespace



  Mesh
  Mesh::create(const Scene &scene)
  {
    Mesh mesh = create_unchecked(scene);
    check_memory(scene, mesh);
    return mesh;
  }
} // namespace palpate
