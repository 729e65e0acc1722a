// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

// A cluster of "hosts" on one Linux machine, for running the MPI engine
// across a real network stack (benchmarks/run network and the test
// tests/network/mpi_partition): each host is a network namespace with one
// Ethernet interface (eth0, 10.77.0.11, .12, ...), and mpirun runs in a
// namespace of its own (10.77.0.1), as on a head node. Open MPI's TCP
// transport carries every message between the ranks, and a launcher that
// enters a host's namespace takes the place of ssh.
//
// The hosts' interfaces are TAP devices whose other ends are held by a
// switch in this process: it forwards every Ethernet frame to the port of
// its destination after a fixed one-way delay, losing a given fraction of
// them, and can cut one port in the middle of a run (a partition). This is
// what `tc qdisc ... netem delay D loss P` on veth links would do; the
// switch does it in user space because netem is not in every kernel (not
// in this machine's). It runs at real-time priority (SCHED_FIFO 70, below
// the haptic loop's 80), so that the solvers' load does not delay frames,
// as it would not on a real network; the run reports how late it delivered
// them.
//
// Everything a cluster creates (namespaces, interfaces, processes in them,
// a temporary directory) is removed when it is destroyed, and also when the
// program gets SIGINT, SIGTERM or SIGHUP (call remove_on_signals() first
// thing in main()); namespaces a killed run left behind are removed by the
// next one. It must run as root: why_not() says why it cannot run here.

#ifndef palpate_benchmarks_netns_cluster_h
#define palpate_benchmarks_netns_cluster_h

#include <fcntl.h>
#include <linux/if.h>
#include <linux/if_tun.h>
#include <poll.h>
#include <pthread.h>
#include <sched.h>
#include <signal.h>
#include <sys/ioctl.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <deque>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iomanip>
#include <iostream>
#include <mutex>
#include <optional>
#include <random>
#include <set>
#include <sstream>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

extern char **environ;

namespace netns_cluster
{
  using Clock = std::chrono::steady_clock;

  /** Run @p command with sh, its output discarded; its exit status. */
  inline int
  quietly(const std::string &command)
  {
    const int s = std::system((command + " >/dev/null 2>&1").c_str());
    return WIFEXITED(s) ? WEXITSTATUS(s) : 128;
  }

  /** Run @p command with sh; its standard output and error. */
  inline std::string
  output_of(const std::string &command, int *status = nullptr)
  {
    FILE *pipe = popen((command + " 2>&1").c_str(), "r");
    if (pipe == nullptr)
      throw std::runtime_error("cannot run " + command);
    std::string            out;
    std::array<char, 4096> buffer;
    std::size_t            n;
    while ((n = fread(buffer.data(), 1, buffer.size(), pipe)) > 0)
      out.append(buffer.data(), n);
    const int s = pclose(pipe);
    if (status != nullptr)
      *status = WIFEXITED(s) ? WEXITSTATUS(s) : 128;
    return out;
  }

  /** @p text without its trailing newlines. */
  inline std::string
  chomp(std::string text)
  {
    while (!text.empty() && (text.back() == '\n' || text.back() == '\r'))
      text.pop_back();
    return text;
  }

  /** The names of this program's namespaces start with this. */
  inline const std::string name_prefix = "palnet";

  /**
   * Kill every process in the network namespace @p ns (a namespace whose
   * name is removed lives on while a process is in it) and remove it.
   */
  inline void
  remove_namespace(const std::string &ns)
  {
    for (int round = 0; round < 20; ++round)
      {
        const std::string pids =
          chomp(output_of("ip netns pids " + ns + " 2>/dev/null"));
        if (pids.empty())
          break;
        std::istringstream words(pids);
        for (pid_t pid; words >> pid;)
          kill(pid, SIGKILL);
        std::this_thread::sleep_for(std::chrono::milliseconds(50));
      }
    quietly("ip netns del " + ns);
  }

  /** Whether process @p pid is gone. */
  inline bool
  gone(const pid_t pid)
  {
    return pid > 0 && pid != getpid() && kill(pid, 0) != 0 && errno == ESRCH;
  }

  /**
   * Remove the namespaces and temporary directories that runs of this
   * program which no longer exist left behind (killed with SIGKILL, say):
   * their names carry their process ids.
   */
  inline void
  remove_stale_namespaces()
  {
    std::error_code error;
    for (const auto &entry : std::filesystem::directory_iterator("/tmp", error))
      {
        const std::string name = entry.path().filename().string();
        if (name.rfind("palpate-netns-", 0) == 0 &&
            gone(std::atoi(name.c_str() + 14)))
          std::filesystem::remove_all(entry.path(), error);
      }
    std::istringstream lines(output_of("ip netns list 2>/dev/null"));
    for (std::string line; std::getline(lines, line);)
      {
        const std::string ns = line.substr(0, line.find(' '));
        if (ns.rfind(name_prefix, 0) != 0)
          continue;
        if (gone(std::atoi(ns.c_str() + name_prefix.size())))
          remove_namespace(ns);
      }
  }

  /**
   * Why a namespace cluster cannot run here, or an empty string if it can:
   * it needs root (CAP_SYS_ADMIN for `ip netns add`, CAP_NET_ADMIN for the
   * interfaces), iproute2, Open MPI's mpirun, unshare (util-linux) and
   * /dev/net/tun. It tries them in a namespace of its own.
   */
  inline std::string
  why_not()
  {
    const std::string fix =
      " A namespace cluster needs root with CAP_SYS_ADMIN and CAP_NET_ADMIN "
      "(in a container: --privileged, or --cap-add SYS_ADMIN --cap-add "
      "NET_ADMIN --device /dev/net/tun), iproute2, util-linux and Open MPI.";
    if (geteuid() != 0)
      return "it must run as root (this is uid " + std::to_string(geteuid()) +
             ")." + fix;
    for (const char *tool : {"ip", "mpirun", "unshare"})
      if (quietly(std::string("command -v ") + tool) != 0)
        return std::string("'") + tool + "' is not installed." + fix;
    const std::string probe = name_prefix + std::to_string(getpid()) + "-probe";
    int               status = 0;
    const std::string out = chomp(output_of("ip netns add " + probe, &status));
    if (status != 0)
      return "'ip netns add' is not permitted here: " + out + "." + fix;
    std::string why;
    const int   tun = open("/dev/net/tun", O_RDWR);
    if (tun < 0)
      why = std::string("/dev/net/tun cannot be opened: ") + strerror(errno) +
            "." + fix;
    else
      close(tun);
    remove_namespace(probe);
    return why;
  }



  /** How the network between the hosts behaves. */
  struct Network
  {
    /** Hosts, one rank each: rank r runs on host r + 1. */
    unsigned int hosts = 3;
    /** One-way delay of every frame (s); a round trip takes twice this. */
    double delay = 0;
    /** Fraction of the frames lost, 0 to 1. */
    double loss = 0;
  };

  /** A link cut in the middle of a run. */
  struct Partition
  {
    /** The rank whose host is cut off. */
    unsigned int rank = 2;
    /** Cut once a line of the run's output contains this ("" at once)... */
    std::string when;
    /** ... and this long after it (s). */
    double after = 0;
    /**
     * true: the host's link goes down (`ip link set eth0 down` on the
     * host); false: the switch drops every frame to and from it (netem
     * loss 100 %), the link stays up.
     */
    bool link_down = true;
  };

  /** How to run a program on the cluster. */
  struct RunOptions
  {
    /** A link to cut during the run, if any. */
    std::optional<Partition> partition;
    /** Gets every line of the output as it comes, if set. */
    std::function<void(const std::string &)> line;
    /**
     * Once rank 0 has ended, how long mpirun may take to end (s). Open MPI
     * 4.1's mpirun waits for every rank, and a partitioned rank never
     * hears that the run is over (nor does mpirun hear of it when its
     * host's processes are killed, under --enable-recovery): then mpirun
     * gets SIGTERM, as a user would press Ctrl-C, and 1 s later every
     * process of the run is killed.
     */
    double linger = 5;
    /** After this long (s; 0: no limit) every process of the run is
     * killed. */
    double time_limit = 0;
  };

  /** What a run on the cluster gave. */
  struct Run
  {
    std::string output;
    int         mpirun_status = -1;
    /** Each rank's exit status (-1: none recorded, e.g. killed). */
    std::vector<int> rank_status;
    /** When the link was cut, since the run started (s; -1 never). */
    double cut_at = -1;
    /** Seconds from the start to the line Partition::when (-1 never). */
    double when_at = -1;
    /** When rank 0 ended, since the run started (s; -1 never seen). */
    double rank0_ended_at = -1;
    /** How mpirun ended: "by itself", "after SIGTERM" (RunOptions::linger),
     * "killed" (1 s after SIGTERM), "at the time limit". */
    std::string mpirun_ended = "by itself";
    /** The whole run (s). */
    double seconds = 0;
  };

  /** Frames the switch handled, and how late it delivered them. */
  struct SwitchCounts
  {
    std::uint64_t frames = 0, lost = 0, cut = 0;
    /** Delivery after the due time (s): the largest, and how many frames
     * were more than 0.1, 1 and 10 ms late. */
    double        latest     = 0;
    std::uint64_t late_0_1ms = 0, late_1ms = 0, late_10ms = 0;
  };



  namespace internal
  {
    inline std::timed_mutex      registry_mutex;
    inline std::atomic<pid_t>    running_child{0};
    inline std::atomic<bool>     interrupted{false};
    inline std::set<std::string> live_namespaces, live_directories;

    /**
     * Kill the running mpirun and every process in the namespaces, remove
     * the namespaces and the temporary directories.
     */
    inline void
    remove_everything()
    {
      // Whoever holds the lock (a cluster being removed) is given 2 s.
      std::unique_lock<std::timed_mutex> lock(registry_mutex,
                                              std::chrono::seconds(2));
      if (const pid_t child = running_child.load(); child > 0)
        kill(-child, SIGKILL);
      for (const auto &ns : live_namespaces)
        remove_namespace(ns);
      live_namespaces.clear();
      for (const auto &d : live_directories)
        std::filesystem::remove_all(d);
      live_directories.clear();
    }

    /** While the signal thread removes everything, other threads wait
     * here for it to end the program. */
    inline void
    wait_if_interrupted()
    {
      while (interrupted)
        std::this_thread::sleep_for(std::chrono::seconds(1));
    }
  } // namespace internal

  /**
   * Remove every cluster's namespaces when this program gets SIGINT,
   * SIGTERM or SIGHUP, then exit with 128 + the signal; and when it ends
   * by an uncaught exception (std::terminate). Call it first thing in
   * main(), before any thread starts: it blocks these signals in this
   * thread and every thread started later, and waits for them in a thread
   * of its own. (Processes started by Cluster::run() get them unblocked.)
   */
  inline void
  remove_on_signals()
  {
    sigset_t set;
    sigemptyset(&set);
    sigaddset(&set, SIGINT);
    sigaddset(&set, SIGTERM);
    sigaddset(&set, SIGHUP);
    pthread_sigmask(SIG_BLOCK, &set, nullptr);
    std::thread([set] {
      int signal = 0;
      sigwait(&set, &signal);
      // From here on the other threads stop where they notice it (at the
      // end of a run, at exit): nothing may end the program before the
      // namespaces are gone.
      internal::interrupted = true;
      std::cerr << "\nnetwork cluster: " << strsignal(signal)
                << ": removing the namespaces" << std::endl;
      internal::remove_everything();
      std::_Exit(128 + signal);
    }).detach();
    std::atexit(internal::wait_if_interrupted);
    std::set_terminate([] {
      internal::wait_if_interrupted();
      internal::remove_everything();
      std::abort();
    });
  }



  /**
   * The cluster: built by the constructor, removed by the destructor. Not
   * copyable; one run at a time.
   */
  class Cluster
  {
  public:
    explicit Cluster(const Network &network)
      : network(network)
      , prefix(name_prefix + std::to_string(getpid()) + "x" +
               std::to_string(next_number()) + "-")
      , cut_port(network.hosts + 1)
    {
      remove_stale_namespaces();
      std::string pattern =
        "/tmp/palpate-netns-" + std::to_string(getpid()) + "-XXXXXX";
      if (mkdtemp(pattern.data()) == nullptr)
        throw std::runtime_error("cannot make a temporary directory");
      directory = pattern;
      {
        std::lock_guard<std::timed_mutex> lock(internal::registry_mutex);
        internal::live_directories.insert(directory);
      }
      try
        {
          build();
        }
      catch (...)
        {
          remove();
          throw;
        }
      switch_thread = std::thread([this] { switch_frames(); });
    }

    Cluster(const Cluster &) = delete;
    Cluster &
    operator=(const Cluster &) = delete;

    ~Cluster()
    {
      remove();
    }

    /** The namespace of host @p h (1..hosts; 0: mpirun's). */
    std::string
    namespace_of(const unsigned int h) const
    {
      return prefix + (h == 0 ? std::string("head") : "h" + std::to_string(h));
    }

    /** The address of host @p h (0: mpirun's). */
    static std::string
    address_of(const unsigned int h)
    {
      return "10.77.0." + std::to_string(h == 0 ? 1 : 10 + h);
    }

    /**
     * Run @p program with @p arguments under mpirun, one rank per host
     * (each through a wrapper that keeps its exit status), as @p options
     * say. Throws if mpirun cannot be started.
     */
    Run
    run(const std::string              &program,
        const std::vector<std::string> &arguments,
        const RunOptions               &options = {})
    {
      for (unsigned int r = 0; r < network.hosts; ++r)
        std::filesystem::remove(directory + "/rank-" + std::to_string(r) +
                                ".status");
      restore_all();

      std::vector<std::string> argv = {
        "ip",
        "netns",
        "exec",
        namespace_of(0),
        "mpirun",
        "--allow-run-as-root",
        "--oversubscribe",
        "--enable-recovery",
        "-np",
        std::to_string(network.hosts),
        "--hostfile",
        directory + "/hostfile",
        // Each host's daemon is started by the launcher, not by another
        // daemon (which would run it from inside a namespace).
        "--mca",
        "plm_rsh_agent",
        directory + "/launcher",
        "--mca",
        "plm_rsh_no_tree_spawn",
        "1",
        // TCP between the ranks (the hosts share this machine's memory,
        // but not as far as Open MPI knows: each is a node of its own).
        "--mca",
        "pml",
        "ob1",
        "--mca",
        "btl",
        "tcp,self",
        "--mca",
        "btl_tcp_if_include",
        "10.77.0.0/24",
        "--mca",
        "oob_tcp_if_include",
        "10.77.0.0/24",
        directory + "/keep-status",
        program};
      argv.insert(argv.end(), arguments.begin(), arguments.end());

      int pipe_ends[2];
      if (pipe(pipe_ends) != 0)
        throw std::runtime_error("cannot make a pipe");
      const auto  start = Clock::now();
      const pid_t child = fork();
      if (child < 0)
        throw std::runtime_error("cannot fork");
      if (child == 0)
        {
          // mpirun in a process group of its own, with the signals this
          // program keeps for itself unblocked, and without the variables
          // of an MPI job this program may be part of.
          setpgid(0, 0);
          sigset_t none;
          sigemptyset(&none);
          sigprocmask(SIG_SETMASK, &none, nullptr);
          dup2(pipe_ends[1], 1);
          dup2(pipe_ends[1], 2);
          close(pipe_ends[0]);
          close(pipe_ends[1]);
          std::vector<std::string> keep;
          for (char **e = environ; *e != nullptr; ++e)
            {
              const std::string v(*e);
              if ((v.rfind("OMPI_", 0) == 0 || v.rfind("PMIX_", 0) == 0) &&
                  v.rfind("OMPI_ALLOW_RUN_AS_ROOT", 0) != 0)
                keep.push_back(v.substr(0, v.find('=')));
            }
          for (const auto &name : keep)
            unsetenv(name.c_str());
          std::vector<char *> c;
          for (auto &a : argv)
            c.push_back(a.data());
          c.push_back(nullptr);
          execvp(c[0], c.data());
          _exit(127);
        }
      internal::running_child = child;
      close(pipe_ends[1]);

      Run               result;
      std::atomic<bool> done{false};
      std::mutex        m;
      std::atomic<bool> seen{false};
      bool              cut = false, killed = false;
      // The partition, and the end of a run whose mpirun lingers, on their
      // own clock.
      std::thread watcher([&] {
        std::optional<Clock::time_point> rank0_ended, terminated;
        const auto                      &partition = options.partition;
        while (!done)
          {
            std::this_thread::sleep_for(std::chrono::milliseconds(20));
            const auto   now = Clock::now();
            const double t = std::chrono::duration<double>(now - start).count();
            if (partition && !cut && (partition->when.empty() || seen) &&
                t - std::max(0.0, result.when_at) >= partition->after)
              {
                cut_off(partition->rank + 1, partition->link_down);
                result.cut_at =
                  std::chrono::duration<double>(Clock::now() - start).count();
                cut = true;
              }
            if (!rank0_ended &&
                std::filesystem::exists(directory + "/rank-0.status"))
              {
                rank0_ended = now;
                std::lock_guard<std::mutex> lock(m);
                result.rank0_ended_at = t;
              }
            if (rank0_ended && !terminated &&
                std::chrono::duration<double>(now - *rank0_ended).count() >
                  options.linger)
              {
                kill(-child, SIGTERM);
                terminated = now;
                std::lock_guard<std::mutex> lock(m);
                result.mpirun_ended = "after SIGTERM";
              }
            const bool overdue =
              (terminated &&
               std::chrono::duration<double>(now - *terminated).count() > 1) ||
              (options.time_limit > 0 && t > options.time_limit);
            if (overdue && !killed)
              {
                {
                  std::lock_guard<std::mutex> lock(m);
                  result.mpirun_ended =
                    terminated ? "killed" : "at the time limit";
                }
                kill(-child, SIGKILL);
                for (unsigned int h = 0; h <= network.hosts; ++h)
                  kill_processes(h);
                killed = true;
              }
          }
      });

      FILE       *in = fdopen(pipe_ends[0], "r");
      std::string current;
      for (int c; (c = fgetc(in)) != EOF;)
        {
          if (c != '\n')
            {
              current += static_cast<char>(c);
              continue;
            }
          {
            std::lock_guard<std::mutex> lock(m);
            result.output += current + "\n";
          }
          if (options.partition && !seen && !options.partition->when.empty() &&
              current.find(options.partition->when) != std::string::npos)
            {
              result.when_at =
                std::chrono::duration<double>(Clock::now() - start).count();
              seen = true;
            }
          if (options.line)
            options.line(current);
          current.clear();
        }
      if (!current.empty())
        result.output += current;
      fclose(in);
      int status = 0;
      waitpid(child, &status, 0);
      internal::wait_if_interrupted();
      internal::running_child = 0;
      done                    = true;
      watcher.join();
      result.seconds =
        std::chrono::duration<double>(Clock::now() - start).count();
      result.mpirun_status = WIFEXITED(status) ? WEXITSTATUS(status) : 128;
      for (unsigned int r = 0; r < network.hosts; ++r)
        {
          std::ifstream f(directory + "/rank-" + std::to_string(r) + ".status");
          int           s = -1;
          f >> s;
          result.rank_status.push_back(f ? s : -1);
        }
      // Whatever a partitioned host still runs ends with the run.
      for (unsigned int h = 1; h <= network.hosts; ++h)
        kill_processes(h);
      restore_all();
      return result;
    }

    /** The frames so far. */
    SwitchCounts
    counts() const
    {
      std::lock_guard<std::mutex> lock(counts_mutex);
      return switch_counts;
    }

    /** A temporary directory of this cluster, removed with it. */
    const std::string &
    work_directory() const
    {
      return directory;
    }

    /** A one-line description, e.g. "3 hosts, one-way delay 1 ms". */
    std::string
    description() const
    {
      std::ostringstream s;
      s << network.hosts << " hosts (network namespaces) and mpirun's, "
        << "one-way delay " << 1000 * network.delay << " ms, loss "
        << 100 * network.loss << " %";
      return s.str();
    }

  private:
    static unsigned int
    next_number()
    {
      static std::atomic<unsigned int> n{0};
      return n++;
    }

    /** Run an `ip` command; throws with its message if it fails. */
    static void
    ip(const std::string &arguments)
    {
      int               status = 0;
      const std::string out    = output_of("ip " + arguments, &status);
      if (status != 0)
        throw std::runtime_error("network cluster: 'ip " + arguments +
                                 "' failed: " + chomp(out));
    }

    /**
     * The namespaces and their interfaces: each namespace gets a TAP
     * device named eth0, made in the namespace by this thread (setns
     * changes only the calling thread's namespace), whose file descriptor
     * is a port of the switch.
     */
    void
    build()
    {
      const int home = open("/proc/thread-self/ns/net", O_RDONLY);
      if (home < 0)
        throw std::runtime_error("cannot open this thread's namespace");
      std::ofstream hostfile(directory + "/hostfile");
      std::string   cases;
      for (unsigned int h = 0; h <= network.hosts; ++h)
        {
          const std::string ns = namespace_of(h);
          ip("netns add " + ns);
          {
            std::lock_guard<std::timed_mutex> lock(internal::registry_mutex);
            internal::live_namespaces.insert(ns);
          }
          made.push_back(ns);
          const int there = open(("/run/netns/" + ns).c_str(), O_RDONLY);
          if (there < 0 || setns(there, CLONE_NEWNET) != 0)
            throw std::runtime_error("cannot enter namespace " + ns);
          close(there);
          const int tap = open("/dev/net/tun", O_RDWR | O_NONBLOCK);
          ifreq     request{};
          request.ifr_flags = IFF_TAP | IFF_NO_PI;
          std::strncpy(request.ifr_name, "eth0", IFNAMSIZ - 1);
          const bool made_tap =
            tap >= 0 && ioctl(tap, TUNSETIFF, &request) == 0;
          const int error = errno;
          setns(home, CLONE_NEWNET);
          if (!made_tap)
            throw std::runtime_error(
              std::string("cannot make a TAP interface: ") + strerror(error));
          ports.push_back(tap);
          std::ostringstream mac;
          mac << "02:50:00:00:00:" << std::hex << std::setw(2)
              << std::setfill('0') << h;
          mac_bytes.push_back(
            {{0x02, 0x50, 0, 0, 0, static_cast<unsigned char>(h)}});
          ip("-n " + ns + " link set lo up");
          // Jumbo frames, as a cluster's network has: fewer frames per
          // state transfer.
          ip("-n " + ns + " link set eth0 address " + mac.str() + " mtu 9000");
          ip("-n " + ns + " addr add " + address_of(h) + "/24 dev eth0");
          ip("-n " + ns + " link set eth0 up");
          if (h > 0)
            {
              hostfile << address_of(h) << " slots=1\n";
              cases += "  " + address_of(h) + ") ns=" + ns + "; name=host" +
                       std::to_string(h) + " ;;\n";
            }
        }
      close(home);
      hostfile.close();

      // The launcher mpirun calls in place of ssh: LAUNCHER HOST COMMAND...
      // runs the command in the host's namespace, with a host name and a
      // temporary directory of its own, as a separate machine has.
      {
        std::ofstream launcher(directory + "/launcher");
        launcher << "#!/bin/sh\n"
                 << "host=$1\nshift\ncase \"$host\" in\n"
                 << cases << "  *) echo \"launcher: unknown host $host\" >&2; "
                 << "exit 255 ;;\nesac\n"
                 << "mkdir -p " << directory << "/tmp-$name\n"
                 << "exec ip netns exec \"$ns\" env TMPDIR=" << directory
                 << "/tmp-$name unshare --uts sh -c \"hostname $name; $*\"\n";
      }
      // Each rank through this, which keeps its exit status.
      {
        std::ofstream keep(directory + "/keep-status");
        keep << "#!/bin/sh\n\"$@\"\ns=$?\necho $s >" << directory
             << "/rank-${OMPI_COMM_WORLD_RANK:-x}.status\nexit $s\n";
      }
      std::filesystem::permissions(directory + "/launcher",
                                   std::filesystem::perms::owner_all);
      std::filesystem::permissions(directory + "/keep-status",
                                   std::filesystem::perms::owner_all);
    }

    /** Cut host @p h's link (see Partition::link_down). */
    void
    cut_off(const unsigned int h, const bool link_down)
    {
      if (link_down)
        quietly("ip -n " + namespace_of(h) + " link set eth0 down");
      cut_port[h] = true;
    }

    void
    kill_processes(const unsigned int h)
    {
      const std::string pids =
        chomp(output_of("ip netns pids " + namespace_of(h) + " 2>/dev/null"));
      std::istringstream words(pids);
      for (pid_t pid; words >> pid;)
        kill(pid, SIGKILL);
    }

    void
    restore_all()
    {
      for (unsigned int h = 1; h <= network.hosts; ++h)
        if (cut_port[h])
          {
            quietly("ip -n " + namespace_of(h) + " link set eth0 up");
            cut_port[h] = false;
          }
    }

    void
    remove()
    {
      stop = true;
      if (switch_thread.joinable())
        switch_thread.join();
      for (const int fd : ports)
        close(fd);
      ports.clear();
      std::lock_guard<std::timed_mutex> lock(internal::registry_mutex);
      for (const auto &ns : made)
        {
          remove_namespace(ns);
          internal::live_namespaces.erase(ns);
        }
      made.clear();
      if (!directory.empty())
        std::filesystem::remove_all(directory);
      internal::live_directories.erase(directory);
    }

    /**
     * The switch: every frame read from a port is written to the port of
     * its destination address (every other port for broadcast, multicast
     * or an unknown address), network.delay after it arrived, unless it is
     * lost (network.loss) or its port or its destination's is cut.
     */
    void
    switch_frames()
    {
      sched_param priority{};
      priority.sched_priority = 70;
      pthread_setschedparam(pthread_self(), SCHED_FIFO, &priority);

      struct Frame
      {
        Clock::time_point due;
        unsigned int      from;
        int               to; // -1: every port but from
        std::vector<char> bytes;
      };
      std::deque<Frame>                      queue;
      std::mt19937_64                        random(12345);
      std::uniform_real_distribution<double> uniform(0, 1);
      const auto delay = std::chrono::duration_cast<Clock::duration>(
        std::chrono::duration<double>(network.delay));
      std::vector<pollfd> polled;
      for (const int fd : ports)
        polled.push_back({fd, POLLIN, 0});
      std::vector<char> buffer(65536);
      SwitchCounts      c;
      const auto        port_of = [&](const char *mac) {
        for (unsigned int p = 0; p < mac_bytes.size(); ++p)
          if (std::memcmp(mac, mac_bytes[p].data(), 6) == 0)
            return static_cast<int>(p);
        return -1;
      };
      const auto deliver = [&](const Frame &f) {
        for (unsigned int p = 0; p < ports.size(); ++p)
          if ((f.to < 0 ? p != f.from : static_cast<int>(p) == f.to) &&
              !cut_port[p])
            {
              // A port whose link is down refuses it: lost, as on a wire.
              [[maybe_unused]] const ssize_t n =
                write(ports[p], f.bytes.data(), f.bytes.size());
            }
      };
      unsigned int published = 0;
      while (!stop)
        {
          timespec timeout{0, 50000000}; // at most 50 ms, to see stop
          if (!queue.empty())
            {
              const auto wait = std::max(Clock::duration::zero(),
                                         queue.front().due - Clock::now());
              if (wait < std::chrono::milliseconds(50))
                {
                  const auto ns =
                    std::chrono::duration_cast<std::chrono::nanoseconds>(wait)
                      .count();
                  timeout = {static_cast<time_t>(ns / 1000000000),
                             static_cast<long>(ns % 1000000000)};
                }
            }
          if (ppoll(polled.data(), polled.size(), &timeout, nullptr) > 0)
            for (unsigned int p = 0; p < polled.size(); ++p)
              if (polled[p].revents & POLLIN)
                while (true)
                  {
                    const ssize_t n =
                      read(ports[p], buffer.data(), buffer.size());
                    if (n <= 0)
                      break;
                    if (n < 14)
                      continue;
                    ++c.frames;
                    const int to = port_of(buffer.data());
                    if (cut_port[p] || (to >= 0 && cut_port[to]))
                      {
                        ++c.cut;
                        continue;
                      }
                    if (network.loss > 0 && uniform(random) < network.loss)
                      {
                        ++c.lost;
                        continue;
                      }
                    queue.push_back(
                      {Clock::now() + delay,
                       p,
                       to,
                       std::vector<char>(buffer.begin(), buffer.begin() + n)});
                  }
          // Every frame that is due; constant delay keeps the queue in
          // order of due times.
          const auto now = Clock::now();
          while (!queue.empty() && queue.front().due <= now)
            {
              const double late =
                std::chrono::duration<double>(now - queue.front().due).count();
              c.latest = std::max(c.latest, late);
              c.late_0_1ms += late > 1e-4;
              c.late_1ms += late > 1e-3;
              c.late_10ms += late > 1e-2;
              deliver(queue.front());
              queue.pop_front();
            }
          if (++published % 64 == 0 || queue.empty())
            {
              std::lock_guard<std::mutex> lock(counts_mutex);
              switch_counts = c;
            }
        }
      std::lock_guard<std::mutex> lock(counts_mutex);
      switch_counts = c;
    }

    const Network                             network;
    const std::string                         prefix;
    std::string                               directory;
    std::vector<std::string>                  made;
    std::vector<int>                          ports;
    std::vector<std::atomic<bool>>            cut_port;
    std::vector<std::array<unsigned char, 6>> mac_bytes;
    std::atomic<bool>                         stop{false};
    std::thread                               switch_thread;
    mutable std::mutex                        counts_mutex;
    SwitchCounts                              switch_counts;
  };
} // namespace netns_cluster

#endif
