// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

// benchmarks/run network [--quick|--smoke] [--latency 0,1,5,20] [--loss 0,1]
//                        [--repeat 2] [--length CM] [--no-partition]
//                        [--drop]
//
// The MPI engine across a real network: `mpirun -np 3 palpate
// parameters/liver-stvk-mpi.prm` with each rank on a host of its own, the
// hosts being network namespaces of this machine joined by a switch that
// delays and loses frames (netns_cluster.h), with Open MPI's TCP transport
// between them. Must run as root; it says why and exits 1 if it cannot.
//
// 1. Stroke speed against latency: for each one-way delay (--latency, ms)
//    and loss rate (--loss, %), the largest speed at which the probe
//    strokes --length cm (8) along -x after the initial cloud with no
//    missing-data event, as benchmarks/run max-speed measures it: the
//    speed is doubled from 28 mm/s until a trial fails, then bisected to
//    10 %; a speed passes if --repeat trials (2) in a row pass. Every trial
//    is a whole `palpate` run on a fresh set of processes. --quick: 0, 1
//    and 5 ms without loss and 1 ms with 1 % loss, one trial per speed,
//    three speeds from 224 mm/s.
//
// 2. A partition (unless --no-partition): at 1 ms, a slow stroke (5 mm/s
//    for 16 s; --quick 3 s) whose server 2 is cut off 1 s into the motion
//    (its link goes down; --drop: the switch drops its frames instead).
//    The client must declare it lost after Engine / Server timeout (5 s;
//    --quick 1 s), go on with server 1, keep every force finite, and exit
//    with status 5 (doc/architecture.md, "Faults"). The benchmark reports
//    when the force came back after the cut (from the force log).
//
// --smoke (the test suite's): one trial at 28 mm/s, 0 ms and no loss, a
// stroke of 1 cm after a cloud of radius 18 mm (the least that holds a
// cell of its 10 mm grid), no partition. Where network namespaces are
// not permitted (not root, or a container without CAP_NET_ADMIN: most CI
// machines), the same trial runs under mpirun on this machine alone,
// without the switch (namespaces=no in its RESULT line): the palpate
// program, its summary and the table are still exercised.

#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include "machine.h"
#include "netns_cluster.h"
#include "report_errors.h"

namespace
{
  struct Options
  {
    bool                quick     = false;
    std::vector<double> latencies = {0, 1, 5, 20}; // ms
    std::vector<double> losses    = {0, 1};        // %
    double              length    = 0.08;          // m
    bool                partition = true;
    bool                drop      = false;
    /** Trials in a row a speed must pass. */
    unsigned int repeat = 2;
    bool         smoke  = false;
    /** --set arguments of every trial of the search, beyond the scene's. */
    std::vector<std::string> settings;
  };

  /** One palpate run on the cluster: its summary and exit status. */
  struct Trial
  {
    double                             speed  = 0; // m/s
    bool                               passed = false;
    std::map<std::string, std::string> summary;
    int                                status = -1;
    std::string                        failure;
    netns_cluster::Run                 run;
    /** The force log: motion time (s) and |f| (N), if asked for. */
    std::vector<std::pair<double, double>> forces;

    double
    number(const std::string &key) const
    {
      const auto i = summary.find(key);
      return i == summary.end() ? std::nan("") : std::atof(i->second.c_str());
    }
  };

  const std::string scene =
    std::string(PALPATE_SOURCE_DIR) + "/parameters/liver-stvk-mpi.prm";
  const std::string palpate_program =
    std::string(PALPATE_BINARY_DIR) + "/palpate";

  /** The key,value CSV summary palpate writes (Output / Summary formats). */
  std::map<std::string, std::string>
  read_summary(const std::string &file)
  {
    std::map<std::string, std::string> values;
    std::ifstream                      in(file);
    std::string                        line;
    std::getline(in, line); // key,value
    while (std::getline(in, line))
      {
        const auto comma = line.find(',');
        if (comma == std::string::npos)
          continue;
        std::string value = line.substr(comma + 1);
        if (value.size() >= 2 && value.front() == '"')
          value = value.substr(1, value.size() - 2);
        values[line.substr(0, comma)] = value;
      }
    return values;
  }

  /** palpate's arguments for a trial: the scene with the stroke at
   * @p speed for @p length, its output in @p directory, plus
   * @p settings. */
  std::vector<std::string>
  trial_arguments(const double                    speed,
                  const double                    length,
                  const std::string              &directory,
                  const std::vector<std::string> &settings)
  {
    std::ostringstream v, d;
    v << std::setprecision(9) << speed;
    d << std::setprecision(9) << length / speed;
    std::vector<std::string> arguments = {scene,
                                          "--set",
                                          "Haptics/Trajectory/Speed=" + v.str(),
                                          "--set",
                                          "Haptics/Trajectory/Duration=" +
                                            d.str(),
                                          "--set",
                                          "Output/Directory=" + directory,
                                          "--set",
                                          "Output/Summary formats=csv"};
    for (const auto &s : settings)
      {
        arguments.push_back("--set");
        arguments.push_back(s);
      }
    return arguments;
  }

  /** What the run @p t.run left in @p directory: its summary, its force
   * log, and whether it passed. */
  void
  read_trial(Trial &t, const std::string &directory)
  {
    t.status  = t.run.rank_status.empty() ? -1 : t.run.rank_status[0];
    t.summary = read_summary(directory + "/liver-stvk-mpi-summary.csv");
    {
      std::ifstream log(directory + "/liver-stvk-mpi-forces.csv");
      std::string   line;
      std::getline(log, line);
      double time, x, y, z, fx, fy, fz;
      char   c;
      while (log >> time >> c >> x >> c >> y >> c >> z >> c >> fx >> c >> fy >>
             c >> fz)
        t.forces.emplace_back(time, std::sqrt(fx * fx + fy * fy + fz * fz));
    }
    if (t.summary.empty())
      t.failure = "no summary (rank 0's status " + std::to_string(t.status) +
                  ", mpirun " + t.run.mpirun_ended + "); its output:\n" +
                  t.run.output;
    else if (t.summary["initial_cloud_complete"] != "true")
      t.failure = "the initial cloud was not complete";
    else if (t.summary["loop_truncated"] != "false")
      t.failure = "the haptic loop's statistics were truncated";
    else if (t.number("lost_servers") > 0)
      t.failure = "a server was lost";
    else if (t.number("server_hold_events") > 0)
      t.failure = "a server was silent (force held)";
    else if (t.number("missing_data_events") > 0)
      t.failure = "missing data";
    t.passed = t.failure.empty() && t.status == 0;
  }

  /**
   * One interaction, exactly as `mpirun -np 3 palpate liver-stvk-mpi.prm`
   * runs it, with the stroke at @p speed for @p length, the scene's other
   * settings as shipped plus @p settings.
   */
  Trial
  run_trial(netns_cluster::Cluster          &cluster,
            const double                     speed,
            const double                     length,
            const std::vector<std::string>  &settings = {},
            const netns_cluster::RunOptions &options  = {})
  {
    static unsigned int n = 0;
    const std::string   directory =
      cluster.work_directory() + "/trial-" + std::to_string(n++);
    Trial t;
    t.speed = speed;
    // A run that hangs ends after 3 minutes (a trial takes seconds).
    netns_cluster::RunOptions limited = options;
    if (limited.time_limit == 0)
      limited.time_limit = 180;
    t.run = cluster.run(palpate_program,
                        trial_arguments(speed, length, directory, settings),
                        limited);
    read_trial(t, directory);
    return t;
  }

  /**
   * The same interaction without network namespaces: `mpirun -np 3
   * palpate` on this machine alone (Open MPI between local processes, no
   * switch), in ./trial-local. For the smoke where namespaces are not
   * permitted.
   */
  Trial
  run_local_trial(const double                    speed,
                  const double                    length,
                  const std::vector<std::string> &settings)
  {
    const std::string directory =
      std::filesystem::absolute("trial-local").string();
    std::string command =
      "mpirun --oversubscribe" +
      std::string(geteuid() == 0 ? " --allow-run-as-root" : "") + " -np 3 '" +
      palpate_program + "'";
    for (const auto &a : trial_arguments(speed, length, directory, settings))
      command += " '" + a + "'";
    command += " 2>&1";
    Trial t;
    t.speed          = speed;
    const auto start = netns_cluster::Clock::now();
    if (FILE *pipe = popen(command.c_str(), "r"))
      {
        std::array<char, 4096> buffer;
        std::size_t            n;
        while ((n = fread(buffer.data(), 1, buffer.size(), pipe)) > 0)
          t.run.output.append(buffer.data(), n);
        const int status    = pclose(pipe);
        t.run.mpirun_status = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
        // mpirun's status is rank 0's when the others end with 0.
        t.run.rank_status = {t.run.mpirun_status};
      }
    t.run.seconds =
      std::chrono::duration<double>(netns_cluster::Clock::now() - start)
        .count();
    read_trial(t, directory);
    return t;
  }

  void
  print_trial(const Trial &t)
  {
    std::ostringstream s;
    s << std::fixed << "    " << std::setw(7) << std::setprecision(1)
      << 1000 * t.speed << " mm/s: " << (t.passed ? "pass" : "FAIL");
    if (t.summary.empty())
      s << ", " << t.failure;
    else
      s << ", " << t.number("missing_data_events") << " missing-data events ("
        << std::setprecision(3) << t.number("missing_data_seconds")
        << " s), initial cloud " << std::setprecision(1)
        << t.number("motion_start_s") << " s, " << std::setprecision(0)
        << t.number("states_computed") << " states, median "
        << std::setprecision(1) << t.number("median_state_ms")
        << " ms/state, transfers p50 " << t.number("transfer_p50_ms")
        << " ms max " << t.number("transfer_max_ms") << " ms, deadline misses "
        << std::setprecision(0) << t.number("deadline_misses")
        << (t.failure.empty() || t.failure == "missing data" ?
              "" :
              " (" + t.failure + ")");
    s << "; run " << std::setprecision(1) << t.run.seconds << " s";
    std::cout << s.str() << std::endl;
    // A server lost without a partition is news: say what the client said.
    std::istringstream lines(t.run.output);
    for (std::string line; std::getline(lines, line);)
      if (line.find("LOST:") != std::string::npos)
        std::cout << "      " << line << std::endl;
  }

  /**
   * The fastest passing trial: doubling, then bisection (as max-speed);
   * @p anomalies counts the trials that failed otherwise than by missing
   * data.
   */
  std::pair<Trial, unsigned int>
  search(netns_cluster::Cluster &cluster,
         const Options          &o,
         unsigned int           &anomalies)
  {
    const double precision = o.quick ? 1.4 : 1.10, max_speed = 1.0; // m/s
    Trial        best;
    double       low = 0, high = 0, v = o.quick ? 0.224 : 0.028;
    unsigned int trials = 0, stage = 0;
    // One trial at v; a failure that is not missing data (a server lost
    // or held without a partition, an initial cloud not complete) says
    // nothing about the speed: counted, and the trial run again once.
    const auto trial = [&](const double v) {
      Trial t = run_trial(cluster, v, o.length, o.settings);
      ++trials;
      print_trial(t);
      if (t.summary.empty())
        throw std::runtime_error(t.failure);
      if (!t.passed && t.failure != "missing data")
        {
          ++anomalies;
          std::cout << "      (" << t.failure << ": run again)" << std::endl;
          t = run_trial(cluster, v, o.length, o.settings);
          ++trials;
          print_trial(t);
          if (t.summary.empty())
            throw std::runtime_error(t.failure);
        }
      return t;
    };
    while (true)
      {
        // A speed passes if --repeat trials in a row pass.
        Trial t = trial(v);
        for (unsigned int r = 1; r < o.repeat && t.passed; ++r)
          t = trial(v);
        ++stage;
        if (t.passed)
          {
            low  = v;
            best = t;
          }
        else
          high = v;
        if ((o.quick && stage >= 3) || o.smoke)
          break;
        if (high == 0)
          {
            if (v >= max_speed)
              break;
            v = std::min(2 * v, max_speed);
          }
        else if (low == 0)
          {
            if (v < 0.002)
              break;
            v /= 2;
          }
        else if (high / low > precision)
          v = std::sqrt(low * high);
        else
          break;
      }
    return {best, trials};
  }

  std::string
  fixed(const double x, const int digits)
  {
    std::ostringstream s;
    s << std::fixed << std::setprecision(digits) << x;
    return s.str();
  }
} // namespace

namespace
{
  /** Everything the benchmark measures and prints. */
  int
  measure(const Options &o)
  {
    // The configurations: (one-way delay in ms, loss in %).
    std::vector<std::pair<double, double>> configurations;
    if (o.quick)
      configurations = {{0, 0}, {1, 0}, {5, 0}, {1, 1}};
    else
      for (const double loss : o.losses)
        for (const double latency : o.latencies)
          configurations.emplace_back(latency, loss);

    std::cout
      << "The MPI engine across a network: 1 client + 2 solver servers, each "
         "on a host of its own\n"
      << "  machine: " << machine() << "; the hosts are network namespaces\n"
      << "  network: a switch with a fixed one-way delay and a loss rate per "
         "frame (MTU 9000), Open MPI TCP (btl tcp,self)\n"
      << "  scene:   parameters/liver-stvk-mpi.prm (liver501, StVK, tricubic "
         "Hermite on 10 mm, cloud "
      << (o.smoke ? 18 : 25) << " mm), stroke of " << 100 * o.length
      << " cm along -x after the initial cloud"
      << (o.smoke ? "  [--smoke]" :
          o.quick ? "  [--quick]" :
                    "")
      << "\n";
    // How late this machine itself wakes a real-time thread (a virtual
    // machine's host may stall it): the switch's late frames and the
    // haptic loop's deadline misses are no better than this.
    if (!o.quick && !o.smoke)
      {
        const double seconds        = 10;
        const auto [misses, latest] = bare_loop(seconds, 1000);
        std::cout << "  platform timer noise: a bare SCHED_FIFO 1 kHz loop "
                     "misses "
                  << misses << " deadlines in " << seconds << " s (latest "
                  << fixed(1000 * latest, 2) << " ms late)\n";
      }
    std::cout << "\n";

    struct Row
    {
      double                      latency, loss;
      Trial                       t;
      unsigned int                trials, anomalies;
      netns_cluster::SwitchCounts frames;
    };
    std::vector<Row> rows;
    for (const auto &[latency, loss] : configurations)
      {
        std::cout << "one-way delay " << latency << " ms (round trip "
                  << 2 * latency << " ms), loss " << loss << " %:" << std::endl;
        netns_cluster::Cluster cluster({3, 1e-3 * latency, 1e-2 * loss});
        unsigned int           anomalies = 0;
        const auto [t, n]                = search(cluster, o, anomalies);
        rows.push_back({latency, loss, t, n, anomalies, cluster.counts()});
      }

    // The partition.
    std::optional<Row> partition;
    double             cut_in_motion = -1, back_after_cut = -1;
    // Whether the force faded to zero after the cut at all (held through
    // the loss, it does not: then there is nothing to come back).
    bool         faded   = false;
    const double timeout = o.quick ? 1 : 5, motion = o.quick ? 3 : 16;
    if (o.partition)
      {
        std::cout << "\none-way delay 1 ms, server 2 cut off ("
                  << (o.drop ? "the switch drops its frames" :
                               "its link goes down")
                  << ") 1 s into a 5 mm/s stroke of " << motion
                  << " s, Engine / Server timeout " << timeout
                  << " s:" << std::endl;
        netns_cluster::Cluster    cluster({3, 1e-3, 0});
        netns_cluster::RunOptions options;
        netns_cluster::Partition  cut;
        cut.rank          = 2;
        cut.when          = "; motion starts";
        cut.after         = 1;
        cut.link_down     = !o.drop;
        options.partition = cut;
        options.linger    = 0.5;
        // When the summary came (the cluster's clock: since the run began).
        const auto started    = netns_cluster::Clock::now();
        double     summary_at = -1;
        options.line          = [&](const std::string &line) {
          if (summary_at < 0 && line.find("Run summary") != std::string::npos)
            summary_at = std::chrono::duration<double>(
                           netns_cluster::Clock::now() - started)
                           .count();
        };
        const Trial t = run_trial(cluster,
                                  0.005,
                                  0.005 * motion,
                                  {"Engine/Server timeout=" + fixed(timeout, 0),
                                   "Effects/Force log=true"},
                                  options);
        if (t.summary.empty())
          throw std::runtime_error(t.failure);
        // The motion's clock starts at the line "motion starts" (the force
        // log counts from there); when the force came back after the cut.
        cut_in_motion = t.run.cut_at - t.run.when_at;
        faded         = false;
        for (const auto &[time, f] : t.forces)
          if (time > cut_in_motion)
            {
              if (f == 0)
                faded = true;
              else if (faded && back_after_cut < 0)
                back_after_cut = time - cut_in_motion;
            }
        std::istringstream lines(t.run.output);
        for (std::string line; std::getline(lines, line);)
          if (line.find("LOST:") != std::string::npos ||
              line.find("missing data") != std::string::npos ||
              line.find("held force") != std::string::npos ||
              line.find("motion:") != std::string::npos ||
              line.find("Exit status") != std::string::npos)
            std::cout << "  " << line << "\n";
        std::cout << "  cut " << fixed(cut_in_motion, 2)
                  << " s into the motion; the force "
                  << (back_after_cut >= 0 ?
                        "faded and came back " + fixed(back_after_cut, 2) +
                          " s after the cut" :
                        std::string("did not fade and come back"))
                  << "; the summary came "
                  << fixed(summary_at - t.run.when_at, 1)
                  << " s after the motion started, rank 0 ended "
                  << fixed(t.run.rank0_ended_at - summary_at, 1)
                  << " s after it, with status " << t.status
                  << "; mpirun ended " << t.run.mpirun_ended << "; run "
                  << fixed(t.run.seconds, 1) << " s" << std::endl;
        partition = Row{1, 0, t, 1, 0, cluster.counts()};
      }

    std::cout << "\n  one-way delay  loss  max speed (mm/s)  state (ms)  "
                 "transfer p50/max (ms)  deadline misses  frames  lost  "
                 "late > 1 ms  latest (ms)  trials\n";
    for (const auto &r : rows)
      std::cout << "  " << std::setw(10) << fixed(r.latency, 0) << " ms"
                << std::setw(4) << fixed(r.loss, 0) << " %" << std::setw(18)
                << fixed(1000 * r.t.speed, 1) << std::setw(12)
                << fixed(r.t.number("median_state_ms"), 1) << std::setw(23)
                << fixed(r.t.number("transfer_p50_ms"), 1) + " / " +
                     fixed(r.t.number("transfer_max_ms"), 1)
                << std::setw(17) << fixed(r.t.number("deadline_misses"), 0)
                << std::setw(8) << r.frames.frames << std::setw(6)
                << r.frames.lost << std::setw(13) << r.frames.late_1ms
                << std::setw(13) << fixed(1000 * r.frames.latest, 2)
                << std::setw(8) << r.trials << "\n";
    if (partition)
      {
        const Trial &t = partition->t;
        std::cout << "\n  partition: lost servers " << t.number("lost_servers")
                  << ", missing data " << t.number("missing_data_events")
                  << " events (" << fixed(t.number("missing_data_seconds"), 2)
                  << " s), non-finite forces " << t.number("non_finite_forces")
                  << ", rank 0's exit status " << t.status << "\n";
      }
    std::cout << "\n";

    for (const auto &r : rows)
      std::cout << "RESULT network latency_ms=" << fixed(r.latency, 0)
                << " loss_pct=" << fixed(r.loss, 0)
                << " speed_mm_s=" << fixed(1000 * r.t.speed, 1)
                << " missing=" << fixed(r.t.number("missing_data_events"), 0)
                << " lost_servers=" << fixed(r.t.number("lost_servers"), 0)
                << " state_ms=" << fixed(r.t.number("median_state_ms"), 1)
                << " transfer_max_ms="
                << fixed(r.t.number("transfer_max_ms"), 1)
                << " deadline_misses="
                << fixed(r.t.number("deadline_misses"), 0)
                << " frames_lost=" << r.frames.lost << " trials=" << r.trials
                << " anomalies=" << r.anomalies << "\n";
    if (partition)
      {
        const Trial &t = partition->t;
        std::cout << "RESULT network latency_ms=1 loss_pct=0 partition=server2"
                  << " cut=" << (o.drop ? "drop" : "link-down")
                  << " speed_mm_s=5.0"
                  << " missing=" << fixed(t.number("missing_data_events"), 0)
                  << " missing_s=" << fixed(t.number("missing_data_seconds"), 2)
                  << " lost_servers=" << fixed(t.number("lost_servers"), 0)
                  << " server_timeout_s=" << fixed(timeout, 0)
                  << " force_faded=" << (faded ? "yes" : "no")
                  << " force_back_after_cut_s="
                  << (!faded              ? std::string("0") :
                      back_after_cut >= 0 ? fixed(back_after_cut, 2) :
                                            std::string("never"))
                  << " non_finite=" << fixed(t.number("non_finite_forces"), 0)
                  << " status=" << t.status << " mpirun_ended="
                  << (t.run.mpirun_ended == "by itself"     ? "itself" :
                      t.run.mpirun_ended == "after SIGTERM" ? "sigterm" :
                      t.run.mpirun_ended == "killed"        ? "killed" :
                                                              "time-limit")
                  << "\n";
      }
    return 0;
  }

  /** The smoke where network namespaces are not permitted (@p why): the
   * trial of the smoke on this machine alone. */
  int
  smoke_without_namespaces(const Options &o, const std::string &why)
  {
    std::cout << "The MPI engine, 1 client + 2 solver servers on this machine "
                 "alone  [--smoke]\n"
              << "  machine: " << machine()
              << "\n  no network namespaces here (" << why
              << "): mpirun without the switch\n\n";
    const Trial t = run_local_trial(0.028, o.length, o.settings);
    print_trial(t);
    if (t.summary.empty())
      throw std::runtime_error(t.failure);
    std::cout << "\nRESULT network namespaces=no latency_ms=0 loss_pct=0"
              << " speed_mm_s=" << fixed(1000 * t.speed, 1)
              << " passed=" << (t.passed ? "yes" : "no")
              << " missing=" << fixed(t.number("missing_data_events"), 0)
              << " lost_servers=" << fixed(t.number("lost_servers"), 0)
              << " state_ms=" << fixed(t.number("median_state_ms"), 1)
              << " deadline_misses=" << fixed(t.number("deadline_misses"), 0)
              << "\n";
    return 0;
  }
} // namespace



static int
run_benchmark(int argc, char **argv)
{
  // Before any thread: SIGINT, SIGTERM, SIGHUP remove the namespaces.
  netns_cluster::remove_on_signals();
  Options o;
  for (int i = 1; i < argc; ++i)
    {
      const std::string a    = argv[i];
      const auto        list = [&]() {
        if (i + 1 >= argc)
          throw std::invalid_argument(a + " needs a value");
        std::vector<double> values;
        std::stringstream   s(argv[++i]);
        for (std::string x; std::getline(s, x, ',');)
          values.push_back(std::stod(x));
        return values;
      };
      if (a == "--quick")
        o.quick = true;
      else if (a == "--smoke")
        o.smoke = true;
      else if (a == "--latency")
        o.latencies = list();
      else if (a == "--loss")
        o.losses = list();
      else if (a == "--length")
        o.length = 0.01 * list().at(0);
      else if (a == "--repeat")
        {
          if (i + 1 >= argc)
            throw std::invalid_argument(a + " needs a value");
          o.repeat = whole_number(a, argv[++i], 1);
        }
      else if (a == "--no-partition")
        o.partition = false;
      else if (a == "--drop")
        o.drop = true;
      else
        {
          std::cerr
            << "network: unknown option " << a
            << "\nusage: benchmarks/run network [--quick|--smoke] [--latency "
               "0,1,5,20] [--loss 0,1] [--repeat 2] [--length CM] "
               "[--no-partition] [--drop]\n";
          return 2;
        }
    }
  if (o.quick)
    o.repeat = 1;
  if (o.smoke)
    {
      o.latencies = {0};
      o.losses    = {0};
      o.repeat    = 1;
      o.length    = 0.01;
      o.partition = false;
      o.settings  = {"Scheduler/Cloud radius=0.018"};
    }
  const std::string why = netns_cluster::why_not();
  if (!why.empty() && !o.smoke)
    {
      std::cerr << "benchmarks/run network: cannot run here: " << why
                << std::endl;
      return 1;
    }
  if (!std::filesystem::exists(palpate_program))
    {
      std::cerr << "benchmarks/run network: " << palpate_program
                << " is missing: cmake --build build --target palpate"
                << std::endl;
      return 1;
    }
  if (!why.empty())
    return smoke_without_namespaces(o, why);

  // An exception from measure() removes the clusters on its way out (each
  // one's destructor) and is reported by report_errors().
  return measure(o);
}



int
main(int argc, char **argv)
{
  return report_errors("network", run_benchmark, argc, argv);
}
