// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

// The HDF5 state store (issue 15), on the small beam:
// - round trip: states read back are identical bit for bit (force,
//   stiffness, displacement field, multipliers), a failure point too;
// - a store is refused when any fingerprint field differs, naming it;
// - a writer killed (SIGKILL) while appending leaves a store that opens,
//   whose records are intact or, the one cut short, detected as
//   incomplete (no checksum), never wrong;
// - a flipped bit in a stored displacement is detected: that state is
//   skipped, the others are used; a truncated file is refused with a
//   message;
// - an interaction with the store computes its cloud and appends it; a
//   second one loads it and its initial cloud is complete at once.

#include <palpate/base/exceptions.h>
#include <palpate/haptics/interaction.h>
#include <palpate/hyperelastic/state_solver.h>
#include <palpate/mesh/mesh.h>
#include <palpate/mesh/node_selection.h>
#include <palpate/state_space/state_cache.h>
#include <palpate/state_space/state_grid.h>
#include <palpate/state_space/state_store.h>

#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <thread>

#include "../tests.h"

namespace
{
  bool
  identical(const palpate::State &a, const palpate::State &b)
  {
    return a.converged == b.converged &&
           std::memcmp(a.force.data(), b.force.data(), sizeof(a.force)) == 0 &&
           a.solution.size() == b.solution.size() &&
           std::memcmp(a.solution.data(),
                       b.solution.data(),
                       a.solution.size() * sizeof(double)) == 0 &&
           a.multipliers == b.multipliers &&
           a.has_stiffness == b.has_stiffness &&
           (!a.has_stiffness || a.stiffness == b.stiffness);
  }

  /** The field a refused store names, or "NOT refused". */
  std::string
  refused_field(const palpate::Scene &scene)
  {
    try
      {
        const Body                b(scene);
        const palpate::StateStore store(
          "store.h5", palpate::StoreFingerprint::of(b.scene, b.mesh, b.nodes));
      }
    catch (const palpate::InputError &e)
      {
        const auto at = e.problem().find("its ");
        return e.problem().substr(at + 4,
                                  e.problem().find(" is '", at) - at - 4);
      }
    return "NOT refused";
  }
} // namespace

int
main(int argc, char **argv)
{
  palpate::Environment env(argc, argv);
  initlog();

  palpate::Scene scene                                = small_beam_scene();
  scene.parameters.nonlinear_solver.compute_stiffness = true;
  const Body                      body(scene);
  const palpate::StoreFingerprint fingerprint =
    palpate::StoreFingerprint::of(body.scene, body.mesh, body.nodes);
  palpate::StateSolver solver(body.mesh, body.nodes, scene.parameters);
  std::vector<std::pair<unsigned int, palpate::State>> states;
  const palpate::StateGrid grid(scene.parameters.state_space.grid_spacing,
                                scene.parameters.state_space.extent);
  for (const auto &g : std::vector<palpate::GridIndex>{
         {{0, 0, 0}}, {{0, 0, -1}}, {{1, 0, -1}}, {{0, 1, -2}}})
    states.emplace_back(grid.linear(g),
                        solver.solve(solver.rest_state(), grid.position(g)));
  palpate::State failure;
  failure.converged = false;
  failure.status    = palpate::SolveStatus::inverted_element;
  states.emplace_back(grid.linear({{0, 0, -3}}), failure);

  // --- Round trip.
  std::filesystem::remove("store.h5");
  {
    palpate::StateStore store("store.h5", fingerprint);
    for (const auto &[point, state] : states)
      store.append(point, state);
  }
  {
    palpate::StateStore store("store.h5", fingerprint);
    unsigned int        damaged = 0;
    const auto          back    = store.read_all(damaged);
    bool                same    = back.size() == states.size();
    for (std::size_t k = 0; same && k < back.size(); ++k)
      same = back[k].first == states[k].first &&
             identical(back[k].second, states[k].second);
    deallog << "round trip of " << states.size()
            << " records (4 states with stiffness, 1 failure point): "
            << "identical bit for bit " << ok(same) << ", damaged " << damaged
            << ", failure status kept "
            << ok(back.size() == 5 && back[4].second.status ==
                                        palpate::SolveStatus::inverted_element)
            << std::endl;
  }

  // --- The ParaView export holds the store's values.
  {
    const palpate::StateStore store("store.h5", fingerprint);
    store.export_vtk(grid, "space.vtk");
    std::ifstream in("space.vtk");
    std::string   line;
    while (std::getline(in, line) && line != "VECTORS force double")
      ;
    // VTK orders the points x fastest; grid index (i, j, k) from -w.
    const int  w = grid.half_width(), side = 2 * w + 1;
    const auto g    = grid.index(states[1].first);
    const int  skip = (g[0] + w) + side * ((g[1] + w) + side * (g[2] + w));
    for (int k = 0; k < skip; ++k)
      std::getline(in, line);
    palpate::Utilities::Point3 f;
    in >> f[0] >> f[1] >> f[2];
    deallog << "ParaView export: the force at grid point (" << g[0] << ", "
            << g[1] << ", " << g[2] << ") is the store's (1e-8): "
            << ok(palpate::Utilities::distance(f, states[1].second.force) <
                  1e-8 * palpate::Utilities::norm(states[1].second.force))
            << std::endl;
  }

  // --- Each fingerprint field refuses a store of other physics.
  {
    const auto changed = [&](const auto &change) {
      palpate::Scene s = scene;
      change(s.parameters);
      return refused_field(s);
    };
    deallog << "refused, naming the field:" << std::endl;
    deallog << "  Young's modulus x 2: " << changed([](auto &p) {
      p.material_model.set("St.Venant-Kirchhoff", "Young's modulus", 2e5);
    }) << std::endl;
    deallog << "  a finer beam: " << changed([](auto &p) {
      p.mesh.beam_subdivisions_length = 12;
    }) << std::endl;
    deallog << "  fixed boundary id 1: " << changed([](auto &p) {
      p.boundary_conditions.fixed_nodes.boundary_ids = {1};
      p.boundary_conditions.active_node.point        = {{0, 0, 0.01}};
    }) << std::endl;
    deallog << "  another active node: " << changed([](auto &p) {
      p.boundary_conditions.active_node.point = {{0.08, 0, 0.01}};
    }) << std::endl;
    deallog << "  degree 2: " << changed([](auto &p) {
      p.discretization.polynomial_degree = 2;
    }) << std::endl;
    deallog << "  grid spacing 3 mm: " << changed([](auto &p) {
      p.state_space.grid_spacing = 0.003;
    }) << std::endl;
    deallog << "  residual tolerance 1e-4: " << changed([](auto &p) {
      p.nonlinear_solver.residual_tolerance = 1e-4;
    }) << std::endl;
    deallog << "  gravity on: " << changed([](auto &p) {
      p.effects.turn_on("Gravity");
    }) << std::endl;
  }

  // --- A writer killed while appending.
  {
    std::filesystem::remove("killed.h5");
    { // create it with its first record
      palpate::StateStore store("killed.h5", fingerprint);
      store.append(states[0].first, states[0].second);
    }
    // The child says (a byte on a pipe) when it has appended 20 records,
    // and goes on appending: it is killed in the middle of one.
    int appended[2];
    AssertThrow(pipe(appended) == 0, dealii::ExcMessage("no pipe"));
    const pid_t child = fork();
    if (child == 0)
      {
        close(appended[0]);
        palpate::StateStore store("killed.h5", fingerprint);
        for (unsigned int k = 0;; ++k)
          {
            store.append(grid.linear({{int(k % 7) - 3, 0, 0}}),
                         states[1 + k % 3].second);
            if (k == 19)
              {
                const char c = 1;
                if (write(appended[1], &c, 1) != 1)
                  _exit(1);
                close(appended[1]);
              }
          }
      }
    close(appended[1]);
    char c = 0; // 0 bytes read: the child ended before 20 (then it fails)
    if (read(appended[0], &c, 1) != 1)
      deallog << "  (the writer ended before 20 records)" << std::endl;
    close(appended[0]);
    kill(child, SIGKILL);
    waitpid(child, nullptr, 0);
    palpate::StateStore store("killed.h5", fingerprint);
    unsigned int        damaged = 0, incomplete = 0;
    const auto          back  = store.read_all(damaged, &incomplete);
    bool                right = !back.empty();
    for (std::size_t k = 1; k < back.size(); ++k)
      right =
        right && identical(back[k].second, states[1 + (k - 1) % 3].second);
    deallog << "killed writer: the store opens, "
            << (back.size() > 10 ? "> 10" : "<= 10")
            << " intact records, all of them right " << ok(right)
            << ", none damaged " << ok(damaged == 0)
            << ", at most one cut short " << ok(incomplete <= 1) << std::endl;
    if (damaged > 0 || incomplete > 1 || back.size() <= 10)
      deallog << "  (" << back.size() << " intact, " << damaged << " damaged, "
              << incomplete << " incomplete)" << std::endl;
  }

  // --- A flipped bit; a truncated file.
  {
    std::string bytes;
    {
      std::ifstream in("store.h5", std::ios::binary);
      bytes.assign(std::istreambuf_iterator<char>(in), {});
    }
    // The bytes of the largest displacements of the third state (zeros,
    // the fixed nodes', would also match metadata).
    const auto &u       = states[2].second.solution;
    const auto  largest = std::max_element(u.begin() + 2,
                                          u.end() - 2,
                                          [](double a, double b) {
                                            return std::abs(a) < std::abs(b);
                                          }) -
                         u.begin();
    const auto at = bytes.find(
      std::string(reinterpret_cast<const char *>(u.data() + largest - 2),
                  4 * sizeof(double)));
    AssertThrow(at != std::string::npos,
                dealii::ExcMessage("the state's bytes are not in the file"));
    bytes[at + 3] ^= 0x10;
    std::ofstream("flipped.h5", std::ios::binary) << bytes;
    palpate::StateStore store("flipped.h5", fingerprint);
    unsigned int        damaged = 0;
    const auto          back    = store.read_all(damaged);
    deallog << "a flipped bit: found in the file "
            << ok(at != std::string::npos) << ", that state skipped "
            << ok(damaged == 1) << ", the other " << back.size() << " intact"
            << std::endl;

    std::ofstream("truncated.h5", std::ios::binary)
      << bytes.substr(0, bytes.size() / 3);
    try
      {
        palpate::StateStore truncated("truncated.h5", fingerprint);
        deallog << "a truncated file: NOT refused" << std::endl;
      }
    catch (const palpate::InputError &e)
      {
        // Up to HDF5's own words (byte counts of this HDF5's layout).
        deallog << "a truncated file: "
                << e.problem().substr(0, e.problem().find(" (")) << std::endl;
      }
  }

  // --- An interaction fills the store; the next one loads it.
  {
    std::filesystem::remove("beam.h5");
    palpate::Scene with_store               = small_beam_scene();
    with_store.parameters.state_space.store = "beam.h5";
    unsigned int cloud                      = 0;
    {
      palpate::Interaction first(with_store);
      cloud = first.initial_cloud_size();
      first.attach();
      wait_until([&] { return first.initial_cloud_complete(); },
                 120,
                 "the first interaction's initial cloud",
                 std::chrono::milliseconds(20));
      first.detach();
      deallog << "first interaction: " << first.store_report().substr(0, 44)
              << "..." << std::endl;
    }
    // The store is loaded when the interaction is made; the cloud is then
    // complete once the engine has looked at it, with nothing to compute.
    palpate::Interaction second(with_store);
    const auto           counts = second.cache().counts();
    second.attach();
    const bool complete =
      wait_until([&] { return second.initial_cloud_complete(); },
                 generous_deadline,
                 "the second interaction's initial cloud");
    second.detach();
    deallog << "second interaction: the " << cloud << " cloud states loaded: "
            << ok(counts.first + counts.second >= cloud)
            << ", initial cloud complete with no state computed: "
            << ok(complete && second.summary().states_computed == 0)
            << std::endl;
  }
}
