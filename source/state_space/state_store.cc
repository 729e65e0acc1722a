// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

#include <palpate/base/exceptions.h>
#include <palpate/mesh/mesh.h>
#include <palpate/mesh/node_selection.h>
#include <palpate/scene/scene.h>
#include <palpate/state_space/state_cache.h>
#include <palpate/state_space/state_grid.h>
#include <palpate/state_space/state_store.h>

#include <hdf5.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <set>
#include <sstream>

namespace palpate
{
  namespace
  {
    /** FNV-1a over bytes: the checksum of a record, and content hashes. */
    class Hash
    {
    public:
      void
      add(const void *data, const std::size_t n)
      {
        const auto *b = static_cast<const unsigned char *>(data);
        for (std::size_t i = 0; i < n; ++i)
          h = (h ^ b[i]) * 1099511628211ull;
      }

      template <typename T>
      void
      add(const std::vector<T> &v)
      {
        add(v.data(), v.size() * sizeof(T));
      }

      std::uint64_t
      value() const
      {
        return h;
      }

      std::string
      hex() const
      {
        char s[17];
        std::snprintf(s, sizeof(s), "%016llx", (unsigned long long)h);
        return s;
      }

    private:
      std::uint64_t h = 1469598103934665603ull;
    };

    std::string
    exact(const double x)
    {
      std::ostringstream s;
      s.precision(17);
      s << x;
      return s.str();
    }

    /** One record's values, in the order the checksum covers them. */
    struct Record
    {
      std::int32_t        point    = 0;
      std::int32_t        status   = 0; // SolveStatus, as a number
      double              force[3] = {0, 0, 0};
      double              stiffness[9];
      double              wall_time = 0;
      std::vector<double> solution, multipliers;

      std::uint64_t
      checksum() const
      {
        Hash h;
        h.add(&point, sizeof(point));
        h.add(&status, sizeof(status));
        h.add(force, sizeof(force));
        h.add(stiffness, sizeof(stiffness));
        h.add(&wall_time, sizeof(wall_time));
        h.add(solution);
        h.add(multipliers);
        return h.value();
      }
    };

    const char *const dataset_names[] = {"point",
                                         "status",
                                         "force",
                                         "stiffness",
                                         "wall_time",
                                         "solution",
                                         "multipliers",
                                         "checksum"};
  } // namespace



  StoreFingerprint
  StoreFingerprint::of(const Scene         &scene,
                       const Mesh          &mesh,
                       const NodeSelection &nodes)
  {
    const auto      &p = scene.parameters;
    StoreFingerprint f;
    {
      Hash h;
      for (const auto &x : mesh.vertices())
        h.add(x.data(), sizeof(x));
      for (const auto &c : mesh.cells())
        h.add(c.data(), sizeof(c));
      f.fields.emplace_back("mesh",
                            std::to_string(mesh.n_vertices()) + " nodes, " +
                              std::to_string(mesh.n_cells()) +
                              " tetrahedra, hash " + h.hex());
    }
    {
      std::string m       = p.material_model.model_name;
      const auto  entries = p.material_model.models.find(m);
      if (entries != p.material_model.models.end())
        for (const auto &[name, value] : entries->second)
          m += "; " + name + " = " + value;
      f.fields.emplace_back("material", m);
    }
    {
      Hash h;
      h.add(nodes.fixed_vertices);
      for (const auto &c : nodes.fixed_components)
        h.add(&c, sizeof(c));
      f.fields.emplace_back("fixed nodes",
                            std::to_string(nodes.fixed_vertices.size()) +
                              " nodes by " +
                              p.boundary_conditions.fixed_nodes.treatment +
                              ", hash " + h.hex());
    }
    {
      std::string a = "node " + std::to_string(nodes.active_vertex);
      if (!nodes.tip_vertices.empty())
        a += ", tip of " + std::to_string(nodes.tip_vertices.size() + 1) +
             " nodes";
      if (p.boundary_conditions.active_node.tip ==
          Parameters::ActiveNode::Tip::sphere)
        a += ", sphere of radius " +
             Utilities::to_string(p.boundary_conditions.active_node.tip_radius,
                                  9) +
             " m at (" + Utilities::to_string(nodes.sphere_center, 9) + ")";
      f.fields.emplace_back("active node", a);
    }
    f.fields.emplace_back("element",
                          "degree " +
                            std::to_string(p.discretization.polynomial_degree) +
                            ", quadrature " +
                            std::to_string(p.discretization.quadrature_order));
    f.fields.emplace_back("grid",
                          "spacing " + exact(p.state_space.grid_spacing) +
                            " m, extent " + exact(p.state_space.extent) + " m");
    f.fields.emplace_back(
      "tolerances",
      "residual " + exact(p.nonlinear_solver.residual_tolerance) +
        ", increment " + exact(p.nonlinear_solver.increment_tolerance) +
        ", increments " + std::to_string(p.nonlinear_solver.n_increments) +
        ", longest increment " +
        exact(p.nonlinear_solver.max_increment_length) + " m");
    {
      std::string e;
      for (const auto &[name, on] : p.effects.switches)
        if (on)
          {
            e += (e.empty() ? "" : "; ") + name;
            const auto entries = p.effects.loads.find(name);
            if (entries != p.effects.loads.end())
              for (const auto &[entry, value] : entries->second)
                e += ", " + entry + " = " + value;
          }
      if (std::find_if(p.effects.switches.begin(),
                       p.effects.switches.end(),
                       [](const auto &s) { return s.second; }) !=
          p.effects.switches.end())
        e += "; density " + exact(p.material_model.density);
      f.fields.emplace_back("load effects", e.empty() ? "none" : e);
    }
    f.fields.emplace_back("palpate version", PALPATE_VERSION);
    return f;
  }



  struct StateStore::Impl
  {
    std::string            file;
    hid_t                  h5 = -1;
    hid_t                  datasets[8];
    hsize_t                n_solution = 0, n_multipliers = 0;
    hsize_t                rows = 0;
    std::set<unsigned int> stored; // points with an intact record
    // Whether the file was left open by a writer that did not finish.
    bool recovered = false;
    // Failure points that came before the first converged state, which
    // fixes the record sizes.
    std::vector<std::pair<unsigned int, State>> pending;

    [[noreturn]] void
    fail(const std::string &problem, const std::string &fix) const
    {
      throw InputError(file, 0, "State space / Store", problem, fix);
    }

    /** The columns of dataset @p d (1 for scalars). */
    hsize_t
    columns(const unsigned int d) const
    {
      switch (d)
        {
          case 2:
            return 3;
          case 3:
            return 9;
          case 5:
            return n_solution;
          case 6:
            return n_multipliers;
          default:
            return 1;
        }
    }

    hid_t
    type(const unsigned int d) const
    {
      return d <= 1 ? H5T_NATIVE_INT32 :
             d == 7 ? H5T_NATIVE_UINT64 :
                      H5T_NATIVE_DOUBLE;
    }

    void
    create(const StoreFingerprint &fingerprint,
           const hsize_t           n_sol,
           const hsize_t           n_mult)
    {
      n_solution       = n_sol;
      n_multipliers    = n_mult;
      const hid_t fapl = H5Pcreate(H5P_FILE_ACCESS);
      H5Pset_libver_bounds(fapl, H5F_LIBVER_LATEST, H5F_LIBVER_LATEST);
      // Written to a temporary name and renamed when complete: a store
      // that exists has its fingerprint and datasets.
      const std::string tmp = file + ".creating";
      h5 = H5Fcreate(tmp.c_str(), H5F_ACC_TRUNC, H5P_DEFAULT, fapl);
      H5Pclose(fapl);
      if (h5 < 0)
        fail("the store cannot be created (" + std::string(strerror(errno)) +
               ")",
             "check that its directory exists and is writable.");
      // The fingerprint: one string attribute per field, on the root.
      const hid_t space = H5Screate(H5S_SCALAR);
      for (const auto &[field, value] : fingerprint.fields)
        {
          const hid_t str = H5Tcopy(H5T_C_S1);
          H5Tset_size(str, value.size() + 1);
          const hid_t a =
            H5Acreate2(h5, field.c_str(), str, space, H5P_DEFAULT, H5P_DEFAULT);
          H5Awrite(a, str, value.c_str());
          H5Aclose(a);
          H5Tclose(str);
        }
      H5Sclose(space);
      for (unsigned int d = 0; d < 8; ++d)
        {
          const hsize_t dims[2]  = {0, columns(d)};
          const hsize_t max[2]   = {H5S_UNLIMITED, columns(d)};
          const hsize_t chunk[2] = {d == 5 || d == 6 ? 1u : 64u,
                                    std::max<hsize_t>(columns(d), 1)};
          const hid_t s    = H5Screate_simple(2, dims, max);
          const hid_t dcpl = H5Pcreate(H5P_DATASET_CREATE);
          H5Pset_chunk(dcpl, 2, chunk);
          datasets[d] = H5Dcreate2(
            h5, dataset_names[d], type(d), s, H5P_DEFAULT, dcpl, H5P_DEFAULT);
          H5Pclose(dcpl);
          H5Sclose(s);
        }
      for (unsigned int d = 0; d < 8; ++d)
        H5Dclose(datasets[d]);
      H5Fclose(h5);
      std::filesystem::rename(tmp, file);
      open();
    }

    void
    open()
    {
      const hid_t fapl = H5Pcreate(H5P_FILE_ACCESS);
      H5Pset_libver_bounds(fapl, H5F_LIBVER_LATEST, H5F_LIBVER_LATEST);
      // A damaged file is damaged on every read: do not retry (SWMR
      // retries metadata reads 100 times with growing pauses, minutes).
      H5Pset_metadata_read_attempts(fapl, 1);
      h5 = H5Fopen(file.c_str(), H5F_ACC_RDWR | H5F_ACC_SWMR_WRITE, fapl);
      if (h5 < 0)
        {
          // A writer that was killed leaves the superblock marked "open for
          // writing", and HDF5 refuses to open it again. The file itself
          // is consistent (SWMR flushes in order): clear the mark, as
          // HDF5's h5clear tool does, and open it again.
          hbool_t     clear = true;
          const hid_t fix   = H5Pcopy(fapl);
          if (H5Pset(fix, "clear_status_flags", &clear) >= 0)
            {
              const hid_t cleared = H5Fopen(file.c_str(), H5F_ACC_RDWR, fix);
              if (cleared >= 0)
                {
                  H5Fclose(cleared);
                  recovered = true;
                  h5        = H5Fopen(file.c_str(),
                               H5F_ACC_RDWR | H5F_ACC_SWMR_WRITE,
                               fapl);
                }
            }
          H5Pclose(fix);
        }
      H5Pclose(fapl);
      if (h5 < 0)
        fail("HDF5 cannot open the store: it is damaged (truncated or "
             "overwritten) or not a palpate store",
             "move it away or delete it: palpate then starts a new store "
             "(the states in it are lost).");
      for (unsigned int d = 0; d < 8; ++d)
        {
          datasets[d] = H5Dopen2(h5, dataset_names[d], H5P_DEFAULT);
          if (datasets[d] < 0)
            fail(std::string("the store has no dataset '") + dataset_names[d] +
                   "': it is not a palpate store, or it is damaged",
                 "move it away or delete it: palpate then starts a new "
                 "store.");
        }
      hsize_t     dims[2];
      const hid_t s = H5Dget_space(datasets[5]);
      H5Sget_simple_extent_dims(s, dims, nullptr);
      H5Sclose(s);
      n_solution    = dims[1];
      const hid_t m = H5Dget_space(datasets[6]);
      H5Sget_simple_extent_dims(m, dims, nullptr);
      H5Sclose(m);
      n_multipliers = dims[1];
      // The rows: the fewest any dataset has (a record cut short by a
      // crash has some datasets extended, not all).
      rows = std::numeric_limits<hsize_t>::max();
      for (unsigned int d = 0; d < 8; ++d)
        {
          const hid_t sp = H5Dget_space(datasets[d]);
          H5Sget_simple_extent_dims(sp, dims, nullptr);
          H5Sclose(sp);
          rows = std::min(rows, dims[0]);
        }
    }

    std::string
    attribute(const std::string &name) const
    {
      if (H5Aexists(h5, name.c_str()) <= 0)
        return "(not recorded)";
      const hid_t a    = H5Aopen(h5, name.c_str(), H5P_DEFAULT);
      const hid_t t    = H5Aget_type(a);
      const auto  size = H5Tget_size(t);
      std::string value(size, '\0');
      const hid_t str = H5Tcopy(H5T_C_S1);
      H5Tset_size(str, size);
      H5Aread(a, str, value.data());
      H5Tclose(str);
      H5Tclose(t);
      H5Aclose(a);
      return value.c_str();
    }

    void
    read_row(const hsize_t row, const unsigned int d, void *data) const
    {
      const hsize_t start[2] = {row, 0}, count[2] = {1, columns(d)};
      if (count[1] == 0)
        return;
      const hid_t file_space = H5Dget_space(datasets[d]);
      H5Sselect_hyperslab(
        file_space, H5S_SELECT_SET, start, nullptr, count, nullptr);
      const hid_t memory = H5Screate_simple(2, count, nullptr);
      H5Dread(datasets[d], type(d), memory, file_space, H5P_DEFAULT, data);
      H5Sclose(memory);
      H5Sclose(file_space);
    }

    void
    write_row(const hsize_t row, const unsigned int d, const void *data)
    {
      const hsize_t extent[2] = {row + 1, columns(d)};
      H5Dset_extent(datasets[d], extent);
      if (columns(d) > 0)
        {
          const hsize_t start[2] = {row, 0}, count[2] = {1, columns(d)};
          const hid_t   file_space = H5Dget_space(datasets[d]);
          H5Sselect_hyperslab(
            file_space, H5S_SELECT_SET, start, nullptr, count, nullptr);
          const hid_t memory = H5Screate_simple(2, count, nullptr);
          if (H5Dwrite(
                datasets[d], type(d), memory, file_space, H5P_DEFAULT, data) <
              0)
            throw OutputError("writing the state store '" + file +
                              "' failed (disk full?)");
          H5Sclose(memory);
          H5Sclose(file_space);
        }
      H5Dflush(datasets[d]);
    }

    bool
    read_record(const hsize_t row, Record &r) const
    {
      r.solution.resize(n_solution);
      r.multipliers.resize(n_multipliers);
      std::uint64_t checksum = 0;
      read_row(row, 0, &r.point);
      read_row(row, 1, &r.status);
      read_row(row, 2, r.force);
      read_row(row, 3, r.stiffness);
      read_row(row, 4, &r.wall_time);
      read_row(row, 5, r.solution.data());
      read_row(row, 6, r.multipliers.data());
      read_row(row, 7, &checksum);
      return checksum == r.checksum() && checksum != 0;
    }
  };



  StateStore::StateStore(const std::string      &file,
                         const StoreFingerprint &fingerprint)
    : impl(std::make_unique<Impl>())
  {
    // HDF5 prints its error stack by default; palpate reports errors itself.
    H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr);
    Impl &s = *impl;
    s.file  = file;
    // error_code: a path the file system refuses (a loop of links, a name
    // too long) is the user's input, not an internal error.
    std::error_code error;
    const bool      exists = std::filesystem::exists(file, error);
    if (error)
      s.fail("the file system refuses this path: " + error.message(),
             "name a store file in a directory you can write, e.g. "
             "'liver.h5'.");
    if (!exists)
      {
        // The sizes come with the first state: create lazily then. Until
        // then the fingerprint is kept.
        s.create(fingerprint, 0, 0);
        return;
      }
    s.open();
    for (const auto &[field, value] : fingerprint.fields)
      {
        const std::string stored = s.attribute(field);
        if (stored != value)
          s.fail("the store was computed for other physics: its " + field +
                   " is '" + stored + "', the scene's is '" + value +
                   "'; its states would be wrong here",
                 "use another store file for this scene (State space / "
                 "Store), or delete this one to compute the states again.");
      }
  }



  StateStore::~StateStore()
  {
    Impl &s = *impl;
    if (s.h5 >= 0)
      {
        for (unsigned int d = 0; d < 8; ++d)
          if (s.datasets[d] >= 0)
            H5Dclose(s.datasets[d]);
        H5Fclose(s.h5);
      }
  }



  void
  StateStore::append(const unsigned int point, const State &state)
  {
    Impl &s = *impl;
    if (s.n_solution == 0 && !state.converged)
      {
        s.pending.emplace_back(point, state);
        s.stored.insert(point);
        return;
      }
    Record r;
    r.point  = point;
    r.status = state.converged ? 0 : 1 + static_cast<int>(state.status);
    for (unsigned int d = 0; d < 3; ++d)
      r.force[d] = state.force[d];
    for (unsigned int k = 0; k < 9; ++k)
      r.stiffness[k] = state.has_stiffness ?
                         state.stiffness[k] :
                         std::numeric_limits<double>::quiet_NaN();
    r.wall_time = state.wall_time;
    if (state.converged)
      {
        r.solution    = state.solution;
        r.multipliers = state.multipliers;
      }
    if (s.rows == 0 && s.n_solution == 0 && state.converged)
      {
        // The first state fixes the record sizes: make the datasets again
        // with them (no row is in the file yet).
        StoreFingerprint keep;
        for (const char *const field : {"mesh",
                                        "material",
                                        "fixed nodes",
                                        "active node",
                                        "element",
                                        "grid",
                                        "tolerances",
                                        "load effects",
                                        "palpate version"})
          keep.fields.emplace_back(field, s.attribute(field));
        for (unsigned int d = 0; d < 8; ++d)
          H5Dclose(s.datasets[d]);
        H5Fclose(s.h5);
        s.h5 = -1;
        s.create(keep, state.solution.size(), state.multipliers.size());
      }
    r.solution.resize(s.n_solution, 0.0);
    r.multipliers.resize(s.n_multipliers, 0.0);
    const std::uint64_t checksum = r.checksum();
    // The checksum goes last: a record cut short has none and is skipped.
    const hsize_t row = s.rows;
    s.write_row(row, 0, &r.point);
    s.write_row(row, 1, &r.status);
    s.write_row(row, 2, r.force);
    s.write_row(row, 3, r.stiffness);
    s.write_row(row, 4, &r.wall_time);
    s.write_row(row, 5, r.solution.data());
    s.write_row(row, 6, r.multipliers.data());
    s.write_row(row, 7, &checksum);
    // The whole file's buffers, so that a killed writer loses at most the
    // record being written.
    H5Fflush(s.h5, H5F_SCOPE_LOCAL);
    ++s.rows;
    s.stored.insert(point);
    if (!s.pending.empty() && s.n_solution > 0)
      {
        const auto pending = std::move(s.pending);
        s.pending.clear();
        for (const auto &[p, failure] : pending)
          append(p, failure);
      }
  }



  std::vector<std::pair<unsigned int, State>>
  StateStore::read_all(unsigned int &damaged) const
  {
    const Impl                                 &s = *impl;
    std::vector<std::pair<unsigned int, State>> states;
    damaged = 0;
    for (hsize_t row = 0; row < s.rows; ++row)
      {
        Record r;
        if (!s.read_record(row, r) || r.point < 0)
          {
            ++damaged;
            continue;
          }
        State state;
        state.converged = r.status == 0;
        state.status    = r.status == 0 ? SolveStatus::converged :
                                          static_cast<SolveStatus>(r.status - 1);
        for (unsigned int d = 0; d < 3; ++d)
          state.force[d] = r.force[d];
        state.has_stiffness = !std::isnan(r.stiffness[0]);
        for (unsigned int k = 0; k < 9; ++k)
          state.stiffness[k] = state.has_stiffness ? r.stiffness[k] : 0;
        state.wall_time = r.wall_time;
        if (state.converged)
          {
            state.solution    = std::move(r.solution);
            state.multipliers = std::move(r.multipliers);
          }
        else
          state.message =
            "a failure point (" + to_string(state.status) + ", from the store)";
        states.emplace_back(r.point, std::move(state));
      }
    return states;
  }



  StateStore::Loaded
  StateStore::load(StateCache &cache, const StateGrid &grid)
  {
    Impl      &s = *impl;
    Loaded     loaded;
    const auto all        = read_all(loaded.damaged);
    const auto generation = cache.generation();
    for (const auto &[point, state] : all)
      {
        if (point >= grid.size())
          {
            ++loaded.damaged;
            continue;
          }
        s.stored.insert(point);
        if (state.converged)
          {
            State copy               = state;
            copy.active_displacement = grid.position(point);
            cache.publish(point,
                          std::make_shared<const State>(std::move(copy)),
                          generation);
            ++loaded.states;
          }
        else
          {
            cache.publish_failure(point, generation, state.status);
            ++loaded.failures;
          }
      }
    return loaded;
  }



  unsigned int
  StateStore::append(const StateCache &cache, const StateGrid &grid)
  {
    Impl        &s = *impl;
    unsigned int n = 0;
    for (unsigned int p = 0; p < grid.size(); ++p)
      {
        if (s.stored.count(p) > 0)
          continue;
        const PointStatus status = cache.status(p);
        if (status == PointStatus::failed)
          {
            State failure;
            failure.converged = false;
            failure.status    = cache.failure_reason(p);
            append(p, failure);
            ++n;
          }
        else if (status == PointStatus::available)
          if (const auto state = cache.state(p))
            {
              append(p, *state);
              ++n;
            }
      }
    return n;
  }



  unsigned int
  StateStore::missing(const StateCache &cache, const StateGrid &grid) const
  {
    const Impl  &s = *impl;
    unsigned int n = 0;
    for (unsigned int p = 0; p < grid.size(); ++p)
      if (s.stored.count(p) == 0)
        {
          const PointStatus status = cache.status(p);
          n += status == PointStatus::failed ||
               (status == PointStatus::available && !cache.dropped(p));
        }
    return n;
  }



  void
  StateStore::export_vtk(const StateGrid   &grid,
                         const std::string &filename) const
  {
    unsigned int               damaged = 0;
    const auto                 all     = read_all(damaged);
    const auto                 n       = grid.size();
    std::vector<const State *> at(n, nullptr);
    for (const auto &[point, state] : all)
      if (point < n)
        at[point] = &state;
    std::ofstream out(filename);
    if (!out)
      throw OutputError("cannot write '" + filename + "'");
    out.precision(9);
    const unsigned int side = 2 * grid.half_width() + 1;
    const double       h = grid.spacing(), o = -h * grid.half_width();
    out << "# vtk DataFile Version 3.0\npalpate state space of " << file()
        << "\nASCII\nDATASET STRUCTURED_POINTS\nDIMENSIONS " << side << ' '
        << side << ' ' << side << "\nORIGIN " << o << ' ' << o << ' ' << o
        << "\nSPACING " << h << ' ' << h << ' ' << h << "\nPOINT_DATA " << n
        << "\n";
    // VTK orders points x fastest: the grid's linear number may not, so go
    // by index.
    const auto point_at =
      [&](const unsigned int i, const unsigned int j, const unsigned int k) {
        const int w = grid.half_width();
        return grid.linear(GridIndex{{int(i) - w, int(j) - w, int(k) - w}});
      };
    const auto each = [&](const auto &write) {
      for (unsigned int k = 0; k < side; ++k)
        for (unsigned int j = 0; j < side; ++j)
          for (unsigned int i = 0; i < side; ++i)
            write(at[point_at(i, j, k)]);
    };
    out << "VECTORS force double\n";
    each([&](const State *s) {
      const bool f = s != nullptr && s->converged;
      out << (f ? s->force[0] : 0.) << ' ' << (f ? s->force[1] : 0.) << ' '
          << (f ? s->force[2] : 0.) << '\n';
    });
    out << "SCALARS force_magnitude double 1\nLOOKUP_TABLE default\n";
    each([&](const State *s) {
      out << (s != nullptr && s->converged ? Utilities::norm(s->force) : 0.)
          << '\n';
    });
    out << "SCALARS status int 1\nLOOKUP_TABLE default\n";
    each([&](const State *s) {
      out << (s == nullptr ? -1 :
              s->converged ? 0 :
                             1 + static_cast<int>(s->status))
          << '\n';
    });
    out << "TENSORS stiffness double\n";
    each([&](const State *s) {
      for (unsigned int r = 0; r < 3; ++r)
        out << (s != nullptr && s->has_stiffness ? s->stiffness[3 * r] : 0.)
            << ' '
            << (s != nullptr && s->has_stiffness ? s->stiffness[3 * r + 1] : 0.)
            << ' '
            << (s != nullptr && s->has_stiffness ? s->stiffness[3 * r + 2] : 0.)
            << '\n';
    });
    if (!out)
      throw OutputError("writing '" + filename + "' failed");
  }



  unsigned int
  StateStore::size() const
  {
    return impl->rows;
  }



  const std::string &
  StateStore::file() const
  {
    return impl->file;
  }
} // namespace palpate
