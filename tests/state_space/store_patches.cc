// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

// The state store keeps each state's contact patch (State space /
// Interpolation = contact patch, issue 45), on the beam touched by a 1 cm
// sphere:
// - round trip: the patches read back are the states' bit for bit, and
//   render the same force where the HIP is between states;
// - a state that comes without its patch (an MPI server's: the cache
//   holds the patch) is kept with the patch given beside it;
// - a changed byte in a stored patch is found: that state is skipped,
//   the others are used;
// - a store made for tricubic Hermite (no patches) is refused by a
//   contact-patch scene, naming the field; a store of the first format
//   (no patch datasets) is refused as older, not as damaged;
// - load() publishes the patches into the cache, where the haptic loop
//   reads them.

#include <palpate/base/exceptions.h>
#include <palpate/hyperelastic/contact_patch.h>
#include <palpate/hyperelastic/patch_contact.h>
#include <palpate/hyperelastic/state_solver.h>
#include <palpate/mesh/mesh.h>
#include <palpate/mesh/node_selection.h>
#include <palpate/state_space/state_cache.h>
#include <palpate/state_space/state_grid.h>
#include <palpate/state_space/state_store.h>

#include <hdf5.h>

#include <algorithm>
#include <filesystem>
#include <fstream>

#include "../tests.h"

namespace
{
  using palpate::Utilities::Point3;

  /** The force of @p patch for the HIP at @p x, from a fresh solver,
   * after 50 steps of its iteration there. */
  Point3
  rendered(const palpate::ContactPatch &patch,
           const Point3                &x,
           const unsigned int           n_vertices)
  {
    palpate::PatchContact contact(n_vertices, 256);
    Point3                f{{0, 0, 0}};
    for (unsigned int tick = 0; tick < 50; ++tick)
      contact.force(patch, x, f);
    return f;
  }

  /** The problem of the refusal of opening @p file for @p fingerprint, or
   * "NOT refused". */
  std::string
  refusal(const std::string &file, const palpate::StoreFingerprint &fingerprint)
  {
    try
      {
        const palpate::StateStore store(file, fingerprint);
      }
    catch (const palpate::InputError &e)
      {
        return e.problem();
      }
    return "NOT refused";
  }
} // namespace

int
main(int argc, char **argv)
{
  palpate::Environment env(argc, argv);
  initlog();

  palpate::Scene scene = shipped_scene("beam.prm");
  touch_beam_with_sphere(scene, 0.01);
  beam_with_contact_patches(scene);
  auto &p                               = scene.parameters;
  p.state_space.grid_spacing            = 0.005;
  p.nonlinear_solver.residual_tolerance = 1e-10;
  const Body body(scene);
  const auto fingerprint =
    palpate::StoreFingerprint::of(body.scene, body.mesh, body.nodes);
  palpate::StateSolver     solver(body.mesh, body.nodes, p);
  const palpate::StateGrid grid(p.state_space.grid_spacing, 0.02);

  // The states at rest, 5 mm deep and 5 mm beside it.
  std::vector<std::pair<unsigned int, palpate::State>> states;
  palpate::State from = solver.rest_state();
  for (const auto &g :
       std::vector<palpate::GridIndex>{{{0, 0, 0}}, {{0, 0, -1}}, {{1, 0, -1}}})
    {
      states.emplace_back(grid.linear(g), solver.solve(from, grid.position(g)));
      from = states.back().second;
    }
  bool all_patches = true;
  for (const auto &[q, s] : states)
    all_patches = all_patches && s.converged && s.contact_patch;
  deallog << "3 states solved with their patches: " << ok(all_patches)
          << std::endl;
  AssertThrow(all_patches, dealii::ExcMessage("no patches to store"));

  // --- Round trip; the third state appended as an MPI client does:
  // without its patch, the patch beside it.
  std::filesystem::remove("patches.h5");
  {
    palpate::StateStore store("patches.h5", fingerprint);
    store.append(states[0].first, states[0].second);
    store.append(states[1].first, states[1].second);
    palpate::State bare = states[2].second;
    bare.contact_patch  = nullptr;
    store.append(states[2].first, bare, states[2].second.contact_patch.get());
  }
  {
    const palpate::StateStore store("patches.h5",
                                    fingerprint,
                                    palpate::StateStore::Access::read);
    unsigned int              damaged = 0;
    const auto                back    = store.read_all(damaged);
    bool                      same    = back.size() == states.size();
    for (std::size_t k = 0; same && k < back.size(); ++k)
      same = back[k].second.contact_patch &&
             palpate::patch_bytes(*back[k].second.contact_patch) ==
               palpate::patch_bytes(*states[k].second.contact_patch);
    deallog << "round trip of 3 patches (one given beside its state): "
            << "identical bit for bit " << ok(same) << ", damaged " << damaged
            << std::endl;
    // Between the states, 1 mm deeper than the deep ones.
    const Point3 x{{0.0025, 0, -0.006}};
    double       worst = 0;
    for (std::size_t k = 1; same && k < back.size(); ++k)
      {
        const Point3 a =
          rendered(*states[k].second.contact_patch, x, body.mesh.n_vertices());
        const Point3 b =
          rendered(*back[k].second.contact_patch, x, body.mesh.n_vertices());
        worst = std::max(worst, palpate::Utilities::distance(a, b));
        if (k == 1)
          deallog << "  the read-back patch presses at (2.5, 0, -6) mm: "
                  << ok(palpate::Utilities::norm(b) > 1e-3) << std::endl;
      }
    deallog << "  and renders the same force there (0 N apart): "
            << ok(same && worst == 0) << std::endl;
  }

  // --- Loaded into a cache.
  {
    palpate::StateStore store("patches.h5", fingerprint);
    palpate::StateCache cache(grid, std::size_t(1) << 32);
    const auto          loaded = store.load(cache, grid);
    bool                held   = loaded.patches == 3;
    for (const auto &[q, s] : states)
      held = held && cache.patch(q) &&
             palpate::patch_bytes(*cache.patch(q)) ==
               palpate::patch_bytes(*s.contact_patch);
    deallog << "loaded: " << loaded.states << " states, " << loaded.patches
            << " with patches, the cache holds them " << ok(held) << std::endl;
  }

  // --- A changed byte in a stored patch (in W, whose values are
  // nowhere else in the file).
  {
    std::string bytes;
    {
      std::ifstream in("patches.h5", std::ios::binary);
      bytes.assign(std::istreambuf_iterator<char>(in), {});
    }
    const auto &W  = states[1].second.contact_patch->W;
    const auto  at = bytes.find(
      std::string(reinterpret_cast<const char *>(W.data() + W.size() / 2),
                  4 * sizeof(double)));
    AssertThrow(at != std::string::npos,
                dealii::ExcMessage("the patch's bytes are not in the file"));
    bytes[at + 5] ^= 0x20;
    std::ofstream("changed.h5", std::ios::binary) << bytes;
    palpate::StateStore store("changed.h5", fingerprint);
    unsigned int        damaged = 0;
    const auto          back    = store.read_all(damaged);
    deallog << "a changed byte in a patch: found " << ok(damaged == 1)
            << ", that state skipped "
            << ok(back.size() == 2 && back[0].first == states[0].first &&
                  back[1].first == states[2].first)
            << std::endl;
  }

  // --- Stores that cannot serve this scene.
  {
    palpate::Scene hermite                       = scene;
    hermite.parameters.state_space.interpolation = "tricubic Hermite";
    const Body h(hermite);
    std::filesystem::remove("hermite.h5");
    {
      palpate::StateStore store(
        "hermite.h5", palpate::StoreFingerprint::of(h.scene, h.mesh, h.nodes));
      palpate::State bare = states[1].second;
      bare.contact_patch  = nullptr;
      store.append(states[1].first, bare);
    }
    deallog << "a Hermite store opened for contact patch: "
            << refusal("hermite.h5", fingerprint) << std::endl;

    // The first format: the same file without the patch datasets.
    std::filesystem::copy_file(
      "hermite.h5",
      "first-format.h5",
      std::filesystem::copy_options::overwrite_existing);
    const hid_t f = H5Fopen("first-format.h5", H5F_ACC_RDWR, H5P_DEFAULT);
    H5Ldelete(f, "patch", H5P_DEFAULT);
    H5Ldelete(f, "patch_bytes", H5P_DEFAULT);
    H5Fclose(f);
    deallog << "a store of the first format: "
            << refusal("first-format.h5",
                       palpate::StoreFingerprint::of(h.scene, h.mesh, h.nodes))
            << std::endl;
  }

  // Patches of the first layout (no model forces at the neighbours): a
  // contact-patch store whose fingerprint says so.
  {
    std::filesystem::remove("layout-1.h5");
    {
      palpate::StateStore store("layout-1.h5", fingerprint);
      store.append(states[0].first, states[0].second);
    }
    const hid_t       f     = H5Fopen("layout-1.h5", H5F_ACC_RDWR, H5P_DEFAULT);
    const std::string value = "kept";
    H5Adelete(f, "contact patches");
    const hid_t type = H5Tcopy(H5T_C_S1);
    H5Tset_size(type, value.size());
    const hid_t space = H5Screate(H5S_SCALAR);
    const hid_t a =
      H5Acreate2(f, "contact patches", type, space, H5P_DEFAULT, H5P_DEFAULT);
    H5Awrite(a, type, value.data());
    H5Aclose(a);
    H5Sclose(space);
    H5Tclose(type);
    H5Fclose(f);
    deallog << "a store of the first patch layout: "
            << refusal("layout-1.h5", fingerprint) << std::endl;
  }
  deallog << "the patches carry their model's force at the 27 grid points "
             "around them: "
          << ok(std::all_of(
               states.begin(),
               states.end(),
               [](const auto &s) {
                 return s.second.contact_patch->neighbour_force.size() == 27;
               }))
          << std::endl;
}
