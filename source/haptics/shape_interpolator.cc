// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

#include <palpate/engine/hip_channel.h>
#include <palpate/haptics/interaction.h>
#include <palpate/haptics/shape_interpolator.h>
#include <palpate/hyperelastic/hyperelastic_system.h>
#include <palpate/mesh/mesh.h>
#include <palpate/mesh/node_selection.h>
#include <palpate/scene/scene.h>
#include <palpate/state_space/state_cache.h>
#include <palpate/state_space/state_grid.h>

#include <fcntl.h>
#include <sys/resource.h>
#include <sys/syscall.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <chrono>
#include <condition_variable>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <map>
#include <mutex>
#include <sstream>
#include <thread>
#include <vector>

namespace palpate
{



  PvdIndex::~PvdIndex()
  {
    if (fd >= 0)
      ::close(fd);
  }



  std::string
  PvdIndex::open(const std::string &name)
  {
    file = name;
    fd   = ::open(file.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
    if (fd < 0)
      return failed(errno);
    const std::string header =
      "<?xml version=\"1.0\"?>\n<VTKFile type=\"Collection\" "
      "version=\"0.1\" ByteOrder=\"LittleEndian\">\n  <Collection>\n";
    if (!write_at(header + closing, 0))
      return failed(errno);
    tail = static_cast<long>(header.size());
    return "";
  }



  std::string
  PvdIndex::append(const double time, const std::string &name)
  {
    std::ostringstream entry;
    entry << std::setprecision(10) << "    <DataSet timestep=\"" << time
          << "\" group=\"\" part=\"0\" file=\"" << name << "\"/>\n";
    if (write_at(entry.str() + closing, tail))
      {
        tail += static_cast<long>(entry.str().size());
        return "";
      }
    const int error = errno;
    write_at(closing, tail);
    if (::ftruncate(fd, tail + static_cast<long>(closing.size())) != 0)
      {
        // The closing tags are in place; a cut entry may follow them,
        // which readers stop before.
      }
    return failed(error);
  }



  bool
  PvdIndex::write_at(const std::string &text, long at) const
  {
    for (std::size_t done = 0; done < text.size();)
      {
        const ssize_t n =
          ::pwrite(fd, text.data() + done, text.size() - done, at);
        if (n < 0 && errno == EINTR)
          continue;
        if (n <= 0)
          return false;
        done += static_cast<std::size_t>(n);
        at += n;
      }
    return true;
  }



  std::string
  PvdIndex::failed(const int error) const
  {
    return "the index '" + file + "' could not be written (" +
           std::strerror(error) + ")";
  }



  struct ShapeInterpolator::Impl
  {
    Impl(const Interaction             &i,
         const double                   r,
         const std::string             &d,
         const std::string             &s,
         const std::function<double()> &c,
         const double                   m)
      : interaction(i)
      , rate(r)
      , directory(d)
      , stem(s)
      , clock(c)
      , max_bytes(m)
      , frames(i.mesh(),
               i.nodes(),
               HyperelasticSystem(i.mesh(), i.nodes(), i.scene().parameters))
    {}

    void
    run();

    void
    write_frames();

    const Interaction            &interaction;
    const double                  rate;
    const std::string             directory, stem;
    const std::function<double()> clock;
    const double                  max_bytes;
    double                        bytes = 0;
    unsigned long                 due   = 0; // moving frames, for decimation
    ShapeFrames                   frames;
    std::atomic<bool>             running{false};
    // stop() wakes the thread from its wait for the next frame (at a slow
    // Shape output rate that wait is minutes long).
    std::mutex                wait_mutex;
    std::condition_variable   wake;
    std::atomic<unsigned int> written{0}, skipped{0}, busy{0}, over{0},
      thinned{0};
    std::string failure; // written by the thread before it ends
    // Set once failure is written: the thread writes no more frames.
    std::atomic<bool> failed{false};
    PvdIndex          index;
    std::thread       thread;
  };



  ShapeFrames::ShapeFrames(const Mesh               &mesh,
                           const NodeSelection      &nodes,
                           const HyperelasticSystem &system)
    : n_cells(mesh.n_cells())
  {
    const auto &x         = mesh.vertices();
    const auto &position  = system.dof_positions();
    const auto &component = system.dof_components();
    std::map<std::array<double, 3>, unsigned int> vertex_at;
    for (unsigned int v = 0; v < x.size(); ++v)
      vertex_at[{{x[v][0], x[v][1], x[v][2]}}] = v;
    vertex_dofs.assign(x.size(), {{0, 0, 0}});
    for (std::size_t d = 0; d < position.size(); ++d)
      if (component[d] < 3)
        if (const auto v = vertex_at.find(
              {{position[d][0], position[d][1], position[d][2]}});
            v != vertex_at.end())
          vertex_dofs[v->second][component[d]] = d;

    std::vector<char> fixed(x.size(), 0), active(x.size(), 0);
    for (const unsigned int v : nodes.fixed_vertices)
      fixed[v] = 1;
    active[nodes.active_vertex] = 1;
    for (const unsigned int v : nodes.tip_vertices)
      active[v] = 1;
    std::ostringstream f;
    f << "<DataArray type=\"UInt8\" Name=\"fixed\" format=\"ascii\">\n";
    for (const char c : fixed)
      f << int(c) << " ";
    f << "\n</DataArray>\n<DataArray type=\"UInt8\" Name=\"active\" "
         "format=\"ascii\">\n";
    for (const char c : active)
      f << int(c) << " ";
    f << "\n</DataArray>\n";
    flags = f.str();

    std::ostringstream g;
    g << std::setprecision(9)
      << "<Points>\n<DataArray type=\"Float64\" "
         "NumberOfComponents=\"3\" format=\"ascii\">\n";
    for (const auto &p : x)
      g << p[0] << " " << p[1] << " " << p[2] << "\n";
    g << "</DataArray>\n</Points>\n<Cells>\n<DataArray type=\"Int32\" "
         "Name=\"connectivity\" format=\"ascii\">\n";
    for (const auto &c : mesh.cells())
      g << c[0] << " " << c[1] << " " << c[2] << " " << c[3] << "\n";
    g << "</DataArray>\n<DataArray type=\"Int32\" Name=\"offsets\" "
         "format=\"ascii\">\n";
    for (unsigned int c = 1; c <= mesh.n_cells(); ++c)
      g << 4 * c << " ";
    g << "\n</DataArray>\n<DataArray type=\"UInt8\" Name=\"types\" "
         "format=\"ascii\">\n";
    for (unsigned int c = 0; c < mesh.n_cells(); ++c)
      g << "10 ";
    g << "\n</DataArray>\n</Cells>\n</Piece>\n</UnstructuredGrid>\n"
         "</VTKFile>\n";
    geometry = g.str();
  }



  double
  ShapeFrames::write(const std::vector<double> &solution,
                     const Utilities::Point3   &force,
                     const std::string         &file) const
  {
    std::ofstream out(file);
    if (!out)
      throw std::runtime_error("cannot write the file '" + file +
                               "': " + std::strerror(errno));
    out << std::setprecision(7)
        << "<?xml version=\"1.0\"?>\n<VTKFile type=\"UnstructuredGrid\" "
           "version=\"0.1\" byte_order=\"LittleEndian\">\n"
           "<UnstructuredGrid>\n<FieldData>\n<DataArray type=\"Float64\" "
           "Name=\"force\" NumberOfTuples=\"1\" NumberOfComponents=\"3\" "
           "format=\"ascii\">"
        << force[0] << " " << force[1] << " " << force[2]
        << "</DataArray>\n</FieldData>\n<Piece NumberOfPoints=\""
        << vertex_dofs.size() << "\" NumberOfCells=\"" << n_cells
        << "\">\n<PointData Vectors=\"displacement\">\n<DataArray "
           "type=\"Float64\" Name=\"displacement\" NumberOfComponents=\"3\" "
           "format=\"ascii\">\n";
    for (const auto &d : vertex_dofs)
      out << solution[d[0]] << " " << solution[d[1]] << " " << solution[d[2]]
          << "\n";
    out << "</DataArray>\n" << flags << "</PointData>\n" << geometry;
    out.flush();
    const double bytes = static_cast<double>(out.tellp());
    out.close();
    if (!out)
      {
        // A full disk (or a file size limit): the frame is cut. It is
        // removed, which also gives back the room the index needs; the
        // caller stops writing frames.
        const int       error = errno;
        std::error_code ignored;
        std::filesystem::remove(file, ignored);
        throw std::runtime_error("cannot write the file '" + file +
                                 "': " + std::strerror(error));
      }
    return bytes;
  }



  void
  ShapeInterpolator::Impl::run()
  {
    // A frame that cannot be written (the directory removed, the disk
    // full) stops the shape output, not the interaction: the error is kept
    // for stop() and failure(), and the frames written so far stay listed.
    try
      {
        write_frames();
      }
    catch (const std::exception &e)
      {
        failure = e.what();
        failed.store(true, std::memory_order_release);
      }
    catch (...)
      {
        failure = "an exception of unknown type";
        failed.store(true, std::memory_order_release);
      }
  }



  void
  ShapeInterpolator::Impl::write_frames()
  {
    using Clock = std::chrono::steady_clock;
    // Behind the solvers: a frame is for the eye, a state for the hand.
    setpriority(PRIO_PROCESS, static_cast<id_t>(syscall(SYS_gettid)), 19);
    const auto t0 = Clock::now();
    if (const std::string why =
          index.open(directory + "/" + stem + "-shape.pvd");
        !why.empty())
      throw std::runtime_error(why);
    const auto period = std::chrono::duration_cast<Clock::duration>(
      std::chrono::duration<double>(1.0 / rate));
    auto              next = t0;
    Utilities::Point3 last{{0, 0, 0}};
    bool              any = false;
    while (running.load())
      {
        next += period;
        const auto now = Clock::now();
        if (now > next + period)
          {
            // Writing fell behind: skip the frames that were due, do not
            // write them in a burst.
            busy += static_cast<unsigned int>((now - next) / period);
            next = now;
          }
        {
          std::unique_lock<std::mutex> lock(wait_mutex);
          wake.wait_until(lock, next, [this] { return !running.load(); });
        }
        if (!running.load())
          break;

        const double t =
          clock ? clock() :
                  std::chrono::duration<double>(Clock::now() - t0).count();
        if (clock && t < 0)
          continue; // before the motion: nothing moves
        Utilities::Point3 x, v;
        interaction.hip().read(x, v);
        if (any && Utilities::distance(x, last) <= 1e-6)
          continue; // not moving: the last frame still shows it
        // Decimation: past half the limit every 2nd frame is written, past
        // 3/4 every 4th, past 7/8 every 8th, ... so a long run keeps frames
        // of its whole length at a coarser rate instead of stopping. Below
        // 1/64 of the rate (the last 1/128 of the room) the limit is
        // reached: no more frames.
        unsigned int stride = 1;
        for (const double left = max_bytes - bytes;
             left <= 0.5 * max_bytes / stride && stride <= 64;)
          stride *= 2;
        if (bytes >= max_bytes || stride > 64)
          {
            ++over; // the output limit: no more frames
            last = x;
            any  = true;
            continue;
          }
        {
          if (due++ % stride != 0)
            {
              ++thinned;
              last = x;
              any  = true;
              continue;
            }
        }
        State blend;
        if (!blend_shape(interaction, x, blend))
          {
            ++skipped;
            continue;
          }
        char name[64];
        std::snprintf(name, sizeof(name), "-shape-%05u.vtu", written.load());
        const std::string file = stem + name;
        bytes +=
          frames.write(blend.solution, blend.force, directory + "/" + file);
        if (const std::string why = index.append(t, file); !why.empty())
          {
            // Counted, on disk and indexed go together: the frame the index
            // cannot name is removed (which gives back its room).
            std::error_code ignored;
            std::filesystem::remove(directory + "/" + file, ignored);
            throw std::runtime_error(why + ": the shape output stopped there");
          }
        ++written;
        last = x;
        any  = true;
      }
  }



  bool
  blend_shape(const Interaction       &interaction,
              const Utilities::Point3 &x,
              State                   &result)
  {
    const auto           &grid = interaction.grid();
    GridIndex             lower;
    std::array<double, 3> local;
    if (!grid.locate(x, lower, local))
      return false;
    const auto corners = grid.corners(lower);
    const auto w       = trilinear_weights(local);
    // Every corner is asked for, even after one is missing: with states
    // held elsewhere (MPI servers) each one asked for is fetched, and the
    // cell's 8 come in one round instead of one per call.
    std::shared_ptr<const State> states[8];
    bool                         complete = true;
    for (unsigned int k = 0; k < 8; ++k)
      {
        states[k] = interaction.cache().state(corners[k]);
        complete  = complete && states[k] != nullptr;
      }
    if (!complete)
      return false;
    // The blended state: displacement (and pressure), multipliers, force.
    State blend               = *states[0];
    blend.active_displacement = x;
    for (double &u : blend.solution)
      u = 0;
    for (double &m : blend.multipliers)
      m = 0;
    blend.force = {{0, 0, 0}};
    for (unsigned int k = 0; k < 8; ++k)
      {
        for (std::size_t i = 0; i < blend.solution.size(); ++i)
          blend.solution[i] += w[k] * states[k]->solution[i];
        for (std::size_t i = 0; i < blend.multipliers.size(); ++i)
          blend.multipliers[i] += w[k] * states[k]->multipliers[i];
        for (unsigned int d = 0; d < 3; ++d)
          blend.force[d] += w[k] * states[k]->force[d];
      }
    result = std::move(blend);
    return true;
  }



  ShapeInterpolator::ShapeInterpolator(const Interaction &interaction,
                                       const double       rate,
                                       const std::string &directory,
                                       const std::string &stem,
                                       const std::function<double()> &clock,
                                       const double                   max_bytes)
    : impl(std::make_unique<Impl>(interaction,
                                  rate,
                                  directory,
                                  stem,
                                  clock,
                                  max_bytes))
  {}



  ShapeInterpolator::~ShapeInterpolator()
  {
    stop();
  }



  void
  ShapeInterpolator::start()
  {
    std::filesystem::create_directories(impl->directory);
    impl->running.store(true);
    impl->thread = std::thread([this] { impl->run(); });
  }



  void
  ShapeInterpolator::stop()
  {
    {
      std::lock_guard<std::mutex> lock(impl->wait_mutex);
      if (!impl->running.exchange(false))
        return;
    }
    impl->wake.notify_all();
    impl->thread.join();
  }



  const std::string &
  ShapeInterpolator::failure() const
  {
    return impl->failure;
  }



  bool
  ShapeInterpolator::failed() const noexcept
  {
    return impl->failed.load(std::memory_order_acquire);
  }



  std::pair<unsigned int, unsigned int>
  ShapeInterpolator::frames() const
  {
    return {impl->written.load(), impl->skipped.load()};
  }



  unsigned int
  ShapeInterpolator::frames_skipped_busy() const
  {
    return impl->busy.load();
  }



  unsigned int
  ShapeInterpolator::frames_decimated() const
  {
    return impl->thinned.load();
  }



  unsigned int
  ShapeInterpolator::frames_over_limit() const
  {
    return impl->over.load();
  }
} // namespace palpate
