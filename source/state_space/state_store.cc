// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

#include <palpate/base/exceptions.h>
#include <palpate/mesh/mesh.h>
#include <palpate/mesh/node_selection.h>
#include <palpate/scene/scene.h>
#include <palpate/state_space/state_cache.h>
#include <palpate/state_space/state_grid.h>
#include <palpate/state_space/state_store_impl.h>

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <limits>
#include <memory>
#include <mutex>
#include <sstream>
#include <string>
#include <vector>

namespace palpate
{
  using internal::acquire_lock;
  using internal::check_store_file;
  using internal::Hash;
  using internal::hdf5_error;
  using internal::Record;
  using internal::WriteFailure;



  namespace
  {
    std::string
    exact(const double x)
    {
      std::ostringstream s;
      s.precision(17);
      s << x;
      return s.str();
    }
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



  void
  StateStore::Impl::read_row(const hsize_t      row,
                             const unsigned int d,
                             void              *data) const
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



  bool
  StateStore::Impl::write_row(const hsize_t      row,
                              const unsigned int d,
                              const void        *data)
  {
    const hsize_t extent[2] = {row + 1, columns(d)};
    if (H5Dset_extent(datasets[d], extent) < 0)
      return false;
    if (columns(d) > 0)
      {
        const hsize_t start[2] = {row, 0}, count[2] = {1, columns(d)};
        const hid_t   file_space = H5Dget_space(datasets[d]);
        H5Sselect_hyperslab(
          file_space, H5S_SELECT_SET, start, nullptr, count, nullptr);
        const hid_t  memory = H5Screate_simple(2, count, nullptr);
        const herr_t written =
          H5Dwrite(datasets[d], type(d), memory, file_space, H5P_DEFAULT, data);
        H5Sclose(memory);
        H5Sclose(file_space);
        if (written < 0)
          return false;
      }
    // The chunk cache holds the row until it is flushed: only the flush
    // meets a full disk, so its result is what says the row is written.
    return H5Dflush(datasets[d]) >= 0;
  }



  std::string
  StateStore::Impl::reserve()
  {
    haddr_t eoa = 0;
    if (H5Fget_eoa(h5, &eoa) < 0)
      return "";
    const off_t record =
      (13 + n_solution + n_multipliers) * sizeof(double) + 16;
    const off_t target = eoa + 4 * record + 128 * 1024;
    // A descriptor of our own, kept while the file is open (close_file()
    // closes it: create() renames a new file into place).
    if (reserve_fd < 0)
      reserve_fd = ::open(file.c_str(), O_WRONLY | O_CLOEXEC);
    if (reserve_fd < 0)
      return std::strerror(errno);
    // The size each time: HDF5 may have cut the file back to its end of
    // allocation when it flushed.
    struct stat st
    {};
    int error = fstat(reserve_fd, &st) == 0 ? 0 : errno;
    // posix_fallocate returns the error; glibc writes zeros where the
    // file system cannot allocate.
    if (error == 0 &&
        static_cast<std::uint64_t>(st.st_size) < eoa + 2 * record + 64 * 1024)
      error = posix_fallocate(reserve_fd, 0, target);
    return error == 0 ? "" : std::strerror(error);
  }



  StateStore::Impl::Read
  StateStore::Impl::read_record(const hsize_t row, Record &r) const
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
    // The checksum is written last: none (HDF5's fill value, 0) means
    // the writer never got there, it was killed or is writing it now.
    if (checksum == 0)
      return Read::incomplete;
    return checksum == r.checksum() && r.point >= 0 ? Read::intact :
                                                      Read::damaged;
  }



  void
  StateStore::Impl::stop(std::string reason)
  {
    if (reason.empty())
      reason = "the file system refused a write";
    stopped = true;
    close_file();
    pending.clear();
    unsigned int states = 0, failures = 0, damaged = 0, incomplete = 0;
    kept = 0;
    std::string unreadable;
    access = Access::read;
    try
      {
        open();
        for (hsize_t row = 0; row < rows; ++row)
          {
            Record     r;
            const Read read = read_record(row, r);
            damaged += read == Read::damaged;
            incomplete += read == Read::incomplete;
            if (read == Read::intact)
              {
                (r.status == 0 ? states : failures) += 1;
                kept += row >= first_row_before_stop;
              }
          }
      }
    catch (const InputError &e)
      {
        unreadable = e.problem();
        close_file();
      }
    const std::string what =
      unreadable.empty() ?
        "it keeps " + std::to_string(states) + " states and " +
          std::to_string(failures) + " failure points (read back), " +
          std::to_string(kept) + " of them appended by this run" +
          (damaged + incomplete > 0 ?
             "; " + std::to_string(damaged + incomplete) +
               " records cut short or damaged are skipped" :
             std::string()) :
        "reading it back failed: " + unreadable;
    const std::string message =
      "writing the state store '" + file + "' failed (" + reason +
      "); appending stopped: " + what +
      ". Make room (or move the store to a disk with room) and run "
      "again: the states kept are not computed again";
    if (lock)
      {
        std::lock_guard<std::mutex> guard(lock->mutex);
        if (lock->failure.empty())
          lock->failure = message;
      }
    throw OutputError(message);
  }



  void
  StateStore::append(const unsigned int point, const State &state)
  {
    Impl &s = *impl;
    if (s.stopped)
      return;
    if (s.access != Access::write)
      throw std::logic_error("StateStore::append on a store opened for "
                             "reading");
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
    s.first_row_before_stop = s.first_row;
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
        s.close_file();
        try
          {
            s.create(keep, state.solution.size(), state.multipliers.size());
          }
        catch (const WriteFailure &f)
          {
            s.first_row_before_stop = 0;
            s.stop(f.reason);
          }
        s.first_row_before_stop = s.first_row;
      }
    r.solution.resize(s.n_solution, 0.0);
    r.multipliers.resize(s.n_multipliers, 0.0);
    const std::uint64_t checksum = r.checksum();
    // Room first: a write that fails half-way leaves HDF5's superblock
    // promising space the file never got (it is then "truncated" to HDF5,
    // and no record in it can be read). So the space for this record, and
    // more, is taken from the file system before HDF5 writes anything; if
    // it cannot be had (the disk full, a file size limit), appending stops
    // here and the file is as the last record left it.
    if (const std::string refused = s.reserve(); !refused.empty())
      s.stop(refused);
    // The checksum goes last: a record cut short has none and is skipped.
    // Each row is flushed as it is written, and the whole file's buffers
    // after the record, so that a killed writer loses at most the record
    // being written and a reader never sees a checksum before its record.
    const hsize_t row = s.rows;
    errno             = 0;
    const bool written =
      s.write_row(row, 0, &r.point) && s.write_row(row, 1, &r.status) &&
      s.write_row(row, 2, r.force) && s.write_row(row, 3, r.stiffness) &&
      s.write_row(row, 4, &r.wall_time) &&
      s.write_row(row, 5, r.solution.data()) &&
      s.write_row(row, 6, r.multipliers.data()) &&
      s.write_row(row, 7, &checksum) && H5Fflush(s.h5, H5F_SCOPE_LOCAL) >= 0;
    if (!written)
      {
        const int         e      = errno;
        const std::string reason = hdf5_error();
        s.stop(!reason.empty() ? reason :
               e != 0          ? std::string(std::strerror(e)) :
                                 std::string());
      }
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
  StateStore::read_all(unsigned int &damaged, unsigned int *incomplete) const
  {
    const Impl                                 &s = *impl;
    std::vector<std::pair<unsigned int, State>> states;
    damaged = 0;
    if (incomplete != nullptr)
      *incomplete = 0;
    if (s.h5 < 0)
      return states;
    for (hsize_t row = 0; row < s.rows; ++row)
      {
        Record           r;
        const Impl::Read read = s.read_record(row, r);
        if (read == Impl::Read::damaged)
          ++damaged;
        if (read == Impl::Read::incomplete && incomplete != nullptr)
          ++*incomplete;
        if (read != Impl::Read::intact)
          continue;
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



  StateStore::StateStore(const std::string      &file,
                         const StoreFingerprint &fingerprint,
                         const Access            access)
    : impl(std::make_unique<Impl>())
  {
    // HDF5 prints its error stack by default; palpate reports errors itself.
    H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr);
    Impl &s            = *impl;
    s.file             = file;
    s.access           = access;
    const bool writing = access == Access::write;
    // What the file is, before HDF5 sees it: a file that is fine but not
    // writable, a directory, a text file are not "damaged".
    check_store_file(file, writing);
    bool exists = true;
    if (writing)
      {
        // The writer's lock, before anything is written; then look again
        // (another writer may have made the store meanwhile).
        s.lock = acquire_lock(file);
        exists = check_store_file(file, writing);
      }
    if (!exists)
      {
        // The sizes come with the first state: create lazily then. Until
        // then the fingerprint is kept.
        try
          {
            s.create(fingerprint, 0, 0);
          }
        catch (const WriteFailure &f)
          {
            s.fail("the store cannot be made: " + f.reason,
                   "make room on its disk, or name a store where there is "
                   "room and you can write (State space / Store).");
          }
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



  StateStore::~StateStore() = default;



  unsigned int
  StateStore::appended() const
  {
    const Impl &s = *impl;
    return s.stopped ? s.kept : s.rows - std::min(s.rows, s.first_row);
  }



  bool
  StateStore::stopped() const
  {
    return impl->stopped;
  }



  StateStore::Loaded
  StateStore::load(StateCache &cache, const StateGrid &grid)
  {
    Impl      &s = *impl;
    Loaded     loaded;
    const auto all        = read_all(loaded.damaged, &loaded.incomplete);
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



  StateStore::Loaded
  StateStore::contents() const
  {
    Loaded     c;
    const auto all = read_all(c.damaged, &c.incomplete);
    for (const auto &[point, state] : all)
      (state.converged ? c.states : c.failures) += 1;
    return c;
  }



  unsigned int
  StateStore::append(const StateCache &cache, const StateGrid &grid)
  {
    Impl        &s = *impl;
    unsigned int n = 0;
    if (s.stopped)
      return 0;
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
    if (s.stopped)
      return 0;
    for (unsigned int p = 0; p < grid.size(); ++p)
      if (s.stored.count(p) == 0)
        {
          const PointStatus status = cache.status(p);
          n += status == PointStatus::failed ||
               (status == PointStatus::available && !cache.dropped(p));
        }
    return n;
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
    out.flush();
    if (!out)
      throw OutputError("writing '" + filename + "' failed (" +
                        std::strerror(errno) + ")");
  }
} // namespace palpate
