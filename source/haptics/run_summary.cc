// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

#include <palpate/base/utilities.h>
#include <palpate/haptics/run_summary.h>

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdint>
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
    /**
     * One summary entry. Tools read the summaries, so each value keeps its
     * kind: counts are exact integers (a double printed with six digits
     * turned 1440000 ticks into 1.44e+06), measurements are doubles that
     * may be NaN or infinite, and text may hold anything a path or a
     * trajectory name can.
     */
    struct Field
    {
      enum class Kind
      {
        text,
        count,
        real,
        boolean
      };

      std::string key;
      Kind        kind;
      std::string text;     // text: the string; count, boolean: the value
      double      real = 0; // real: the value
    };

    Field
    text(const std::string &key, const std::string &value)
    {
      return {key, Field::Kind::text, value};
    }

    Field
    count(const std::string &key, const std::uint64_t value)
    {
      return {key, Field::Kind::count, std::to_string(value)};
    }

    Field
    real(const std::string &key, const double value)
    {
      return {key, Field::Kind::real, "", value};
    }

    Field
    boolean(const std::string &key, const bool value)
    {
      return {key, Field::Kind::boolean, value ? "true" : "false"};
    }



    /** A JSON value: numbers bare, NaN and infinities null (JSON has no
     * such numbers), text escaped. */
    std::string
    json_value(const Field &f)
    {
      switch (f.kind)
        {
          case Field::Kind::text:
            return Utilities::json_string(f.text);
          case Field::Kind::real:
            return std::isfinite(f.real) ? Utilities::to_string_exact(f.real) :
                                           "null";
          default:
            return f.text;
        }
    }

    /**
     * A CSV field (RFC 4180): in double quotes, with quotes inside doubled;
     * line breaks may stay inside the quotes. Non-finite numbers are
     * written nan, inf and -inf: pandas.read_csv, numpy and Python's
     * float() read these as NaN and +-infinity (pandas counts "nan" among
     * its default missing values), and unlike an empty field they keep
     * "no value" and "infinite" apart.
     */
    std::string
    csv_value(const Field &f)
    {
      std::string value = f.text;
      if (f.kind == Field::Kind::real)
        value = std::isnan(f.real) ? "nan" :
                std::isinf(f.real) ? (f.real > 0 ? "inf" : "-inf") :
                                     Utilities::to_string_exact(f.real);
      std::string out = "\"";
      for (const char c : value)
        out += c == '"' ? std::string("\"\"") : std::string(1, c);
      return out + "\"";
    }

    /** Every field, in order, for CSV and JSON. */
    std::vector<Field>
    fields(const RunSummary &s)
    {
      return {text("scene", s.scene),
              text("engine", s.engine),
              text("trajectory", s.trajectory),
              count("states_computed", s.states_computed),
              count("states_failed", s.states_failed),
              count("tasks_dropped", s.tasks_dropped),
              count("tasks_cancelled", s.tasks_cancelled),
              count("results_discarded", s.results_discarded),
              count("solver_errors", s.solver_errors),
              real("median_state_ms", s.median_state_ms),
              real("worker_busy_fraction", s.worker_busy_fraction),
              count("messages", s.messages),
              count("bytes", s.bytes),
              count("local_sources", s.local_sources),
              count("fetched_sources", s.fetched_sources),
              count("states_to_client", s.states_to_client),
              real("transfer_p50_ms", s.transfer_p50_ms),
              real("transfer_max_ms", s.transfer_max_ms),
              count("lost_servers", s.lost_servers.size()),
              count("states_used", s.states_used),
              count("corner_reads", s.corner_reads),
              count("corner_hits", s.corner_hits),
              count("missing_data_events", s.missing_events),
              real("missing_data_seconds", s.missing_seconds),
              real("missing_data_patched_seconds", s.missing_patched_seconds),
              real("patched_farthest_m", s.patched_farthest),
              count("failure_region_events", s.failure_region_events),
              real("failure_region_seconds", s.failure_region_seconds),
              count("outside_events", s.outside_events),
              real("outside_seconds", s.outside_seconds),
              count("server_hold_events", s.server_hold_events),
              real("server_hold_seconds", s.server_hold_seconds),
              count("non_finite_forces", s.non_finite_forces),
              real("largest_force_N", s.largest_force),
              real("largest_force_change_N", s.largest_force_change),
              boolean("loop_ran", s.loop_ran),
              boolean("realtime_priority", s.realtime_priority),
              boolean("memory_locked", s.memory_locked),
              boolean("loop_truncated", s.loop_truncated),
              real("loop_rate_Hz", s.loop_rate),
              real("motion_start_s", s.motion_start),
              real("motion_duration_s", s.motion_duration),
              count("ticks", s.ticks),
              count("deadline_misses", s.deadline_misses),
              real("period_p50_ms", s.period_p50_ms),
              real("period_p99_ms", s.period_p99_ms),
              real("period_p999_ms", s.period_p999_ms),
              real("period_max_ms", s.period_max_ms),
              real("interpolation_p50_us", s.interpolation_p50_us),
              real("interpolation_p999_us", s.interpolation_p999_us),
              count("initial_cloud_states", s.initial_cloud_states),
              boolean("initial_cloud_complete", s.initial_cloud_complete),
              count("shape_frames", s.shape_frames),
              text("stopped_by", s.stopped_by)};
    }



    // RunSummary::print(), a step: the missing-data and held-force lines.
    void
    print_missing_data(const RunSummary &r, std::ostream &s)
    {
      s << "  missing data:      " << r.missing_events << " events, "
        << r.missing_seconds << " s in total";
      // The contact patches may have rendered the force while the states
      // were missing: then it did not fade, and the line says so.
      if (r.missing_patched_seconds > 0)
        s << " (" << r.missing_patched_seconds
          << " s of it rendered from the last complete cell's contact "
             "patches)";
      if (r.missing_events > 0 &&
          r.missing_seconds - r.missing_patched_seconds > 1e-3)
        s << "  <-- the force faded to zero then";
      s << "\n";
      if (r.failure_region_events + r.outside_events > 0)
        s << "  held force:        " << r.failure_region_events
          << " times in failure regions (" << r.failure_region_seconds
          << " s), " << r.outside_events << " times outside the state space ("
          << r.outside_seconds << " s)  <-- no state can exist there\n";
      if (r.patched_farthest > 0)
        s << "  patches beyond:    the last complete cell's contact patches "
             "answered for missing data up to "
          << 1000 * r.patched_farthest
          << " mm from where the data were last complete (their linear "
             "contact models, extrapolated)\n";
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
      << " queued tasks dropped (left the cloud), " << tasks_cancelled
      << " running states given up (the HIP moved away, preempted for a "
         "corner on its path, or a stop signal), "
      << results_discarded << " results discarded (parameters changed)\n"
      << "  cache:             " << corner_hits << " of " << corner_reads
      << " corner reads found a state\n";
    print_missing_data(*this, s);
    if (server_hold_events > 0)
      s << "  held force:        " << server_hold_events
        << " times while a solver server was silent or lost ("
        << server_hold_seconds << " s)  <-- its states were late\n";
    s << "  forces:            largest " << largest_force
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
      {
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
          << period_max_ms << " ms"
          << (statistics_window > 0 ?
                " (the last " + Utilities::to_string(statistics_window, 4) +
                  " s)" :
                std::string())
          << "\n"
          << "  deadline misses:   " << deadline_misses
          << " (ticks more than 0.5 ms late)\n"
          << "  interpolation:     p50 " << interpolation_p50_us
          << " us, p99.9 " << interpolation_p999_us << " us\n"
          << "  motion:            ";
        // A run stopped during the initial cloud never moved: not "started 0 s
        // after attach".
        if (motion_start < 0)
          s << "never started\n";
        else
          s << "started " << motion_start << " s after attach, lasted "
            << motion_duration << " s"
            << (loop_truncated ?
                  "  <-- cut short: the loop reached its time bound" :
                  "")
            << "\n";
      }
    if (shape_frames > 0)
      s << "  shape output:      " << shape_frames << " frames\n";
    if (!stopped_by.empty())
      s << "  STOPPED:           " << stopped_by
        << "; everything above is what ran until then\n";
    out << s.str();
  }



  void
  RunSummary::write_csv(const std::string &filename) const
  {
    std::ofstream out(filename);
    if (!out)
      throw std::runtime_error("cannot write '" + filename + "'");
    out << "key,value\n";
    for (const Field &f : fields(*this))
      out << f.key << "," << csv_value(f) << "\n";
    out.close();
    if (!out)
      throw std::runtime_error("'" + filename +
                               "' could not be written whole (is the disk "
                               "full?)");
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
      out << "  " << Utilities::json_string(f[i].key) << ": "
          << json_value(f[i]) << (i + 1 < f.size() ? "," : "") << "\n";
    out << "}\n";
    out.close();
    if (!out)
      throw std::runtime_error("'" + filename +
                               "' could not be written whole (is the disk "
                               "full?)");
  }
} // namespace palpate
