// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

#ifndef palpate_hyperelastic_contact_patch_h
#define palpate_hyperelastic_contact_patch_h

#include <palpate/base/utilities.h>
#include <palpate/hyperelastic/hyperelastic_system.h>

#include <cstddef>
#include <cstdint>
#include <memory>
#include <vector>

namespace palpate
{
  class InverseBlock;

  /**
   * A state's contact patch (State space / Interpolation = contact patch):
   * the linearised contact problem of the sphere against the state's
   * surface, small enough to be solved again at every haptic tick for the
   * sphere where the hand actually is (Duriez et al. 2006; SOFA's
   * LCPForceFeedback).
   *
   * For the n surface nodes the sphere can touch from anywhere in the
   * cells around the state (within `reach` of it) it holds their deformed
   * positions x_i, the state's contact forces lambda_s (along the normals
   * n_i from the sphere's centre) and their compliance H (3n x 3n) from
   * the state's contact-free tangent K: H = P K^-1 P^T, how node i moves
   * under a unit force on node j. The tissue around the sphere is then
   * modelled as linear about the state:
   *
   *   y(lambda) = x_free + H f(lambda),  x_free = x - H f_s,
   *
   * with f the contact forces lambda_j along the directions nu_j from the
   * sphere's centre c to the nodes (f_s the state's own), x_free the
   * surface with the state's contact forces taken off (SOFA's "dfree"),
   * and the sphere's geometry exact: node i's gap is
   * |y_i - c| - R + o_i. The offset o_i closes the state's active gaps
   * exactly and opens the others to at least zero (the Newton solution
   * meets them to its tolerance only), so that at the state's own centre
   * lambda_s is the solution to round-off and the force -sum lambda_i nu_i
   * is the state's. Away from it the frictionless contact (lambda >= 0,
   * gap >= 0, lambda gap = 0) is solved on this model (PatchContact).
   *
   * Immutable once made; shared by the state, the cache and the haptic
   * loop.
   */
  struct ContactPatch
  {
    /** A number no other patch of this process has: a haptic loop's warm
     * start for a patch is kept by it. */
    std::uint64_t id = new_id();

    /** The state's HIP displacement (m) and the sphere's centre there (m),
     * and its radius (m). */
    Utilities::Point3 target = {{0, 0, 0}}, center = {{0, 0, 0}};
    double            radius = 0;

    /** The patch's surface nodes (contact candidate numbers). */
    std::vector<unsigned int> nodes;
    /** Their deformed positions, x_i = position[3 i + a] (m), the
     * state's normals n_i (from the centre), and the positions with the
     * state's contact forces taken off, x_free (m). */
    std::vector<double> position, normal, free_position;
    /** The state's contact forces on them (N). */
    std::vector<double> lambda;
    /** Their resultant on the sphere, -sum lambda_i n_i (N): the state's
     * force, which the patch gives at its own centre. */
    Utilities::Point3 force = {{0, 0, 0}};
    /** o_i of the gaps (m). */
    std::vector<double> offset;
    /** H (3n x 3n, row-major, symmetric; m/N), in single precision: the
     * haptic tick moves the nodes by it (H f), and single precision
     * halves both the memory it streams through and the patch. x_free is
     * computed with these values, so that the state's own forces still
     * give its positions to double round-off. */
    std::vector<float> H;
    /** W = N^T H N along the state's normals (n x n; m/N): the contact
     * problem's matrix near the state, kept factorised by the haptic loop
     * while the set of nodes in contact stays. */
    std::vector<double> W;

    /**
     * The grid spacing h (m) of the states around this one, and the
     * magnitude of this model's force (N) at each of them, solved by
     * following the sphere there from the state (tabulate_neighbours()):
     * neighbour_force[9 (k + 1) + 3 (j + 1) + (i + 1)] for the HIP at
     * target + h (i, j, k), i, j, k in {-1, 0, 1}; 27 entries (-1 where
     * not solved: at the neighbours that share no tetrahedron of the grid
     * with this state), or none (then the blend does not correct the
     * model: PatchContact::blend()).
     */
    double              spacing = 0;
    std::vector<double> neighbour_force;

    /** The number of nodes. */
    unsigned int
    size() const noexcept
    {
      return nodes.size();
    }

    /** Bytes held. */
    std::size_t
    memory() const noexcept;

    /** The next id. */
    static std::uint64_t
    new_id() noexcept;
  };

  /**
   * @p patch as bytes, the same on every machine of one byte order: its
   * node count, target, centre, radius, force and spacing (11 doubles),
   * then its arrays, whose lengths follow from the count (n node numbers,
   * 3n, 3n, 3n, n, n and n^2 doubles, 9 n^2 floats for H, 27 doubles of
   * neighbour_force, -1 where it has none). What an MPI result
   * carries after its header and a state store keeps beside a state.
   */
  std::vector<char>
  patch_bytes(const ContactPatch &patch);

  /**
   * The patch @p size bytes at @p data hold (patch_bytes()), with an id of
   * this process. Throws std::runtime_error saying "truncated" or "the
   * wrong length" if they are not one patch's bytes: the caller names the
   * message or record they came from.
   */
  std::shared_ptr<const ContactPatch>
  patch_from_bytes(const char *data, std::size_t size);

  /**
   * The nodes a contact patch holds, from the sphere's candidate @p rows
   * at some unknowns: those within @p reach (m) of the box of sphere
   * centres that the grid cells around the state allow, the state's centre
   * +- @p half_width (m) in each axis, less any a
   * boundary condition fixes in every direction (its compliance row would
   * be zero and the contact problem singular). Into @p nodes, and their
   * free DoFs in that order into @p unknowns: the block of the compliance
   * that make_contact_patch() wants.
   */
  void
  contact_patch_nodes(const std::vector<HyperelasticSystem::ContactRow> &rows,
                      double                     half_width,
                      double                     reach,
                      std::vector<unsigned int> &nodes,
                      std::vector<unsigned int> &unknowns);

  /**
   * The contact patch of the converged state at unknowns @p x with the
   * HIP at @p target, on @p nodes (contact_patch_nodes()), whose
   * compliance @p block is the block of the inverse of the contact-free
   * tangent on their free DoFs (k x k, row-major, in the order of
   * contact_patch_nodes()'s unknowns: InverseBlock::compute()), of the
   * tangent at x or at an iterate close to it. @p rows is work space.
   */
  std::shared_ptr<ContactPatch>
  make_contact_patch(const HyperelasticSystem                    &system,
                     const std::vector<unsigned int>             &nodes,
                     const std::vector<double>                   &block,
                     const std::vector<double>                   &x,
                     const Utilities::Point3                     &target,
                     std::vector<HyperelasticSystem::ContactRow> &rows);
} // namespace palpate

#endif
