// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

#include <palpate/base/exceptions.h>
#include <palpate/base/stop_request.h>
#include <palpate/mesh/mesh_file.h>
#include <palpate/mesh/volume_mesher.h>
#include <palpate/scene/scene.h>

#include <gmsh.h>
#include <signal.h>
#include <sys/prctl.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <functional>
#include <sstream>
#include <thread>

namespace palpate
{
  namespace
  {
    using Clock = std::chrono::steady_clock;

    /** One Gmsh meshing of the surface at element size h. */
    struct Pass
    {
      double      h     = 0;
      std::size_t nodes = 0, tetrahedra = 0, triangles = 0;
    };

    /**
     * The element size that should give @p target nodes, from a pass that
     * gave pass.nodes at pass.h. Interior nodes fill the volume, one per
     * ~h^3; surface nodes cover the boundary, one per ~h^2, so a pure
     * h^-3 law over-corrects on coarse meshes, where a third or more of
     * the nodes lie on the surface (a closed triangulated surface has
     * triangles / 2 + 2 nodes: Euler). Solves
     *   n_interior s^3 + n_surface s^2 = target,  s = pass.h / h,
     * by bisection (the left side grows with s), with the step kept to a
     * factor 2 either way so that a freak count cannot throw the size far.
     */
    double
    corrected_size(const Pass &pass, const unsigned int target)
    {
      const double n_surface =
        std::min<double>(pass.triangles / 2. + 2, pass.nodes);
      const double n_interior = pass.nodes - n_surface;
      const auto   count      = [&](const double s) {
        return n_interior * s * s * s + n_surface * s * s;
      };
      double lo = 0.5, hi = 2;
      if (count(lo) >= target)
        return pass.h / lo;
      if (count(hi) <= target)
        return pass.h / hi;
      for (unsigned int k = 0; k < 60; ++k)
        {
          const double mid                = (lo + hi) / 2;
          (count(mid) < target ? lo : hi) = mid;
        }
      return pass.h / ((lo + hi) / 2);
    }

    /**
     * Give Gmsh @p s as one discrete surface, classified into patches at
     * @p angle degrees, and the volume it bounds.
     */
    void
    add_body(const Surface &s, const double angle)
    {
      gmsh::model::add("organ");
      const int                tag = gmsh::model::addDiscreteEntity(2);
      std::vector<std::size_t> node_tags(s.vertices.size());
      std::vector<double>      xyz;
      for (std::size_t v = 0; v < s.vertices.size(); ++v)
        {
          node_tags[v] = v + 1;
          for (const double x : s.vertices[v])
            xyz.push_back(x);
        }
      gmsh::model::mesh::addNodes(2, tag, node_tags, xyz);
      std::vector<std::size_t> element_tags, element_nodes;
      for (std::size_t t = 0; t < s.triangles.size(); ++t)
        {
          element_tags.push_back(t + 1);
          for (const unsigned int v : s.triangles[t])
            element_nodes.push_back(v + 1);
        }
      gmsh::model::mesh::addElementsByType(tag, 2, element_tags, element_nodes);
      gmsh::model::mesh::classifySurfaces(angle * M_PI / 180, true, true, M_PI);
      gmsh::model::mesh::createGeometry();
      std::vector<std::pair<int, int>> surfaces;
      gmsh::model::getEntities(surfaces, 2);
      std::vector<int> surface_tags;
      for (const auto &e : surfaces)
        surface_tags.push_back(e.second);
      const int loop = gmsh::model::geo::addSurfaceLoop(surface_tags);
      const int body = gmsh::model::geo::addVolume({loop});
      gmsh::model::geo::synchronize();
      gmsh::model::addPhysicalGroup(3, {body}, 1);
      gmsh::model::addPhysicalGroup(2, surface_tags, 1);
    }



    /**
     * Gmsh's element sizes: in [h/2, h], or (@p grading) from its fine size
     * near its centre, growing to @p h.
     */
    void
    set_sizes(const double h, const MeshGrading &grading)
    {
      const bool graded  = grading.fine_size > 0;
      const bool refined = graded && grading.fine_size < h;
      gmsh::option::setNumber("Mesh.MeshSizeMin",
                              0.5 * (refined ? grading.fine_size : h));
      if (refined)
        {
          // size(r) = fine + growth max(0, r - radius), capped
          // at h by MeshSizeMax; max(0, t) = (t + |t|)/2
          // written with Sqrt, which MathEval surely has.
          const auto        &c = grading.center;
          std::ostringstream r, f;
          r.precision(17);
          f.precision(17);
          r << "(Sqrt((x-(" << c[0] << "))^2+(y-(" << c[1] << "))^2+(z-("
            << c[2] << "))^2)-" << grading.radius << ")";
          f << grading.fine_size << "+" << grading.growth << "*(" << r.str()
            << "+Sqrt(" << r.str() << "^2))/2";
          const int field = gmsh::model::mesh::field::add("MathEval");
          gmsh::model::mesh::field::setString(field, "F", f.str());
          gmsh::model::mesh::field::setAsBackgroundMesh(field);
        }
      gmsh::option::setNumber("Mesh.MeshSizeMax", h);
      gmsh::option::setNumber("Mesh.MeshSizeFromPoints", 0);
      gmsh::option::setNumber("Mesh.MeshSizeFromCurvature", 0);
      gmsh::option::setNumber("Mesh.MeshSizeExtendFromBoundary", 0);
      gmsh::option::setNumber("Mesh.Algorithm",
                              6);                     // Frontal-Delaunay
      gmsh::option::setNumber("Mesh.Algorithm3D", 1); // Delaunay
      gmsh::option::setNumber("Mesh.Optimize", 1);
    }



    /** The counts of the mesh Gmsh made at element size @p h. */
    Pass
    counts_of_mesh(const double h)
    {
      std::size_t              nodes = 0, tets = 0, triangles = 0;
      std::vector<std::size_t> tags;
      std::vector<double>      coords, parametric;
      gmsh::model::mesh::getNodes(tags, coords, parametric);
      std::vector<int>                      types;
      std::vector<std::vector<std::size_t>> elements, enodes;
      gmsh::model::mesh::getElements(types, elements, enodes, 3);
      nodes = tags.size();
      tets  = 0;
      for (std::size_t k = 0; k < types.size(); ++k)
        if (types[k] == 4)
          tets += elements[k].size();
      gmsh::model::mesh::getElements(types, elements, enodes, 2);
      triangles = 0;
      for (std::size_t k = 0; k < types.size(); ++k)
        if (types[k] == 2)
          triangles += elements[k].size();
      return {h, nodes, tets, triangles};
    }



    /**
     * One attempt to mesh @p s at element size @p h, classified at
     * @p angle degrees: its counts in @p result, and the mesh written to
     * @p out if @p is_best says it is the best so far. False (with Gmsh's
     * error in @p last_error) if Gmsh fails.
     */
    bool
    mesh_attempt(const Surface                          &s,
                 const double                            angle,
                 const double                            h,
                 const MeshGrading                      &grading,
                 const std::string                      &out,
                 const std::function<bool(std::size_t)> &is_best,
                 Pass                                   &result,
                 std::string                            &last_error)
    {
      bool meshed = false;
      gmsh::initialize();
      gmsh::option::setNumber("General.Terminal", 0);
      gmsh::option::setNumber("General.NumThreads", 1);
      gmsh::logger::start();
      try
        {
          add_body(s, angle);
          set_sizes(h, grading);
          gmsh::model::mesh::generate(3);
          result = counts_of_mesh(h);
          if (result.tetrahedra == 0)
            throw std::runtime_error("Gmsh made no tetrahedra");
          // Only the pass closest to the target is kept: a later
          // pass can land farther off than an earlier one.
          if (is_best(result.nodes))
            {
              gmsh::option::setNumber("Mesh.MshFileVersion", 2.2);
              gmsh::option::setNumber("Mesh.Binary", 0);
              // Written aside and renamed: a child killed while
              // writing leaves the last complete mesh in @p out.
              gmsh::write(out + ".pass.msh");
              std::rename((out + ".pass.msh").c_str(), out.c_str());
            }
          meshed = true;
        }
      catch (...)
        {
          std::string error;
          gmsh::logger::getLastError(error);
          last_error = error.empty() ? "Gmsh failed" : error;
        }
      gmsh::logger::stop();
      gmsh::finalize();
      return meshed;
    }



    /**
     * Tell the parent through @p progress_fd that the best mesh so far,
     * @p best, is in the output file.
     */
    void
    report_pass(const int          progress_fd,
                const Pass        &best,
                const unsigned int attempts,
                const unsigned int passes,
                const bool         within)
    {
      std::ostringstream r;
      r.precision(17);
      r << "PASS " << best.nodes << ' ' << best.tetrahedra << ' '
        << best.triangles << ' ' << best.h << ' ' << attempts << ' ' << passes
        << ' ' << within << " 1\n";
      const std::string line = r.str();
      if (::write(progress_fd, line.data(), line.size()) < 0)
        {} // the parent is gone: nothing to tell
    }



    /**
     * The meshing itself, in the child process: Gmsh's STL-remeshing
     * workflow (its tutorial t13). The triangles become one discrete
     * surface; classifySurfaces() splits it into patches that can be
     * parametrised (a closed surface cannot be mapped to a plane in one
     * piece); createGeometry() builds the parametrisations; the patches
     * bound a volume, and the mesher remeshes the patches at the target
     * size and fills the volume. Classification at 180 degrees (no
     * sharp-edge curves) suits smooth organs; if Gmsh cannot parametrise
     * the patches it makes, smaller angles give it more, smaller ones.
     *
     * A uniform mesh is made again at a corrected size until its node
     * count is within target_nodes_tolerance of @p target (at most
     * max_passes meshings, and none that would likely overrun
     * @p time_limit); the pass closest to the target is the one written
     * to @p out. Returns "nodes tets triangles size attempts passes
     * within stopped_by_time", or "ERROR message".
     */
    std::string
    mesh_in_child(const Surface     &s,
                  const unsigned int target,
                  const std::string &out,
                  const MeshGrading &grading,
                  const double       time_limit,
                  const int          progress_fd)
    {
      const auto   start  = Clock::now();
      const double volume = s.volume();
      // Nodes of a Delaunay mesh with sizes in [h/2, h]: about V / (0.8 h^3)
      // (measured on the liver surfaces; within 10 % from 750 to 2,000
      // nodes, but 13 % too few at 4,000, where a smaller share of the
      // nodes lies on the surface). The passes below correct it; a mesh it
      // already gets within 10 % stays as it was. A graded mesh keeps this
      // size as its coarse size: the target names a uniform mesh's count.
      double       h = std::cbrt(volume / (0.8 * std::max(target, 10u)));
      std::string  last_error;
      unsigned int attempts = 0;
      const bool   graded   = grading.fine_size > 0;
      // A pass costs 0.1-2 s on a liver of up to 8,000 nodes. On the
      // shipped livers the second pass lands every count tried from 500 to
      // 8,000 within 6 %; four leave room for surfaces where Gmsh's count
      // jumps with the size.
      const unsigned int max_passes = graded ? 1 : 4;
      Pass               best;
      unsigned int       passes          = 0;
      bool               stopped_by_time = false;
      const auto         off             = [&](const std::size_t nodes) {
        return std::abs(double(nodes) / target - 1);
      };
      for (unsigned int pass = 0; pass < max_passes; ++pass)
        {
          const auto pass_start = Clock::now();
          bool       meshed     = false;
          Pass       this_pass;
          for (const double angle : {180., 60., 40., 20.})
            {
              ++attempts;
              meshed = mesh_attempt(
                s,
                angle,
                h,
                grading,
                out,
                [&](const std::size_t nodes) {
                  return best.nodes == 0 || off(nodes) < off(best.nodes);
                },
                this_pass,
                last_error);
              if (meshed)
                break;
            }
          if (!meshed)
            {
              // A correction pass that fails (a finer surface can show a
              // fold a coarser one smoothed) leaves the best mesh so far.
              if (best.nodes > 0)
                break;
              return "ERROR " + last_error;
            }
          ++passes;
          const double seconds =
            std::chrono::duration<double>(Clock::now() - pass_start).count();
          if (best.nodes == 0 || off(this_pass.nodes) < off(best.nodes))
            best = this_pass;
          // The best mesh so far is in @p out: say so at once, so that if
          // the next pass overruns the time limit and the parent kills this
          // process, the parent keeps this one instead of failing.
          report_pass(progress_fd,
                      best,
                      attempts,
                      passes,
                      off(best.nodes) <= target_nodes_tolerance);
          if (off(best.nodes) <= target_nodes_tolerance ||
              pass + 1 == max_passes)
            break;
          // Mesh again at the corrected size, unless that pass would
          // likely not finish in time: its cost grows with its nodes (by
          // the count it aims at), and the child is killed at the limit.
          const double next_h = corrected_size(this_pass, target);
          const double elapsed =
            std::chrono::duration<double>(Clock::now() - start).count();
          const double next_seconds =
            1.5 * seconds * std::max(1., double(target) / this_pass.nodes);
          if (elapsed + next_seconds > 0.8 * time_limit)
            {
              stopped_by_time = true;
              break;
            }
          h = next_h;
        }
      std::ostringstream r;
      r.precision(17);
      r << best.nodes << ' ' << best.tetrahedra << ' ' << best.triangles << ' '
        << best.h << ' ' << attempts << ' ' << passes << ' '
        << (off(best.nodes) <= target_nodes_tolerance) << ' '
        << stopped_by_time;
      return r.str();
    }
  } // namespace



  namespace
  {
    /**
     * The child's side of mesh_volume(): mesh, report through the pipe
     * @p channel, leave without running the parent's atexit handlers (MPI,
     * deal.II). It dies with the parent (@p parent), however the parent
     * ends.
     */
    [[noreturn]] void
    mesh_in_child_and_exit(const pid_t        parent,
                           const Surface     &surface,
                           const unsigned int target_nodes,
                           const std::string &tmp,
                           const MeshGrading &grading,
                           const double       time_limit,
                           const int          channel[2])
    {
      ::prctl(PR_SET_PDEATHSIG, SIGKILL);
      if (::getppid() != parent)
        ::_exit(1);
      ::close(channel[0]);
      std::string report;
      try
        {
          report = mesh_in_child(
            surface, target_nodes, tmp, grading, time_limit, channel[1]);
        }
      catch (const std::exception &e)
        {
          report = std::string("ERROR ") + e.what();
        }
      catch (...)
        {
          report = "ERROR Gmsh failed";
        }
      std::size_t written = 0;
      while (written < report.size())
        {
          const auto n = ::write(channel[1],
                                 report.data() + written,
                                 report.size() - written);
          if (n <= 0)
            break;
          written += n;
        }
      ::close(channel[1]);
      ::_exit(0);
    }



    /**
     * The parent's wait for the meshing child @p child, at most
     * @p time_limit seconds from @p start: whether it finished (exited)
     * rather than being killed at the limit. A stop request kills it and
     * removes its files (@p tmp), then throws StoppedError.
     */
    bool
    wait_for_child(const pid_t             child,
                   const Clock::time_point start,
                   const double            time_limit,
                   const int               from_child,
                   const std::string      &tmp,
                   const std::string      &surface_name)
    {
      bool finished = false;
      while (true)
        {
          int         status = 0;
          const pid_t done   = ::waitpid(child, &status, WNOHANG);
          if (done == child)
            {
              finished = WIFEXITED(status);
              break;
            }
          if (std::chrono::duration<double>(Clock::now() - start).count() >
              time_limit)
            {
              ::kill(child, SIGKILL);
              ::waitpid(child, &status, 0);
              break;
            }
          // Ctrl-C or kill: the child goes, and its files with it (left
          // alone, it meshes on after palpate has ended and leaves a
          // temporary file of megabytes behind).
          if (StopRequest::pending())
            {
              ::kill(child, SIGKILL);
              ::waitpid(child, &status, 0);
              ::close(from_child);
              std::error_code ec;
              std::filesystem::remove(tmp, ec);
              std::filesystem::remove(tmp + ".pass.msh", ec);
              throw StoppedError("meshing '" + surface_name + "'");
            }
          std::this_thread::sleep_for(std::chrono::milliseconds(10));
        }
      return finished;
    }
  } // namespace



  VolumeMeshing
  mesh_volume(const Surface     &surface,
              const unsigned int target_nodes,
              const double       time_limit,
              const std::string &out_msh,
              const std::string &surface_name,
              const MeshGrading &grading)
  {
    const auto        start = Clock::now();
    const std::string tmp =
      out_msh + ".tmp-" + std::to_string(::getpid()) + ".msh";

    int channel[2];
    if (::pipe(channel) != 0)
      throw std::runtime_error(std::string("pipe: ") + std::strerror(errno));
    std::fflush(nullptr);
    const pid_t parent = ::getpid();
    const pid_t child  = ::fork();
    if (child < 0)
      throw std::runtime_error(std::string("fork: ") + std::strerror(errno));
    if (child == 0)
      mesh_in_child_and_exit(
        parent, surface, target_nodes, tmp, grading, time_limit, channel);

    // The parent: wait for the report, at most time_limit seconds.
    ::close(channel[1]);
    std::string report;
    bool        finished =
      wait_for_child(child, start, time_limit, channel[0], tmp, surface_name);
    {
      char buffer[4096];
      // The pipe holds everything the child wrote (far less than its
      // capacity), so reading after it ended cannot block.
      ssize_t n;
      while ((n = ::read(channel[0], buffer, sizeof(buffer))) > 0)
        report.append(buffer, n);
      ::close(channel[0]);
    }
    const double seconds =
      std::chrono::duration<double>(Clock::now() - start).count();
    const auto fail = [&](const std::string &problem, const std::string &fix) {
      std::error_code ec;
      std::filesystem::remove(tmp, ec);
      std::filesystem::remove(tmp + ".pass.msh", ec);
      return InputError(surface_name, 0, "surface", problem, fix);
    };
    // Killed while a correction pass overran the limit: the last pass the
    // child reported is in the file, and good enough to keep.
    if (!finished)
      if (const auto at = report.rfind("PASS "); at != std::string::npos)
        {
          report   = report.substr(at + 5);
          finished = true;
        }
    // A finished child's last line is its report.
    if (finished)
      if (const auto at = report.rfind("\n"); at != std::string::npos)
        {
          if (at + 1 < report.size())
            report = report.substr(at + 1);
          else if (const auto pass = report.rfind("PASS ");
                   pass != std::string::npos)
            report = report.substr(pass + 5);
        }
    if (!finished || report.empty())
      throw fail("meshing did not finish within the time limit of " +
                   Utilities::to_string(time_limit, 3) +
                   " s (Gmsh was "
                   "stopped after " +
                   Utilities::to_string(seconds, 3) + " s)",
                 "ask for fewer nodes (palpate mesh --nodes, Mesh / Surface / "
                 "Target nodes), allow more time (--time-limit, Mesh / "
                 "Surface / Time limit), or simplify the surface.");
    if (report.rfind("ERROR ", 0) == 0)
      throw fail(
        "Gmsh could not mesh the surface: " + report.substr(6) +
          (report.find("intersect") != std::string::npos ?
             " (the surface intersects itself where the remeshed surface "
             "is finer than the fold)" :
             ""),
        "check the surface for self-intersections and folds (palpate mesh "
        "reports them; MeshLab: Filters > Cleaning and Repairing > Select "
        "Self Intersecting Faces); fewer nodes give a coarser surface that "
        "smooths small folds away.");
    VolumeMeshing      result;
    std::istringstream in(report);
    in >> result.nodes >> result.tetrahedra >> result.surface_triangles >>
      result.size >> result.attempts >> result.passes >>
      result.target_nodes_met >> result.stopped_by_time_limit;
    result.target_nodes = target_nodes;
    result.graded       = grading.fine_size > 0;
    result.seconds      = seconds;
    std::filesystem::rename(tmp, out_msh);
    return result;
  }



  std::string
  unit_advice(const double size, const double factor)
  {
    if (size >= Limits::min_organ_size && size <= Limits::max_organ_size)
      return "";
    // The file's own size, and the units that would make it an organ.
    const double                          file_size = size / factor;
    const std::pair<double, const char *> units[]   = {{0.001, "millimetres"},
                                                       {0.01, "centimetres"},
                                                       {1, "metres"}};
    for (const auto &[unit, name] : units)
      if (file_size * unit >= Limits::min_organ_size &&
          file_size * unit <= Limits::max_organ_size)
        return std::string("it looks like ") + name + ": set " +
               Utilities::to_string(unit, 3) + " (the body is then " +
               Utilities::to_string(file_size * unit, 3) + " m across)";
    // A factor --scale takes, or none: a surface of zero extent would be
    // told "set inf", and one at 1e150 a factor like 1.443e-151.
    const double liver = factor * 0.25 / size;
    if (!(liver >= 1e-9 && liver <= 1e9))
      return "no scale factor from 1e-9 to 1e9 makes it an organ (the "
             "surface spans " +
             Utilities::to_string(file_size, 3) +
             " file units): check that the file holds the organ's surface";
    return "for the body to be 0.25 m across (a liver), set " +
           Utilities::to_string(liver, 4);
  }



  std::vector<std::string>
  SurfaceMeshReport::lines() const
  {
    std::vector<std::string> l;
    l.push_back("surface:       " + format + ", " + std::to_string(vertices) +
                " vertices, " + std::to_string(triangles) + " triangles, " +
                Utilities::to_string(box[1][0] - box[0][0], 3) + " x " +
                Utilities::to_string(box[1][1] - box[0][1], 3) + " x " +
                Utilities::to_string(box[1][2] - box[0][2], 3) + " m");
    const auto r = repairs.lines();
    if (r.empty())
      l.push_back("repairs:       none needed");
    for (std::size_t k = 0; k < r.size(); ++k)
      l.push_back((k == 0 ? "repairs:       " : "               ") + r[k]);
    l.push_back("closed:        yes, volume " +
                Utilities::to_string(volume * 1e6, 4) + " cm^3");
    l.push_back("intersections: " +
                (self_intersections == 0 ?
                   std::string("none") :
                   std::to_string(self_intersections) +
                     " pairs of triangles cross (the first near (" +
                     Utilities::to_string(intersection, 4) +
                     ") m); the remeshed surface crosses nowhere (checked)"));
    l.push_back("volume mesh:   " + std::to_string(meshing.nodes) + " nodes, " +
                std::to_string(meshing.tetrahedra) + " tetrahedra, " +
                std::to_string(meshing.surface_triangles) +
                " boundary triangles (boundary id 1), element size " +
                Utilities::to_string(meshing.size * 1000, 3) + " mm, volume " +
                Utilities::to_string(mesh_volume * 1e6, 4) + " cm^3 (" +
                Utilities::to_string(100 * (mesh_volume / volume - 1), 2) +
                " % against the surface)");
    l.push_back("meshing:       Gmsh " + std::string(GMSH_API_VERSION) + ", " +
                Utilities::to_string(meshing.seconds, 3) + " s, " +
                std::to_string(meshing.attempts) + " attempt" +
                (meshing.attempts > 1 ? "s" : ""));
    if (!meshing.graded && !meshing.target_nodes_met &&
        meshing.target_nodes > 0)
      {
        const double off = 100. * meshing.nodes / meshing.target_nodes - 100;
        l.push_back(
          "warning:       " + std::to_string(meshing.nodes) + " nodes, " +
          Utilities::to_string(std::abs(off), 2) + " % " +
          (off < 0 ? "fewer" : "more") + " than the " +
          std::to_string(meshing.target_nodes) + " asked for: " +
          (meshing.stopped_by_time_limit ?
             "another correction of the element size would likely have "
             "overrun the time limit (--time-limit, Mesh / Surface / Time "
             "limit)" :
             std::to_string(meshing.passes) +
               " meshings at corrected element sizes did not come within " +
               Utilities::to_string(100 * target_nodes_tolerance, 2) +
               " % (Gmsh's count does not follow the size smoothly on this "
               "surface)") +
          ". The closest is kept; if the count matters, ask for a "
          "somewhat different one" +
          (meshing.stopped_by_time_limit ? " or allow more time" : "") + ".");
      }
    l.push_back("quality:       " + quality.summary());
    if (!quality.slivers.empty())
      l.push_back("warning:       " + std::to_string(quality.slivers.size()) +
                  " slivers (flat tetrahedra, usually at sharp edges of a "
                  "coarse surface): their strains are unreliable. The scene "
                  "report says if they lie near the active node; smoothing the "
                  "surface's sharp edges (or another node count) may remove "
                  "them.");
    return l;
  }



  namespace
  {
    /**
     * That the surface @p s, read at @p scale (the entry @p scale_entry
     * sets it), has sizes an organ has: no overflow, no wild vertex, a
     * size within the scenes' limits (Limits::body_size_problem(); @p
     * report: its measures).
     */
    void
    check_surface_size(const Surface           &s,
                       const SurfaceMeshReport &report,
                       const std::string       &surface_file,
                       const double             scale,
                       const std::string       &scale_entry)
    {
      // Coordinates so large that their distances overflow (every one
      // times 1e300): no vertex is the outlier, and the outlier check below
      // would name a healthy one.
      if (!std::isfinite(report.diameter))
        throw InputError(surface_file,
                         0,
                         scale_entry + " = " + Utilities::to_string(scale, 6),
                         "the surface's coordinates reach " +
                           Utilities::to_string(
                             Utilities::scaled(report.box[1], 1 / scale), 3) +
                           " (file units): the distances between them overflow",
                         "check the file: it is corrupted or in a unit no "
                         "scale factor from 1e-9 to 1e9 can make an organ of.");
      // One wild vertex (1e308) is not a unit mistake: name it, rather than
      // advise a scale factor of 0.
      if (const long far = far_outlier(s.vertices); far >= 0)
        throw InputError(surface_file,
                         0,
                         "vertex " + std::to_string(far + 1),
                         "the vertex at (" +
                           Utilities::to_string(
                             Utilities::scaled(s.vertices[far], 1 / scale), 6) +
                           ") (file units) lies more than 1000 times farther "
                           "from the surface's centre than the median vertex: "
                           "a mistyped or corrupted coordinate",
                         "correct that vertex in the file, or export the "
                         "surface again.");
      // A body outside the scenes' limits is a unit mistake (refused with
      // the same words as a scene's mesh; unit_advice() says which unit).
      if (!(report.diameter >= Limits::min_body_size &&
            report.diameter <= Limits::max_body_size))
        throw InputError(surface_file,
                         0,
                         scale_entry + " = " + Utilities::to_string(scale, 6),
                         "with this scale factor " +
                           Limits::body_size_problem(report.diameter),
                         unit_advice(report.diameter, scale) + ".");
    }



    /**
     * That the refinement @p grading, if there is one, is centred within
     * its radius of the surface's bounding box @p box.
     */
    void
    check_refinement_centre(const std::array<Utilities::Point3, 2> &box,
                            const MeshGrading                      &grading,
                            const std::string &surface_file,
                            const std::string &scale_entry)
    {
      // A refinement centred far from the organ refines nothing, silently
      // (--refine 100,0,0 beside a 25 cm liver gives the uniform mesh):
      // the centre must lie within its radius of the bounding box.
      if (grading.fine_size > 0)
        {
          double outside = 0;
          for (unsigned int d = 0; d < 3; ++d)
            outside = std::hypot(outside,
                                 std::max({box[0][d] - grading.center[d],
                                           grading.center[d] - box[1][d],
                                           0.0}));
          if (!(outside <= grading.radius))
            throw InputError(
              scale_entry.rfind("--", 0) == 0 ? "command line" : surface_file,
              0,
              scale_entry.rfind("--", 0) == 0 ?
                "--refine " + Utilities::to_string(grading.center, 6) :
                "Boundary conditions / Active node / Point = " +
                  Utilities::to_string(grading.center, 6) +
                  " (the centre of Mesh / Surface / Refinement)",
              "the refinement's centre is " + Utilities::to_string(outside, 3) +
                " m outside the surface's bounding box (" +
                Utilities::to_string(box[0], 3) + " to " +
                Utilities::to_string(box[1], 3) +
                " m), farther than its radius (" +
                Utilities::to_string(grading.radius, 3) +
                " m): it would refine nothing",
              "give the point where the probe touches, in metres (after "
              "--scale), e.g. a vertex of the surface.");
        }
    }



    /**
     * That the boundary of the volume mesh @p data (written to @p out_msh,
     * removed if not) does not cross itself.
     */
    void
    check_remeshed_boundary(const MeshData    &data,
                            const std::string &out_msh,
                            const std::string &surface_file)
    {
      // The remeshed boundary must not cross itself: a fold larger than
      // the elements survives remeshing, and Gmsh's volume mesh of it
      // would not be the organ.
      Surface boundary;
      boundary.vertices  = data.nodes;
      boundary.triangles = data.triangles;
      Utilities::Point3 where;
      if (const unsigned int n = count_self_intersections(boundary, where);
          n > 0)
        {
          std::error_code ec;
          std::filesystem::remove(out_msh, ec);
          throw InputError(
            surface_file,
            0,
            "surface",
            "the surface intersects itself: " + std::to_string(n) +
              " pairs of triangles of the remeshed surface cross (near (" +
              Utilities::to_string(where, 4) + ") m)",
            "remove the fold or self-intersection in your segmentation tool "
            "(MeshLab: Filters > Cleaning and Repairing > Select Self "
            "Intersecting Faces, then delete and close the hole), or ask for "
            "fewer nodes: a coarser surface smooths small folds away.");
        }
    }
  } // namespace



  SurfaceMeshReport
  mesh_surface_file(const std::string &surface_file,
                    const double       scale,
                    const std::string &scale_entry,
                    const unsigned int target_nodes,
                    const double       time_limit,
                    const std::string &out_msh,
                    const MeshGrading &grading)
  {
    SurfaceMeshReport report;
    Surface           s = read_surface(surface_file, scale);
    report.format       = s.format;
    report.vertices     = s.vertices.size();
    report.triangles    = s.triangles.size();
    report.diameter     = s.diameter();
    report.box          = s.bounding_box();
    report.area         = s.area();
    check_surface_size(s, report, surface_file, scale, scale_entry);
    check_refinement_centre(report.box, grading, surface_file, scale_entry);
    report.repairs = repair_surface(s, surface_file);
    report.volume  = s.volume();
    // A closed surface that encloses (next to) nothing: a flat or folded
    // shell. The mesher would try for the whole time limit and then blame
    // the node count.
    if (!(std::abs(report.volume) >= 1e-6 * std::pow(report.diameter, 3)))
      throw InputError(surface_file,
                       0,
                       "surface",
                       "the surface encloses " +
                         Utilities::to_string(std::abs(report.volume), 3) +
                         " m^3, nothing next to a body " +
                         Utilities::to_string(report.diameter, 3) +
                         " m across: it is flat or folded onto itself",
                       "export the organ's closed outer surface (a solid, "
                       "not a sheet).");
    report.self_intersections =
      count_self_intersections(s, report.intersection);
    report.meshing =
      mesh_volume(s, target_nodes, time_limit, out_msh, surface_file, grading);
    const MeshData data = read_mesh_file(out_msh);
    report.quality      = mesh_quality(data.nodes, data.tetrahedra);
    check_remeshed_boundary(data, out_msh, surface_file);
    for (const auto &t : data.tetrahedra)
      {
        using namespace Utilities;
        const auto &x = data.nodes;
        report.mesh_volume += std::abs(dot(minus(x[t[1]], x[t[0]]),
                                           cross(minus(x[t[2]], x[t[0]]),
                                                 minus(x[t[3]], x[t[0]])))) /
                              6;
      }
    return report;
  }
} // namespace palpate
