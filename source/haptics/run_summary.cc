// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

#include <palpate/haptics/run_summary.h>

#include <algorithm>
#include <fstream>
#include <iomanip>
#include <ostream>
#include <sstream>
#include <stdexcept>
#include <utility>
#include <vector>

namespace palpate
{
  namespace
  {
    std::string
    number(const double x)
    {
      std::ostringstream s;
      s << std::setprecision(6) << x;
      return s.str();
    }

    /** Every field as (key, value), in order, for CSV and JSON. */
    std::vector<std::pair<std::string, std::string>>
    fields(const RunSummary &s)
    {
      return {{"scene", s.scene},
              {"engine", s.engine},
              {"trajectory", s.trajectory},
              {"states_computed", number(s.states_computed)},
              {"states_failed", number(s.states_failed)},
              {"tasks_dropped", number(s.tasks_dropped)},
              {"results_discarded", number(s.results_discarded)},
              {"solver_errors", number(s.solver_errors)},
              {"median_state_ms", number(s.median_state_ms)},
              {"worker_busy_fraction", number(s.worker_busy_fraction)},
              {"messages", number(s.messages)},
              {"bytes", number(s.bytes)},
              {"local_sources", number(s.local_sources)},
              {"fetched_sources", number(s.fetched_sources)},
              {"states_to_client", number(s.states_to_client)},
              {"transfer_p50_ms", number(s.transfer_p50_ms)},
              {"transfer_max_ms", number(s.transfer_max_ms)},
              {"lost_servers", number(s.lost_servers.size())},
              {"states_used", number(s.states_used)},
              {"corner_reads", number(s.corner_reads)},
              {"corner_hits", number(s.corner_hits)},
              {"missing_data_events", number(s.missing_events)},
              {"missing_data_seconds", number(s.missing_seconds)},
              {"non_finite_forces", number(s.non_finite_forces)},
              {"largest_force_N", number(s.largest_force)},
              {"largest_force_change_N", number(s.largest_force_change)},
              {"loop_ran", s.loop_ran ? "true" : "false"},
              {"realtime_priority", s.realtime_priority ? "true" : "false"},
              {"memory_locked", s.memory_locked ? "true" : "false"},
              {"loop_truncated", s.loop_truncated ? "true" : "false"},
              {"loop_rate_Hz", number(s.loop_rate)},
              {"motion_start_s", number(s.motion_start)},
              {"motion_duration_s", number(s.motion_duration)},
              {"ticks", number(s.ticks)},
              {"deadline_misses", number(s.deadline_misses)},
              {"period_p50_ms", number(s.period_p50_ms)},
              {"period_p99_ms", number(s.period_p99_ms)},
              {"period_p999_ms", number(s.period_p999_ms)},
              {"period_max_ms", number(s.period_max_ms)},
              {"interpolation_p50_us", number(s.interpolation_p50_us)},
              {"interpolation_p999_us", number(s.interpolation_p999_us)},
              {"initial_cloud_states", number(s.initial_cloud_states)},
              {"initial_cloud_complete",
               s.initial_cloud_complete ? "true" : "false"},
              {"shape_frames", number(s.shape_frames)}};
    }
  } // namespace



  void
  RunSummary::print(std::ostream &out) const
  {
    std::ostringstream s;
    s << std::setprecision(4);
    s << "Run summary\n"
      << "  engine:            " << engine << "\n"
      << "  trajectory:        " << trajectory << "\n"
      << "  states:            " << states_computed << " computed, "
      << states_failed << " failure points, " << states_used
      << " used by the haptic loop; median " << median_state_ms
      << " ms per state, workers busy " << 100 * worker_busy_fraction
      << " % of the time\n"
      << "  scheduling:        " << tasks_dropped
      << " queued tasks dropped (left the cloud), " << results_discarded
      << " results discarded (parameters changed)\n"
      << "  cache:             " << corner_hits << " of " << corner_reads
      << " corner reads found a state\n"
      << "  missing data:      " << missing_events << " events, "
      << missing_seconds << " s in total"
      << (missing_events > 0 ? "  <-- the force faded to zero then" : "")
      << "\n"
      << "  forces:            largest " << largest_force
      << " N, largest change per tick " << largest_force_change
      << " N, non-finite " << non_finite_forces << "\n";
    if (messages > 0)
      {
        const double n = std::max(1u, states_computed + states_failed);
        s << "  messages:          " << messages / n << " per state, "
          << bytes / n << " bytes per state (all ranks)\n"
          << "  state transfers:   " << fetched_sources
          << " sources fetched from another server, " << local_sources
          << " found on the server that got the task; " << states_to_client
          << " states sent to the client (lazy: "
          << states_computed - std::min(states_computed, states_to_client)
          << " never sent); needed to arrived p50 " << transfer_p50_ms
          << " ms, max " << transfer_max_ms << " ms\n";
      }
    for (const auto &lost : lost_servers)
      s << "  LOST:              " << lost << "\n";
    if (solver_errors > 0)
      s << "  solver errors:     " << solver_errors
        << " solves threw (counted as failure points); the last: "
        << last_solver_error << "\n";
    if (loop_ran)
      s << "  haptic loop:       " << ticks << " ticks at " << loop_rate
        << " Hz, "
        << (realtime_priority ?
              "real-time priority (SCHED_FIFO)" :
              "normal priority (no real-time scheduling permitted)")
        << (memory_locked ? ", memory locked" :
                            ", memory not locked (page faults possible)")
        << "\n"
        << "  loop period:       p50 " << period_p50_ms << " ms, p99 "
        << period_p99_ms << " ms, p99.9 " << period_p999_ms << " ms, max "
        << period_max_ms << " ms\n"
        << "  deadline misses:   " << deadline_misses
        << " (ticks more than 0.5 ms late)\n"
        << "  interpolation:     p50 " << interpolation_p50_us << " us, p99.9 "
        << interpolation_p999_us << " us\n"
        << "  motion:            started " << motion_start
        << " s after attach, lasted " << motion_duration << " s"
        << (loop_truncated ?
              "  <-- cut short: the loop reached its time bound" :
              "")
        << "\n";
    if (shape_frames > 0)
      s << "  shape output:      " << shape_frames << " frames\n";
    out << s.str();
  }



  void
  RunSummary::write_csv(const std::string &filename) const
  {
    std::ofstream out(filename);
    if (!out)
      throw std::runtime_error("cannot write '" + filename + "'");
    out << "key,value\n";
    for (const auto &[k, v] : fields(*this))
      out << k << ",\"" << v << "\"\n";
  }



  void
  RunSummary::write_json(const std::string &filename) const
  {
    std::ofstream out(filename);
    if (!out)
      throw std::runtime_error("cannot write '" + filename + "'");
    const auto f = fields(*this);
    out << "{\n";
    for (std::size_t i = 0; i < f.size(); ++i)
      {
        const bool text = f[i].first == "scene" || f[i].first == "engine" ||
                          f[i].first == "trajectory";
        std::string value = f[i].second;
        if (text)
          {
            std::string escaped;
            for (const char c : value)
              escaped += (c == '"' || c == '\\') ? std::string("\\") + c :
                                                   std::string(1, c);
            value = "\"" + escaped + "\"";
          }
        out << "  \"" << f[i].first << "\": " << value
            << (i + 1 < f.size() ? "," : "") << "\n";
      }
    out << "}\n";
  }
} // namespace palpate
