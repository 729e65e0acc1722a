// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

#include <palpate/app/live_server.h>
#include <palpate/app/live_server_impl.h>
#include <palpate/haptics/run_summary.h>

#include <chrono>
#include <iomanip>
#include <sstream>
#include <thread>

namespace palpate
{
  LiveServer::LiveServer(const Scene       &scene,
                         const std::string &host,
                         const int          port,
                         const double       max_speed,
                         std::ostream      *log)
    : impl(std::make_unique<Impl>(scene, max_speed, log))
  {
    Impl &s = *impl;
    s.guard_requests();
    s.add_reads();
    s.add_device_requests();
    // On-the-fly changes (the paper's): a material constant, as
    // "ENTRY=VALUE" of the scene's model; another active node, as "node N"
    // (N as the mesh file numbers it, as the scene's Active node / Node id
    // and the scene report do) or as the point "x,y,z" (m, mesh
    // coordinates) whose nearest surface node it becomes.
    s.add_material_change();
    s.add_active_node_change();
    s.limit_connections();
    s.listen(host, port);
    s.interaction.attach();
    // The browser's mouse runs in the common haptic loop, as every device
    // does (real-time priority, statistics, force log), until the view
    // stops.
    s.loop = std::make_unique<HapticLoop>(
      s.interaction, s.device, s.rate, HapticLoop::continuous, s.force_log);
    s.loop->start(HapticLoop::continuous);
    s.loop->start_motion();
    s.http = std::thread([&s] { s.server.listen_after_bind(); });
    // Listening before the constructor returns: a stop() right after it
    // (standard output closed, so the view ends at once) that finds
    // cpp-httplib not listening yet stops nothing, and then waits for ever
    // for the thread, which serves on with every signal ignored.
    for (int k = 0; k < 10000 && !s.server.is_running(); ++k)
      std::this_thread::sleep_for(std::chrono::microseconds(500));
  }



  LiveServer::~LiveServer()
  {
    stop();
  }



  void
  LiveServer::stop()
  {
    Impl &s = *impl;
    if (!s.running.exchange(false))
      return;
    s.server.stop();
    if (s.http.joinable())
      s.http.join();
    if (s.loop)
      s.loop->join();
    s.interaction.detach();
  }



  int
  LiveServer::port() const
  {
    return impl->bound;
  }



  const std::string &
  LiveServer::token() const
  {
    return impl->token;
  }



  const std::string &
  LiveServer::address() const
  {
    return impl->address;
  }



  std::vector<std::string>
  LiveServer::accepted_hosts() const
  {
    return {impl->hosts.begin(), impl->hosts.end()};
  }



  std::vector<LiveServer::Change>
  LiveServer::changes() const
  {
    std::lock_guard<std::mutex> lock(impl->record_mutex);
    return impl->changes;
  }



  std::map<std::string, unsigned int>
  LiveServer::refused() const
  {
    std::lock_guard<std::mutex> lock(impl->record_mutex);
    return impl->refusals;
  }



  void
  LiveServer::print_summary(std::ostream &out) const
  {
    Impl &s = *impl;
    // The material and the active node now, under the lock changes take.
    std::string material, active;
    {
      std::lock_guard<std::mutex> lock(s.control_mutex);
      material = s.material_description();
      active   = s.active_description();
    }
    const auto         made    = changes();
    const auto         refusal = refused();
    std::ostringstream o;
    o << "Live view\n"
      << "  material:          " << material
      << (material == s.scene_material ?
            " (the scene's)" :
            " (the scene's: " + s.scene_material + ")")
      << "\n"
      << "  active node:       " << active
      << (active == s.scene_active ? " (the scene's)" :
                                     " (the scene's: " + s.scene_active + ")")
      << "\n"
      << "  changes:           ";
    if (made.empty())
      o << "none made through the view\n";
    else
      {
        o << made.size() << " made through the view, in order:\n";
        // A long list is cut: every change was printed as it was made.
        const std::size_t shown = 50;
        for (std::size_t i = 0; i < made.size(); ++i)
          if (i < shown || i == made.size() - 1)
            o << "    " << std::fixed << std::setprecision(1) << made[i].time
              << " s: " << made[i].what << "\n";
          else if (i == shown)
            o << "    ... " << made.size() - shown - 1
              << " more (printed above as they were made)\n";
      }
    unsigned int total = 0;
    for (const auto &[kind, count] : refusal)
      total += count;
    o << "  refused:           " << total << " requests";
    if (total > 0)
      {
        o << (refusal.count("malformed") > 0 ? " (403, malformed 400;" :
                                               " (403;")
          << " by what was wrong:";
        for (const auto &[kind, count] : refusal)
          o << " " << kind << " " << count
            << (&kind == &refusal.rbegin()->first ? ")" : ",");
      }
    o << "\n";
    out << o.str();
  }



  const Interaction &
  LiveServer::interaction() const
  {
    return impl->interaction;
  }



  std::size_t
  LiveServer::write_force_log(std::ostream &csv)
  {
    return impl->loop->drain_force_log(csv);
  }



  std::uint64_t
  LiveServer::force_log_dropped() const
  {
    return impl->loop->force_log_dropped();
  }



  void
  LiveServer::last(Utilities::Point3 &hip, Utilities::Point3 &force) const
  {
    hip   = impl->device.hip();
    force = impl->device.force();
  }



  void
  LiveServer::add_to(RunSummary &summary) const
  {
    impl->loop->add_to(summary);
    summary.trajectory = impl->device.description();
  }

} // namespace palpate
