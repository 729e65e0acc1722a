// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

#include <palpate/app/application.h>
#include <palpate/app/interaction_run.h>
#include <palpate/app/serve.h>
#include <palpate/base/exceptions.h>
#include <palpate/base/stop_request.h>
#include <palpate/engine/engine.h>
#include <palpate/haptics/haptic_loop.h>
#include <palpate/haptics/interaction.h>
#include <palpate/haptics/run_summary.h>
#include <palpate/haptics/shape_interpolator.h>
#include <palpate/haptics/target_follower.h>
#include <palpate/hyperelastic/hyperelastic_system.h>
#include <palpate/hyperelastic/material.h>
#include <palpate/mesh/mesh.h>
#include <palpate/mesh/node_selection.h>
#include <palpate/scene/scene.h>
#include <palpate/state_space/state_cache.h>
#include <palpate/state_space/state_grid.h>

#include <arpa/inet.h>
#include <httplib.h>
#include <ifaddrs.h>
#include <netdb.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cctype>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <condition_variable>
#include <cstdlib>
#include <cstring>
#include <deque>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iomanip>
#include <limits>
#include <map>
#include <mutex>
#include <optional>
#include <random>
#include <set>
#include <sstream>
#include <string_view>
#include <thread>
#include <utility>

namespace palpate
{
  namespace
  {
    /**
     * Why @p host : @p port cannot be listened on, blaming the right one:
     * a name that does not resolve or an address this machine does not
     * have is --host's fault, a port in use or reserved is --port's (the
     * server library only says "no").
     */
    InputError
    cannot_listen(const std::string &host, const int port)
    {
      const std::string where = host + ":" + std::to_string(port);
      addrinfo          hints{};
      hints.ai_family   = AF_UNSPEC;
      hints.ai_socktype = SOCK_STREAM;
      hints.ai_flags    = AI_PASSIVE;
      addrinfo *found   = nullptr;
      if (::getaddrinfo(
            host.c_str(), std::to_string(port).c_str(), &hints, &found) != 0 ||
          found == nullptr)
        return InputError("command line",
                          0,
                          "--host " + host,
                          "'" + host +
                            "' is not an address or a name this machine can "
                            "resolve",
                          "give one of this machine's addresses: 127.0.0.1 "
                          "(the default: this machine only), 0.0.0.0 (every "
                          "interface), or an interface's address (ip addr).");
      int error = 0;
      for (addrinfo *a = found; a != nullptr && error == 0; a = a->ai_next)
        {
          const int fd = ::socket(a->ai_family, a->ai_socktype, 0);
          if (fd < 0)
            continue;
          const int yes = 1;
          ::setsockopt(fd, SOL_SOCKET, SO_REUSEADDR, &yes, sizeof(yes));
          if (::bind(fd, a->ai_addr, a->ai_addrlen) != 0)
            error = errno;
          ::close(fd);
        }
      ::freeaddrinfo(found);
      if (error == EADDRNOTAVAIL)
        return InputError("command line",
                          0,
                          "--host " + host,
                          "'" + host + "' is not an address of this machine",
                          "give one of this machine's addresses: 127.0.0.1 "
                          "(the default), 0.0.0.0 (every interface), or an "
                          "interface's address (ip addr).");
      if (error == EACCES)
        return InputError("command line",
                          0,
                          "--port " + std::to_string(port),
                          "cannot listen on " + where +
                            ": ports below 1024 need privileges",
                          "choose a port from 1024 up, e.g. --port 8081.");
      return InputError("command line",
                        0,
                        "--port " + std::to_string(port),
                        "cannot listen on " + where +
                          (error == EADDRINUSE ?
                             ": another program uses the port" :
                             " (" + std::string(std::strerror(error)) + ")"),
                        "choose another port, e.g. --port " +
                          std::to_string(port == 65535 ? 8081 : port + 1) +
                          ".");
    }
  } // namespace



  /** The page (serve_page.cc): three.js draws the surface, the HIP and the
   * force; a drag on the organ moves the HIP in the view plane (with Alt,
   * in depth), other drags and the wheel turn, pan and zoom the view. */
  extern const char *const live_view_page;

  /** three.js, compiled in (live_view_assets.cc). */
  namespace live_view_assets
  {
    std::string_view
    three_core();
    std::string_view
    three_module();
    std::string_view
    orbit_controls();
  } // namespace live_view_assets

  namespace
  {
    using Clock = std::chrono::steady_clock;

    std::string
    json_array(const std::vector<double> &v, const unsigned int digits = 6)
    {
      std::ostringstream s;
      s.precision(digits);
      s << '[';
      for (std::size_t i = 0; i < v.size(); ++i)
        s << (i ? "," : "") << (std::isfinite(v[i]) ? v[i] : 0.0);
      s << ']';
      return s.str();
    }

    /** Runs @p f; returns "" if it succeeds, else why it was refused, as a
     * live view's change reports it: "problem (fix)" for bad input. */
    std::string
    refusal_of(const std::function<void()> &f)
    {
      try
        {
          f();
        }
      catch (const InputError &e)
        {
          return e.problem() + " (" + e.fix() + ")";
        }
      catch (const std::exception &e)
        {
          return *e.what() != '\0' ? e.what() : "refused (no reason given)";
        }
      return "";
    }

    std::string
    json_number(const double x)
    {
      std::ostringstream s;
      s.precision(4);
      s << (std::isfinite(x) ? x : 0.0);
      return s.str();
    }

    std::string
    json_point(const Utilities::Point3 &p)
    {
      return json_array({p[0], p[1], p[2]}, 17);
    }

    const char *
    cause_name(const MissingCause c)
    {
      switch (c)
        {
          case MissingCause::none:
            return "none";
          case MissingCause::not_computed:
            return "not computed yet";
          case MissingCause::failure_region:
            return "failure region";
          default:
            return "outside the state space";
        }
    }

    /** The outward unit normal of the surface at vertex @p v: the
     * area-weighted mean of the normals of the surface triangles around
     * it (Mesh orients them outward), or 0 if it is on none. */
    Utilities::Point3
    outward_normal(const Mesh &mesh, const unsigned int v)
    {
      const auto       &x = mesh.vertices();
      Utilities::Point3 n{{0, 0, 0}};
      for (const auto &face : mesh.surface_faces())
        {
          const auto &t = face.vertices;
          if (t[0] != v && t[1] != v && t[2] != v)
            continue;
          // Twice the area times the unit normal.
          const auto c = Utilities::cross(Utilities::minus(x[t[1]], x[t[0]]),
                                          Utilities::minus(x[t[2]], x[t[0]]));
          for (unsigned int k = 0; k < 3; ++k)
            n[k] += c[k];
        }
      const double length = Utilities::norm(n);
      return length > 0 ? Utilities::scaled(n, 1 / length) : n;
    }

    /** The run's secret: 128 bits from /dev/urandom (the kernel's
     * cryptographic generator; libstdc++'s random_device reads it when
     * named), as 32 hexadecimal digits. */
    std::string
    make_token()
    {
      std::random_device urandom("/dev/urandom");
      std::ostringstream token;
      token << std::hex;
      for (unsigned int k = 0; k < 4; ++k)
        {
          const std::uint32_t bits = urandom();
          for (int shift = 28; shift >= 0; shift -= 4)
            token << ((bits >> shift) & 0xF);
        }
      return token.str();
    }

    /** Whether @p given is @p secret, in a time that does not depend on
     * where they differ: an attacker who can time the answers learns
     * nothing from them about the secret's digits. */
    bool
    same_secret(const std::string &given, const std::string &secret)
    {
      if (given.size() != secret.size())
        return false;
      volatile unsigned char difference = 0;
      for (std::size_t i = 0; i < secret.size(); ++i)
        difference = difference | (static_cast<unsigned char>(given[i]) ^
                                   static_cast<unsigned char>(secret[i]));
      return difference == 0;
    }

    /** @p text as it may be printed: what a client sent is shown to the
     * user, so control characters (a terminal's escape sequences) become
     * '?', and it is cut to @p most characters. */
    std::string
    printable(const std::string &text, const std::size_t most = 80)
    {
      std::string shown;
      for (const char c : text.substr(0, most))
        shown += static_cast<unsigned char>(c) >= 0x20 &&
                     static_cast<unsigned char>(c) < 0x7F ?
                   c :
                   '?';
      return shown + (text.size() > most ? "..." : "");
    }

    std::string
    lower_case(std::string text)
    {
      for (char &c : text)
        c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
      return text;
    }

    /** The host (lower case; an IPv6 address in brackets) and port of a
     * Host header or of an origin after its "http://". */
    struct Authority
    {
      std::string host;
      int         port;

      bool
      operator==(const Authority &other) const
      {
        return host == other.host && port == other.port;
      }
    };

    /** "host", "host:port", "[v6]" or "[v6]:port" (the port 80 if none,
     * as browsers leave it out then), or nothing if @p text is not one of
     * these (a user name, a path or a second colon included). */
    std::optional<Authority>
    parse_authority(const std::string &text)
    {
      std::string host, port;
      if (!text.empty() && text[0] == '[')
        {
          const auto close = text.find(']');
          if (close == std::string::npos)
            return {};
          host = text.substr(0, close + 1);
          if (close + 1 < text.size())
            {
              if (text[close + 1] != ':')
                return {};
              port = text.substr(close + 2);
            }
          if (host.find_first_not_of("[]0123456789abcdefABCDEF:.") !=
              std::string::npos)
            return {};
        }
      else
        {
          const auto colon = text.find(':');
          host             = text.substr(0, colon);
          if (colon != std::string::npos)
            port = text.substr(colon + 1);
          if (host.find_first_not_of(
                "abcdefghijklmnopqrstuvwxyz"
                "ABCDEFGHIJKLMNOPQRSTUVWXYZ0123456789.-_") != std::string::npos)
            return {};
        }
      if (host.empty() || host == "[]")
        return {};
      int number = 80;
      if (!port.empty() || text.back() == ':')
        {
          if (port.empty() || port.size() > 5 ||
              port.find_first_not_of("0123456789") != std::string::npos)
            return {};
          number = std::stoi(port);
          if (number < 1 || number > 65535)
            return {};
        }
      return Authority{lower_case(host), number};
    }

    /** @p host as a Host header names it: IPv6 addresses in brackets. */
    std::string
    as_url_host(const std::string &host)
    {
      return host.find(':') != std::string::npos && host[0] != '[' ?
               "[" + lower_case(host) + "]" :
               lower_case(host);
    }

    /** Whether --host @p host means every interface. */
    bool
    every_interface(const std::string &host)
    {
      return host == "0.0.0.0" || host == "::" || host == "[::]";
    }

    /** Whether --host @p host is this machine's loopback interface. */
    bool
    loopback(const std::string &host)
    {
      return host == "localhost" || host == "::1" || host == "[::1]" ||
             host.rfind("127.", 0) == 0;
    }

    /** This machine's name and the addresses of its interfaces now, as a
     * Host header gives them: a browser that opens the view listening on
     * every interface names it by one of these. */
    std::vector<std::string>
    machine_names()
    {
      std::vector<std::string> names;
      char                     name[256] = {};
      if (gethostname(name, sizeof name - 1) == 0 && name[0] != 0)
        names.push_back(lower_case(name));
      ifaddrs *list = nullptr;
      if (getifaddrs(&list) == 0)
        {
          for (const ifaddrs *a = list; a != nullptr; a = a->ifa_next)
            {
              if (a->ifa_addr == nullptr)
                continue;
              char text[INET6_ADDRSTRLEN] = {};
              if (a->ifa_addr->sa_family == AF_INET &&
                  inet_ntop(AF_INET,
                            &reinterpret_cast<const sockaddr_in *>(a->ifa_addr)
                               ->sin_addr,
                            text,
                            sizeof text) != nullptr)
                names.emplace_back(text);
              else if (a->ifa_addr->sa_family == AF_INET6 &&
                       inet_ntop(AF_INET6,
                                 &reinterpret_cast<const sockaddr_in6 *>(
                                    a->ifa_addr)
                                    ->sin6_addr,
                                 text,
                                 sizeof text) != nullptr)
                names.push_back("[" + std::string(text) + "]");
            }
          freeifaddrs(list);
        }
      return names;
    }

    /** The media type of a Content-Type header, without its parameters
     * ("; charset=..."), in lower case. */
    std::string
    media_type(const std::string &content_type)
    {
      return lower_case(
        Utilities::trim(content_type.substr(0, content_type.find(';'))));
    }

    /** @p value as the change lines print numbers (6 digits), or as it is
     * if it is not one. */
    std::string
    number_text(const std::string &value)
    {
      try
        {
          std::size_t  used = 0;
          const double x    = std::stod(value, &used);
          if (used == value.size())
            {
              std::ostringstream s;
              s << std::setprecision(10) << x;
              return s.str();
            }
        }
      catch (const std::exception &)
        {}
      return value;
    }

    /**
     * cpp-httplib's task queue for the server: each connection is served
     * on a thread of its own, up to @p most at once (more wait for one to
     * end), so that a client that holds a connection without finishing
     * its request (slow, idle, or on purpose: a "slow loris") holds one
     * thread and nobody waits for it. cpp-httplib's ThreadPool has a
     * fixed number of threads (the live view had 8): nine clients that
     * sent a header line every 3 s made /frame wait more than a minute.
     * The read timeout (LiveServer) ends each such connection after a
     * pause of 2 s; a client must keep sending to keep its thread, and
     * @p most of them at once to make the view wait. Threads beyond @p
     * keep end after 10 s without work.
     */
    class ConnectionThreads : public httplib::TaskQueue
    {
    public:
      /** @p evict, when every thread is taken, closes the connection
       * that has waited longest for a request (GuardedServer), so that a
       * new one (the page's) gets a thread; false if there was none. */
      ConnectionThreads(const std::size_t     keep,
                        const std::size_t     most,
                        std::function<bool()> evict)
        : keep(keep)
        , most(most)
        , evict(std::move(evict))
      {
        // Evictions also while no connection arrives: a queued connection
        // (the page's) waited behind threads whose clients stopped
        // reading until their write timeout, since evictions came only
        // with new connections (the sixth re-run: 9.5 s).
        if (this->evict)
          watchdog = std::thread([this] {
            std::unique_lock<std::mutex> lock(mutex);
            while (!stopping)
              {
                wake_watchdog.wait_for(lock, std::chrono::milliseconds(100));
                if (!stopping && jobs.size() > waiting &&
                    threads.size() >= this->most)
                  for (std::size_t k = waiting; k < jobs.size(); ++k)
                    if (!this->evict())
                      break;
              }
          });
      }

      ~ConnectionThreads() override
      {
        shutdown();
      }

      void
      enqueue(std::function<void()> job) override
      {
        std::lock_guard<std::mutex> lock(mutex);
        reap();
        jobs.push_back(std::move(job));
        // A thread of its own, unless one is waiting for work.
        if (jobs.size() > waiting && threads.size() < most)
          try
            {
              std::thread thread([this] { work(); });
              const auto  id = thread.get_id();
              threads.emplace(id, std::move(thread));
              return;
            }
          catch (const std::system_error &)
            {
              // No more threads to be had: it waits for one.
            }
        else if (evict)
          // Every thread taken, most by clients still sending a request:
          // the slowest are closed, one for each connection that waits
          // for a thread, and their threads take them.
          for (std::size_t k = waiting; k < jobs.size(); ++k)
            if (!evict())
              break;
        wake.notify_one();
      }

      void
      shutdown() override
      {
        std::map<std::thread::id, std::thread> all;
        {
          std::lock_guard<std::mutex> lock(mutex);
          stopping = true;
          all.swap(threads);
        }
        wake_watchdog.notify_all();
        if (watchdog.joinable())
          watchdog.join();
        // The connections accepted and not served yet are closed by the
        // threads on their way out.
        wake.notify_all();
        for (auto &thread : all)
          thread.second.join();
      }

      void
      on_idle() override
      {
        std::lock_guard<std::mutex> lock(mutex);
        reap();
      }

    private:
      void
      work()
      {
        std::unique_lock<std::mutex> lock(mutex);
        for (;;)
          {
            ++waiting;
            const bool woken =
              wake.wait_for(lock, std::chrono::seconds(10), [this] {
                return !jobs.empty() || stopping;
              });
            --waiting;
            if (!jobs.empty())
              {
                // Under a flood of connections queued for a thread (3,000
                // idle connects delayed the page's next request by 10 s),
                // the newest first: the page's reconnect is behind the
                // flood, whose older connections wait and are then closed
                // as idle or evicted.
                const bool newest = jobs.size() > most / 8;
                auto       job = std::move(newest ? jobs.back() : jobs.front());
                if (newest)
                  jobs.pop_back();
                else
                  jobs.pop_front();
                lock.unlock();
                job();
                lock.lock();
              }
            else if (stopping ||
                     (!woken && threads.size() - finished.size() > keep))
              {
                // Joined by reap() or shutdown(); the lock is released
                // on the way out, and nothing after it is touched.
                finished.push_back(std::this_thread::get_id());
                return;
              }
          }
      }

      /** Join the threads that ended (mutex held). */
      void
      reap()
      {
        for (const auto id : finished)
          if (const auto it = threads.find(id); it != threads.end())
            {
              it->second.join();
              threads.erase(it);
            }
        finished.clear();
      }

      const std::size_t                      keep, most;
      const std::function<bool()>            evict;
      std::mutex                             mutex;
      std::condition_variable                wake, wake_watchdog;
      std::thread                            watchdog;
      std::deque<std::function<void()>>      jobs;
      std::map<std::thread::id, std::thread> threads;
      std::vector<std::thread::id>           finished;
      std::size_t                            waiting  = 0;
      bool                                   stopping = false;
    };
  } // namespace



  namespace
  {
    /**
     * cpp-httplib's server with a deadline on every request: a client must
     * send a request whole within @p request_limit seconds of connecting
     * or of its last answer, or its connection is closed. cpp-httplib's
     * own read timeout is per read, so a client that sent a header line
     * every second (slowloris) held a thread for ever, and 300 of them took
     * every thread. The page's requests come whole at once.
     *
     * It serves each connection itself (the same keep-alive loop as
     * cpp-httplib's, around its process_request()) on a Stream whose reads
     * end at the deadline; and it knows its connections, so that with
     * every thread taken the one that has waited longest for its request
     * can be closed to make room (evict_slowest()).
     */
    class GuardedServer : public httplib::Server
    {
    public:
      explicit GuardedServer(const double request_limit)
        : request_limit(std::chrono::duration_cast<Clock::duration>(
            std::chrono::duration<double>(request_limit)))
      {}

      /** Close the connection that has waited longest (at least 0.1 s)
       * for its request; if none waits, the one whose answer has taken
       * longest (at least 1 s: a client that does not read what it asked
       * for); false if there is neither. */
      bool
      evict_slowest()
      {
        std::lock_guard<std::mutex> lock(mutex);
        Connection                 *slowest = nullptr;
        const auto                  now     = Clock::now();
        for (auto &[socket, c] : connections)
          if (c.waiting && !c.closed &&
              now - c.waiting_since > std::chrono::milliseconds(100) &&
              (slowest == nullptr || c.waiting_since < slowest->waiting_since))
            slowest = &c;
        // 260 clients that pipelined requests for three.js and never read
        // the answers held every thread in its write for the whole write
        // timeout, again and again: the page's /frame waited 9.5 s (the
        // sixth re-run). The page reads its answers within milliseconds:
        // every connection whose answer has not been taken for 1 s is
        // closed (one at a time was not enough: each freed thread went to
        // the next such client's reconnect).
        if (slowest == nullptr)
          {
            bool any = false;
            for (auto &[socket, c] : connections)
              {
                const auto since = c.write_blocked_since->load();
                if (!c.closed && since != 0 &&
                    now.time_since_epoch().count() - since >
                      std::chrono::duration_cast<Clock::duration>(
                        std::chrono::seconds(1))
                        .count())
                  {
                    ::shutdown(c.socket, SHUT_RDWR);
                    c.closed = true;
                    any      = true;
                  }
              }
            return any;
          }
        // The thread serving it sees the end of the stream and returns.
        ::shutdown(slowest->socket, SHUT_RDWR);
        slowest->closed = true;
        return true;
      }

    private:
      struct Connection
      {
        socket_t          socket = -1;
        Clock::time_point waiting_since;
        bool              waiting = true, closed = false;
        /** Since when its answer waits for the client to take it (steady
         * clock ticks; 0: not waiting), set by its DeadlineStream. */
        std::shared_ptr<std::atomic<Clock::rep>> write_blocked_since =
          std::make_shared<std::atomic<Clock::rep>>(0);
      };

      /** A socket whose reads end at a deadline (the request's). */
      class DeadlineStream : public httplib::Stream
      {
      public:
        DeadlineStream(const socket_t                           sock,
                       const Clock::duration                    write_limit,
                       std::shared_ptr<std::atomic<Clock::rep>> blocked)
          : sock(sock)
          , write_limit(write_limit)
          , blocked(std::move(blocked))
        {}

        Clock::time_point deadline;
        bool              late = false;

        bool
        is_readable() const override
        {
          return wait(POLLIN, deadline);
        }

        bool
        is_writable() const override
        {
          return wait(POLLOUT, Clock::now() + write_limit);
        }

        ssize_t
        read(char *ptr, size_t size) override
        {
          if (!wait(POLLIN, deadline))
            {
              late = true;
              return -1;
            }
          ssize_t n;
          do
            n = ::recv(sock, ptr, size, 0);
          while (n < 0 && errno == EINTR);
          return n;
        }

        ssize_t
        write(const char *ptr, size_t size) override
        {
          // Writable at once, as for a client that reads; otherwise the
          // wait is known to evict_slowest().
          pollfd now_writable{sock, POLLOUT, 0};
          if (::poll(&now_writable, 1, 0) <= 0)
            {
              blocked->store(Clock::now().time_since_epoch().count());
              const bool writable = is_writable();
              blocked->store(0);
              if (!writable)
                return -1;
            }
          ssize_t n;
          do
            n = ::send(sock, ptr, size, MSG_NOSIGNAL);
          while (n < 0 && errno == EINTR);
          return n;
        }

        void
        get_remote_ip_and_port(std::string &ip, int &port) const override
        {
          address(::getpeername, ip, port);
        }

        void
        get_local_ip_and_port(std::string &ip, int &port) const override
        {
          address(::getsockname, ip, port);
        }

        socket_t
        socket() const override
        {
          return sock;
        }

      private:
        const socket_t                           sock;
        const Clock::duration                    write_limit;
        std::shared_ptr<std::atomic<Clock::rep>> blocked;

        bool
        wait(const short events, const Clock::time_point until) const
        {
          for (;;)
            {
              const auto left =
                std::chrono::duration_cast<std::chrono::milliseconds>(
                  until - Clock::now())
                  .count();
              if (left <= 0)
                return false;
              pollfd    p{sock, events, 0};
              const int r = ::poll(&p, 1, static_cast<int>(left));
              if (r > 0)
                return true;
              if (r == 0 || errno != EINTR)
                return false;
            }
        }

        void
        address(int (*get)(int, sockaddr *, socklen_t *),
                std::string &ip,
                int         &port) const
        {
          sockaddr_storage a{};
          socklen_t        length           = sizeof a;
          char             host[NI_MAXHOST] = {}, service[NI_MAXSERV] = {};
          if (get(sock, reinterpret_cast<sockaddr *>(&a), &length) == 0 &&
              ::getnameinfo(reinterpret_cast<sockaddr *>(&a),
                            length,
                            host,
                            sizeof host,
                            service,
                            sizeof service,
                            NI_NUMERICHOST | NI_NUMERICSERV) == 0)
            {
              ip   = host;
              port = std::atoi(service);
            }
        }
      };

      bool
      process_and_close_socket(socket_t sock) override
      {
        std::shared_ptr<std::atomic<Clock::rep>> blocked;
        {
          std::lock_guard<std::mutex> lock(mutex);
          Connection                 &c = connections[sock];
          c                             = Connection();
          c.socket                      = sock;
          c.waiting_since               = Clock::now();
          blocked                       = c.write_blocked_since;
        }
        const auto seconds = [](const time_t s, const time_t us) {
          return std::chrono::duration_cast<Clock::duration>(
            std::chrono::seconds(s) + std::chrono::microseconds(us));
        };
        DeadlineStream stream(sock,
                              seconds(write_timeout_sec_, write_timeout_usec_),
                              blocked);
        const auto read_limit = seconds(read_timeout_sec_, read_timeout_usec_);
        const auto keep_alive = seconds(keep_alive_timeout_sec_, 0);
        bool       result     = false;
        for (std::size_t left = keep_alive_max_count_; left > 0; --left)
          {
            // Kept alive: the next request's first byte within the
            // keep-alive time (checking now and then that the server
            // still runs); then the whole request within request_limit.
            const auto start = Clock::now();
            bool       ready = false;
            while (!ready && is_running() && Clock::now() - start < keep_alive)
              {
                pollfd p{sock, POLLIN, 0};
                ready = ::poll(&p, 1, 100) > 0;
              }
            if (!ready)
              break;
            stream.deadline =
              std::min(start + request_limit, Clock::now() + read_limit);
            bool closed = false;
            result      = process_request(stream,
                                     left == 1 || !is_running(),
                                     closed,
                                     [this, sock](httplib::Request &) {
                                       set_waiting(sock, false);
                                     });
            if (!result || closed || stream.late)
              break;
            set_waiting(sock, true);
          }
        {
          std::lock_guard<std::mutex> lock(mutex);
          connections.erase(sock);
        }
        ::shutdown(sock, SHUT_RDWR);
        ::close(sock);
        return result;
      }

      void
      set_waiting(const socket_t sock, const bool waiting)
      {
        std::lock_guard<std::mutex> lock(mutex);
        auto                       &c = connections[sock];
        c.waiting                     = waiting;
        c.waiting_since               = Clock::now();
      }

      const Clock::duration          request_limit;
      std::mutex                     mutex;
      std::map<socket_t, Connection> connections;
    };
  } // namespace



  struct LiveServer::Impl
  {
    Impl(const Scene &scene, const double max_speed, std::ostream *log)
      : interaction(scene)
      , max_speed(max_speed)
      , rate(scene.parameters.haptics.loop_rate)
      , device(rate, max_speed)
      , token(make_token())
      , log(log)
      , scene_material(material_description())
      , scene_active(active_description())
    {
      force_log = scene.parameters.effects.force_log;
      // The surface: its vertices (rest positions), triangles, and the
      // DoFs of each vertex's displacement.
      const Mesh              &mesh = interaction.mesh();
      const HyperelasticSystem system(mesh,
                                      interaction.nodes(),
                                      interaction.scene().parameters);
      const ShapeFrames        frames(mesh, interaction.nodes(), system);
      std::map<unsigned int, unsigned int> &compact = surface_index;
      for (const auto &face : mesh.surface_faces())
        {
          std::array<unsigned int, 3> t;
          for (unsigned int k = 0; k < 3; ++k)
            {
              const unsigned int v  = face.vertices[k];
              const auto         it = compact.find(v);
              if (it == compact.end())
                {
                  t[k] = compact[v] = surface.size();
                  surface.push_back(v);
                }
              else
                t[k] = it->second;
            }
          triangles.push_back(t);
        }
      for (const unsigned int v : surface)
        dofs.push_back(frames.dofs_of_vertices()[v]);

      std::vector<double> xyz, tri, fixed;
      for (const unsigned int v : surface)
        for (const double x : mesh.vertices()[v])
          xyz.push_back(x);
      for (const auto &t : triangles)
        for (const unsigned int v : t)
          tri.push_back(v);
      for (const unsigned int v : interaction.nodes().fixed_vertices)
        if (compact.count(v) > 0)
          fixed.push_back(compact[v]);
      // The surface vertices' numbers as the mesh file gives them: the
      // page names nodes by these, as the scene report and the scene's
      // Active node / Node id do, never by its own (surface) or deal.II's
      // (vertex) indices.
      std::vector<double> ids;
      for (const unsigned int v : surface)
        ids.push_back(mesh.node_id(v));
      const auto        &grid = interaction.grid();
      std::ostringstream m;
      m << "{\"vertices\":" << json_array(xyz, 9)
        << ",\"triangles\":" << json_array(tri, 9)
        << ",\"nodes\":" << json_array(ids, 17)
        << ",\"fixed\":" << json_array(fixed, 9)
        << ",\"spacing\":" << grid.spacing()
        << ",\"extent\":" << grid.spacing() * grid.half_width()
        << ",\"diameter\":" << mesh.diameter()
        << ",\"scene\":" << Utilities::json_string(interaction.scene().file());
      m << ",\"engine\":"
        << Utilities::json_string(interaction.summary().engine);
      mesh_json = m.str();
      describe_active();
      displacement.assign(3 * surface.size(), 0.0);

      // The page with the run's token in it (its <meta name=
      // "palpate-token">): the page sends it back with every change.
      page                          = live_view_page;
      const std::string placeholder = "{{palpate-token}}";
      const auto        at          = page.find(placeholder);
      if (at == std::string::npos)
        throw std::logic_error("the live view's page has no place for its "
                               "token");
      page.replace(at, placeholder.size(), token);

      if (live_view_assets::three_module().empty())
        throw NotAvailableError(
          "the live view's 3-D rendering (three.js)",
          "this palpate was built without it: npm was missing (or failed) "
          "when cmake ran. Install npm (apt-get install npm), then run cmake "
          "and make again: cmake installs three.js from npm into the build "
          "tree and builds it in");
    }

    /** The active node as /mesh and /frame give it (active_json), made
     * again when it changes: its number in the mesh file, the outward
     * normal of the surface there (the page's first camera looks along
     * it, at the probe's side of the organ) and, with a sphere probe, the
     * sphere's centre at HIP = 0 and its radius (m), so that the page
     * draws the indenter where it touches, not a marker at the node.
     * Called with mutex held, or before the server runs. */
    void
    describe_active()
    {
      const Mesh          &mesh  = interaction.mesh();
      const NodeSelection &nodes = interaction.nodes();
      const auto          &tip =
        interaction.scene().parameters.boundary_conditions.active_node;
      const bool sphere = tip.tip == Parameters::ActiveNode::Tip::sphere;
      const bool none   = nodes.active_vertex == NodeSelection::no_active_node;
      std::ostringstream a;
      a << "\"active\":" << (none ? -1L : mesh.node_id(nodes.active_vertex))
        << ",\"normal\":"
        << json_point(sphere ? nodes.active_normal :
                      none   ? Utilities::Point3{{0, 0, 0}} :
                               outward_normal(mesh, nodes.active_vertex));
      if (sphere)
        {
          const auto &c = nodes.sphere_center;
          a << ",\"sphere\":"
            << json_array({c[0], c[1], c[2], tip.tip_radius}, 17);
        }
      active_json = a.str();
    }

    std::string
    frame()
    {
      const Utilities::Point3 x = device.hip(), f = device.force(),
                              t = device.target();
      // The lock first: the parameters (and the nodes) may be changing.
      std::lock_guard<std::mutex> lock(mutex);
      State                       blend;
      const bool                  complete = blend_shape(interaction, x, blend);
      if (complete)
        for (std::size_t v = 0; v < surface.size(); ++v)
          for (unsigned int k = 0; k < 3; ++k)
            displacement[3 * v + k] = blend.solution[dofs[v][k]];
      const auto counts = interaction.cache().counts();
      // The engine's load: workers solving, tasks waiting, and since the
      // last frame (at least 0.5 s ago) states per second and the fraction
      // of the workers' time spent solving.
      const EngineLoad load = interaction.engine_load();
      const auto       now  = Clock::now();
      const double     dt =
        std::chrono::duration<double>(now - load_sample.time).count();
      if (dt >= 0.5)
        {
          const unsigned int done = load.computed + load.failed;
          states_per_second =
            done >= load_sample.done ? (done - load_sample.done) / dt : 0.0;
          utilisation = std::clamp((load.busy_time - load_sample.busy_time) /
                                     (dt * std::max(1u, load.workers)),
                                   0.0,
                                   1.0);
          load_sample = {now, done, load.busy_time};
        }
      std::vector<std::uint8_t> computing(interaction.grid().size(), 0);
      for (const unsigned int p : load.in_progress)
        computing[p] = 1;
      // The cloud around the HIP, as the paper's Fig. 1 draws it and the
      // scheduler keeps it (at rest): each grid point within the cloud
      // radius of the HIP with its status (0 not computed, 1
      // computed, 2 a failure point, 3 being computed), as i, j, k, status.
      const auto     &grid   = interaction.grid();
      const GridIndex centre = grid.nearest(x);
      const double    radius =
        interaction.scene().parameters.scheduler.cloud_radius;
      const int           reach = std::ceil(radius / grid.spacing()) + 1;
      std::vector<double> cloud;
      for (int i = -reach; i <= reach; ++i)
        for (int j = -reach; j <= reach; ++j)
          for (int k = -reach; k <= reach; ++k)
            {
              const GridIndex g{{centre[0] + i, centre[1] + j, centre[2] + k}};
              if (!grid.contains(g))
                continue;
              const unsigned int p = grid.linear(g);
              if (Utilities::distance(grid.position(p), x) > radius)
                continue;
              const int status =
                static_cast<int>(interaction.cache().status(p));
              cloud.insert(cloud.end(),
                           {double(g[0]),
                            double(g[1]),
                            double(g[2]),
                            double(status == 0 && computing[p] ? 3 : status)});
            }
      std::ostringstream s;
      s << "{\"hip\":" << json_point(x) << ",\"target\":" << json_point(t)
        << ",\"force\":" << json_point(f)
        << ",\"shape\":" << (complete ? "true" : "false") << ",\"missing\":\""
        << cause_name(interaction.missing_cause())
        << "\",\"available\":" << counts.first
        << ",\"failed\":" << counts.second << ",\"cloud_complete\":"
        << (interaction.initial_cloud_complete() ? "true" : "false")
        << ",\"attached\":" << (interaction.attached() ? "true" : "false")
        << "," << active_json << ",\"load\":{\"workers\":" << load.workers
        << ",\"busy\":" << load.busy << ",\"queued\":" << load.queued
        << ",\"states_per_second\":" << json_number(states_per_second)
        << ",\"utilisation\":" << json_number(utilisation) << "}"
        << ",\"cloud\":" << json_array(cloud, 6)
        << ",\"displacement\":" << json_array(displacement, 6) << "}";
      return s.str();
    }

    Interaction  interaction;
    const double max_speed, rate;
    /** The browser's mouse: the HIP follows the target the page sends, in
     * the common haptic loop (started by LiveServer's constructor). */
    TargetFollower                           device;
    std::unique_ptr<HapticLoop>              loop;
    std::vector<unsigned int>                surface;
    std::vector<std::array<unsigned int, 3>> triangles, dofs;
    // /mesh without the active node, and the active node (mutex).
    std::string         mesh_json, active_json;
    std::vector<double> displacement;
    /** Effects / Force log: the loop's ring, emptied by
     * write_force_log(). */
    bool force_log = false;
    // The engine's counters at the last load sample (frame()).
    struct
    {
      Clock::time_point time;
      unsigned int      done;
      double            busy_time;
    } load_sample{Clock::now(), 0, 0.0};
    double            states_per_second = 0, utilisation = 0;
    std::atomic<bool> running{true};
    // Locked in this order: control_mutex, (the loop held), mutex.
    std::mutex control_mutex, mutex;
    // Mesh vertex -> its index among the surface's vertices.
    std::map<unsigned int, unsigned int> surface_index;

    // Who gets in. The run's secret, and the page that carries it.
    const std::string token;
    std::string       page;
    // The port it listens on (and the listening socket); the host names a
    // request's Host header may give with it (lower case, IPv6 in
    // brackets); the address to open.
    int                   bound = 0, listening = -1;
    std::set<std::string> hosts;
    std::string           address;

    // What happened, for the user: the log, when the server started, the
    // changes made through the view and the requests refused, by kind
    // (record_mutex). The material and the active node at the start.
    std::ostream *const                 log;
    const Clock::time_point             started = Clock::now();
    mutable std::mutex                  record_mutex;
    std::vector<LiveServer::Change>     changes;
    std::map<std::string, unsigned int> refusals;
    const std::string                   scene_material, scene_active;

    /** The material model and its constants now, as the scene report
     * gives them: "St.Venant-Kirchhoff, E = 15465 Pa, nu = 0.49". */
    std::string
    material_description() const
    {
      const auto &material = interaction.scene().parameters.material_model;
      return material.model_name + ", " +
             Material::create(material)->description();
    }

    /** The active node now: "node 87 at (100, 0, 10) mm". */
    std::string
    active_description() const
    {
      const auto &mesh = interaction.mesh();
      const auto  v    = interaction.nodes().active_vertex;
      if (v == NodeSelection::no_active_node)
        return "none";
      return "node " + std::to_string(mesh.node_id(v)) + " at (" +
             Utilities::to_string(Utilities::scaled(mesh.vertices()[v], 1000),
                                  4) +
             ") mm";
    }

    /** A change made through the view: printed on the log as it is made
     * and kept for the summary. */
    void
    record(const std::string &what)
    {
      std::lock_guard<std::mutex> lock(record_mutex);
      changes.push_back(
        {std::chrono::duration<double>(Clock::now() - started).count(), what});
      if (log != nullptr)
        *log << "live view: " << what << std::endl;
    }

    /**
     * Why @p request must be refused, with its kind (LiveServer::refused()),
     * or "" if it may go on. Every request must name this server by an
     * address it listens on (DNS rebinding: a page of another site whose
     * name was made to point to this machine names that site). A POST
     * changes the model: it must come from the page this run served, which
     * is what its token proves; no Origin but this server's (browsers send
     * one with every POST; "null" from sandboxed frames and files), and
     * none of the content types a form or a script of another site may
     * send without asking first (a CORS preflight, which is refused here:
     * so a script of another site cannot send the token's header either).
     */
    std::string
    refusal(const httplib::Request &request, std::string &kind) const
    {
      // A control character in a header (a NUL, a bare CR or LF) is not
      // HTTP (RFC 9110, 5.5): whoever sends it is probing for a parser
      // that reads it differently.
      for (const auto &[name, value] : request.headers)
        for (const std::string *text : {&name, &value})
          for (const char c : *text)
            if ((static_cast<unsigned char>(c) < 0x20 && c != '\t') ||
                c == 0x7f)
              {
                kind = "malformed";
                return "the header '" + printable(name, 40) +
                       "' holds a control character (NUL, CR or LF), which "
                       "HTTP does not allow";
              }
      const std::string host      = request.get_header_value("Host");
      const auto        authority = parse_authority(host);
      if (request.headers.count("Host") != 1 || !authority ||
          authority->port != bound || hosts.count(authority->host) == 0)
        {
          kind = "Host";
          return "this live view answers only requests addressed to it (" +
                 address + "), not to '" + printable(host) +
                 "' (a page of another site whose name was made to point "
                 "here, DNS rebinding, gets nothing)";
        }
      if (request.method == "OPTIONS")
        {
          kind = "preflight";
          return "the live view allows no requests from other sites (a CORS "
                 "preflight is never answered yes)";
        }
      if (request.method != "POST")
        return "";
      if (request.has_header("Origin"))
        {
          const std::string origin = request.get_header_value("Origin");
          const auto        from   = origin.rfind("http://", 0) == 0 ?
                                       parse_authority(origin.substr(7)) :
                                       std::nullopt;
          if (request.headers.count("Origin") != 1 || !from ||
              !(*from == *authority))
            {
              kind = "Origin";
              return "a change sent by a page of another site (Origin: " +
                     printable(origin) +
                     "); the live view takes changes from its own page only";
            }
        }
      const std::string site = request.get_header_value("Sec-Fetch-Site");
      if (!site.empty() && site != "same-origin")
        {
          kind = "Origin";
          return "a change sent by a page of another site (Sec-Fetch-Site: " +
                 printable(site) +
                 "); the live view takes changes from its own page only";
        }
      const std::string type = request.get_header_value("Content-Type");
      if (media_type(type) != LiveServer::command_type)
        {
          kind = "content type";
          return "a change must be sent as Content-Type: " +
                 std::string(LiveServer::command_type) + ", not '" +
                 printable(type) +
                 "' (the types a form or a script of another site can send "
                 "are refused)";
        }
      if (request.headers.count(LiveServer::token_header) != 1 ||
          !same_secret(request.get_header_value(LiveServer::token_header),
                       token))
        {
          kind = "token";
          return std::string(request.has_header(LiveServer::token_header) ?
                               "a wrong " :
                               "no ") +
                 LiveServer::token_header +
                 ": changes need the token of the page this run served (a "
                 "page from an earlier run: reload it, " +
                 address + ")";
        }
      return "";
    }

    /** Count a refused request; print the first of each kind. */
    void
    refuse(const httplib::Request &request,
           const std::string      &kind,
           const std::string      &reason)
    {
      std::lock_guard<std::mutex> lock(record_mutex);
      if (++refusals[kind] == 1 && log != nullptr)
        *log << "live view: refused " << printable(request.method, 10) << " "
             << printable(request.path) << ": " << reason
             << " [more of this kind are counted in the summary, not printed]"
             << std::endl;
    }

    /** The material model and its constants as they are now (the m key's
     * prompt). */
    std::string
    material_json()
    {
      std::lock_guard<std::mutex> lock(mutex);
      const auto &material = interaction.scene().parameters.material_model;
      std::ostringstream m;
      m << "{\"model\":" << Utilities::json_string(material.model_name)
        << ",\"constants\":{";
      const auto found = material.models.find(material.model_name);
      if (found != material.models.end())
        {
          bool first = true;
          for (const auto &[entry, value] : found->second)
            {
              m << (first ? "" : ",") << Utilities::json_string(entry) << ":"
                << Utilities::json_string(value);
              first = false;
            }
        }
      m << "}}";
      return m.str();
    }

    /** Change the scene's parameters on the fly: detach, change (the
     * cache is invalidated and the states are computed again), attach.
     * If it was made, the line describe() returns is recorded (printed
     * and kept for the summary) in the order the changes were made.
     * Returns "" or the reason the change was refused. */
    std::string
    change(const std::function<void(Parameters::AllParameters &)> &edit,
           const bool                                              rest,
           const std::function<std::string()>                     &describe)
    {
      // One change, attach or detach at a time (connections are served
      // in parallel); the device runs on while detaching (the force
      // fades).
      std::lock_guard<std::mutex> control(control_mutex);
      Parameters::AllParameters   p = interaction.scene().parameters;
      edit(p);
      // Checked first, attached and outside the lock /frame waits for: a
      // refused sphere tries the radius it offers by static solves, and
      // under the locks the view froze for them (12.8 s on the graded
      // liver, the eighteenth re-run's F2).
      const std::string early =
        refusal_of([&] { interaction.check_parameters(p); });
      if (!early.empty())
        return early;
      interaction.detach();
      const std::string refused = refusal_of([&] {
        // The device held (the loop asks the interaction for nothing)
        // while its scene is replaced.
        const HeldDevice            held(*loop);
        std::lock_guard<std::mutex> frame_lock(mutex);
        interaction.change_parameters(p);
        describe_active();
        // Another active node: the device at rest on it (a target sent
        // meanwhile was for the old one).
        if (rest)
          device.reset();
      });
      interaction.attach();
      if (refused.empty())
        record(describe());
      return refused;
    }

    /** A request must come whole within this many seconds of connecting
     * or of the last answer (keep-alive waits 1 s for its first byte). */
    static constexpr double request_limit = 3;
    GuardedServer           server{request_limit};
    std::thread             http;

    /** The steps of LiveServer's constructor. */
    void
    guard_requests();
    void
    add_reads();
    void
    add_device_requests();
    void
    add_material_change();
    void
    add_active_node_change();
    void
    limit_connections();
    void
    listen(const std::string &host, const int port);
  };



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
    // (standard output closed, so the view ends at once) found cpp-httplib
    // not listening yet, stopped nothing, and then waited for ever for the
    // thread, serving on with every signal ignored; a later Ctrl-C lost
    // every output (the sixth re-run, issue 26).
    for (int k = 0; k < 10000 && !s.server.is_running(); ++k)
      std::this_thread::sleep_for(std::chrono::microseconds(500));
  }



  /** Who may ask, checked before any handler; the answers' own headers. */
  void
  LiveServer::Impl::guard_requests()
  {
    Impl &s      = *this;
    auto &server = s.server;
    // Before any handler, and before a POST's body is read: who may ask
    // (Impl::refusal()). A refused client's connection is closed (the body
    // it sent, unread, is not taken for another request).
    server.set_pre_routing_handler(
      [&s](const httplib::Request &req, httplib::Response &res) {
        std::string       kind;
        const std::string reason = s.refusal(req, kind);
        if (reason.empty())
          return httplib::Server::HandlerResponse::Unhandled;
        s.refuse(req, kind, reason);
        res.status = kind == "malformed" ? 400 : 403;
        res.set_header("Connection", "close");
        res.set_content("refused: " + reason + "\n", "text/plain");
        return httplib::Server::HandlerResponse::Handled;
      });
    // On every answer: never read by a page of another site as a script or
    // an image (no-cors), nor guessed as another type than it says.
    server.set_default_headers({{"Cross-Origin-Resource-Policy", "same-origin"},
                                {"X-Content-Type-Options", "nosniff"}});
  }



  /** The page, three.js, the model (/mesh, /material) and its frames. */
  void
  LiveServer::Impl::add_reads()
  {
    Impl &s      = *this;
    auto &server = s.server;
    server.Get("/", [&s](const httplib::Request &, httplib::Response &res) {
      // The page holds the run's token: not kept by the browser's cache
      // (a page from an earlier run would send a stale one), and never
      // shown in a frame of another site's page (a click there would be a
      // click on the view: clickjacking).
      res.set_header("Cache-Control", "no-store");
      res.set_header("X-Frame-Options", "DENY");
      res.set_header("Content-Security-Policy", "frame-ancestors 'none'");
      res.set_content(s.page, "text/html");
    });
    server.Get("/favicon.ico",
               [](const httplib::Request &, httplib::Response &res) {
                 res.status = 204;
               });
    // three.js's modules: the page imports three.module.js, which imports
    // ./three.core.js, and OrbitControls.js, which imports 'three' (the
    // page's import map: /three.module.js, the same module).
    for (const auto &[path, module] :
         {std::make_pair("/three.module.js", live_view_assets::three_module()),
          std::make_pair("/three.core.js", live_view_assets::three_core()),
          std::make_pair("/OrbitControls.js",
                         live_view_assets::orbit_controls())})
      server.Get(
        path,
        [module = module](const httplib::Request &, httplib::Response &res) {
          res.set_content(module.data(), module.size(), "text/javascript");
        });
    server.Get("/mesh", [&s](const httplib::Request &, httplib::Response &res) {
      std::lock_guard<std::mutex> lock(s.mutex);
      res.set_content(s.mesh_json + "," + s.active_json + "}",
                      "application/json");
    });
    server.Get("/material",
               [&s](const httplib::Request &, httplib::Response &res) {
                 res.set_content(s.material_json(), "application/json");
               });
    server.Get("/frame",
               [&s](const httplib::Request &, httplib::Response &res) {
                 res.set_content(s.frame(), "application/json");
               });
  }



  /** The probe's target, attach, detach and back to rest. */
  void
  LiveServer::Impl::add_device_requests()
  {
    Impl &s      = *this;
    auto &server = s.server;
    server.Post(
      "/hip", [&s](const httplib::Request &req, httplib::Response &res) {
        // "x,y,z": the target displacement from rest (m). Anything else, or
        // a target beyond twice the state space, is refused: the device
        // keeps its target.
        try
          {
            const auto   x     = Utilities::parse_point(req.body);
            const double limit = 2 * s.interaction.grid().spacing() *
                                 s.interaction.grid().half_width();
            for (const double c : x)
              if (!std::isfinite(c) || std::abs(c) > limit)
                throw std::invalid_argument("out of range");
            s.device.set_target(x);
            res.set_content("ok", "text/plain");
          }
        catch (const std::exception &)
          {
            res.status = 400;
            res.set_content("expected x,y,z in metres (the HIP's displacement "
                            "from rest, within twice the state space)",
                            "text/plain");
          }
      });
    // Attach and detach are recorded when they change something (a
    // second d changes nothing).
    server.Post("/attach",
                [&s](const httplib::Request &, httplib::Response &res) {
                  std::lock_guard<std::mutex> lock(s.control_mutex);
                  if (!s.interaction.attached())
                    {
                      s.interaction.attach();
                      s.record("attached");
                    }
                  res.set_content("ok", "text/plain");
                });
    server.Post("/detach",
                [&s](const httplib::Request &, httplib::Response &res) {
                  std::lock_guard<std::mutex> lock(s.control_mutex);
                  if (s.interaction.attached())
                    {
                      s.interaction.detach();
                      s.record("detached (the force fades to zero)");
                    }
                  res.set_content("ok", "text/plain");
                });
    server.Post("/reset",
                [&s](const httplib::Request &, httplib::Response &res) {
                  s.device.set_target({{0, 0, 0}});
                  s.record("the probe sent back to rest");
                  res.set_content("ok", "text/plain");
                });
  }



  /** A material constant of the scene's model, "ENTRY=VALUE". */
  void
  LiveServer::Impl::add_material_change()
  {
    Impl &s      = *this;
    auto &server = s.server;
    server.Post(
      "/material", [&s](const httplib::Request &req, httplib::Response &res) {
        const auto eq = req.body.find('=');
        if (eq == std::string::npos)
          {
            res.status = 400;
            res.set_content("expected ENTRY=VALUE, e.g. Young's "
                            "modulus=20000",
                            "text/plain");
            return;
          }
        const std::string entry = Utilities::trim(req.body.substr(0, eq));
        const std::string value = Utilities::trim(req.body.substr(eq + 1));
        // A number deal.II's pattern takes but cannot convert (1e-320, a
        // subnormal) or that is not finite: refused here, in words (the
        // scene file's reader does the same).
        {
          char        *end = nullptr;
          const double x   = std::strtod(value.c_str(), &end);
          if (!value.empty() && end == value.c_str() + value.size() &&
              (!std::isfinite(x) ||
               (x != 0 && std::abs(x) < std::numeric_limits<double>::min())))
            {
              res.status = 400;
              res.set_content("refused: " + entry + " = " + value +
                                " is not a number palpate can compute with "
                                "(beyond a double's normal range)",
                              "text/plain");
              return;
            }
        }
        // The value in force sent again: nothing changes, and the cached
        // states are kept (it dropped them and was counted as a change).
        {
          std::lock_guard<std::mutex> control(s.control_mutex);
          const auto                 &material =
            s.interaction.scene().parameters.material_model;
          try
            {
              const std::string now = material.get(material.model_name, entry);
              char             *end_now = nullptr, *end_new = nullptr;
              const double      a = std::strtod(now.c_str(), &end_now);
              const double      b = std::strtod(value.c_str(), &end_new);
              if (!now.empty() && !value.empty() &&
                  end_now == now.c_str() + now.size() &&
                  end_new == value.c_str() + value.size() && a == b)
                {
                  res.set_content(entry + " = " + value +
                                    ": unchanged (the value in force); the "
                                    "cached states are kept",
                                  "text/plain");
                  return;
                }
            }
          catch (const std::exception &)
            {
              // An entry the model does not have: change() says so.
            }
        }
        std::string refused, before;
        try
          {
            refused = s.change(
              [&](Parameters::AllParameters &p) {
                auto &material = p.material_model;
                try
                  {
                    before = material.get(material.model_name, entry);
                  }
                catch (const std::exception &)
                  {
                    // An entry the model does not have: set() says so.
                  }
                material.set(material.model_name, entry, value);
              },
              false,
              [&] {
                // "Young's modulus 15465 -> 20000 Pa": the value in force
                // now, as the model read it; pascals for its moduli.
                const auto &material =
                  s.interaction.scene().parameters.material_model;
                std::string unit;
                for (const auto &modulus : Material::create(material)->moduli())
                  if (modulus.first == entry)
                    unit = " Pa";
                return entry + " " + number_text(before) + " -> " +
                       number_text(material.get(material.model_name, entry)) +
                       unit;
              });
          }
        catch (const std::exception &e)
          {
            refused = e.what();
          }
        res.status = refused.empty() ? 200 : 400;
        res.set_content(refused.empty() ?
                          entry + " = " + value +
                            ": changed; the cached states were dropped and "
                            "are computed again" :
                          "refused: " + refused,
                        "text/plain");
      });
  }



  /** Another active node: "node N" or the point "x,y,z". */
  void
  LiveServer::Impl::add_active_node_change()
  {
    Impl &s      = *this;
    auto &server = s.server;
    server.Post(
      "/active", [&s](const httplib::Request &req, httplib::Response &res) {
        std::string refused;
        // "active node: node 87 at (...) mm -> node 45 at (...) mm": the
        // active node before (read by the edit, under change()'s lock)
        // and after.
        std::string before;
        const auto  describe = [&] {
          return "active node: " + before + " -> " + s.active_description();
        };
        try
          {
            const std::string body = Utilities::trim(req.body);
            if (body.rfind("node", 0) == 0)
              {
                // The whole rest must be the number: "node 3x" is refused,
                // not read as node 3.
                const std::string number = Utilities::trim(body.substr(4));
                long              id     = 0;
                if (!Utilities::parse_whole_number(number, id))
                  throw std::invalid_argument("'" + number +
                                              "' is not a node number");
                refused = s.change(
                  [&](Parameters::AllParameters &p) {
                    before = s.active_description();
                    p.boundary_conditions.active_node.selection = "node id";
                    p.boundary_conditions.active_node.node_id   = id;
                  },
                  true,
                  describe);
              }
            else
              {
                const auto point = Utilities::parse_point(body);
                // A point on the organ: within its bounding box, enlarged by a
                // tenth of its diameter (a huge or NaN point would select no
                // node).
                const auto [low, high] = s.interaction.mesh().bounding_box();
                const double margin    = 0.1 * s.interaction.mesh().diameter();
                for (unsigned int k = 0; k < 3; ++k)
                  if (!(point[k] >= low[k] - margin &&
                        point[k] <= high[k] + margin))
                    throw std::invalid_argument(
                      "the point (" + Utilities::to_string(point, 6) +
                      ") m is not on the organ (its bounding box is (" +
                      Utilities::to_string(low, 6) + ") to (" +
                      Utilities::to_string(high, 6) + ") m)");
                refused = s.change(
                  [&](Parameters::AllParameters &p) {
                    before = s.active_description();
                    p.boundary_conditions.active_node.selection =
                      "nearest surface node";
                    p.boundary_conditions.active_node.point = point;
                  },
                  true,
                  describe);
              }
          }
        catch (const std::invalid_argument &e)
          {
            refused = std::string(e.what()) +
                      "; send 'node N' (N as the mesh file numbers the "
                      "node) or a point 'x,y,z' (m) on the organ";
          }
        catch (const std::exception &e)
          {
            refused = e.what();
          }
        if (refused.empty())
          {
            std::lock_guard<std::mutex> lock(s.mutex);
            const auto                 &m = s.interaction.mesh();
            const auto                  v = s.interaction.nodes().active_vertex;
            Utilities::Point3           x;
            for (unsigned int k = 0; k < 3; ++k)
              x[k] = 1000 * m.vertices()[v][k];
            res.set_content("node " + std::to_string(m.node_id(v)) + " at (" +
                              Utilities::to_string(x, 4) +
                              ") mm; the cached states were dropped and are "
                              "computed again",
                            "text/plain");
            return;
          }
        res.status = 400;
        res.set_content("refused: " + refused, "text/plain");
      });
  }



  /** What a request may be, and how long a connection may take. */
  void
  LiveServer::Impl::limit_connections()
  {
    Impl &s      = *this;
    auto &server = s.server;
    server.set_payload_max_length(4096);
    server.set_payload_max_length(4096);
    // Slow or idle clients cannot keep the page waiting. Each connection
    // has a thread of its own (ConnectionThreads: a browser keeps several
    // open, and with a fixed pool nine clients that sent a header line
    // every 3 s held every thread); one that sends nothing for 1 s
    // before a request, or pauses 2 s within one (the page's requests
    // come whole; cpp-httplib's default would wait 5 s), or does not take
    // an answer for 5 s, is closed; so is one whose request has not come
    // whole 3 s after it connected or got its last answer (GuardedServer:
    // a header line every second held a thread for ever), and with every
    // thread taken, the one that has waited longest for its request is
    // closed to make room. A kept-alive connection serves up to
    // 100 requests (the page asks 30 times a second; the default, 5, made
    // it connect again six times a second).
    server.new_task_queue = [&s] {
      return new ConnectionThreads(8, 256, [&s] {
        return s.server.evict_slowest();
      });
    };
    server.set_keep_alive_timeout(1);
    server.set_keep_alive_max_count(100);
    server.set_read_timeout(2, 0);
    server.set_write_timeout(5, 0);
    // Without connections, the threads that ended are joined once a
    // second (ConnectionThreads::on_idle()).
    server.set_idle_interval(1, 0);
    // The reply's header and body go in two writes: with Nagle's algorithm
    // the second waits for the browser's delayed ACK of the first, 40 ms,
    // and the page's frames came at 20 Hz instead of 30 (measured in
    // headless Chromium: 44 ms per /frame, 2 ms with curl).
    server.set_tcp_nodelay(true);
    // cpp-httplib's default also sets SO_REUSEPORT, with which a second
    // palpate serve on the same port binds too and the kernel shares the
    // connections between the two: only SO_REUSEADDR (a restart can bind
    // at once), so a port in use is an error that says so.
    server.set_socket_options([&s](const socket_t sock) {
      const int yes = 1;
      setsockopt(sock, SOL_SOCKET, SO_REUSEADDR, &yes, sizeof yes);
      s.listening = sock;
    });
  }



  /** Bind (a port in use is an error that says so), listen with a long
   * queue, and the names and address requests may use. */
  void
  LiveServer::Impl::listen(const std::string &host, const int port)
  {
    Impl &s      = *this;
    auto &server = s.server;
    s.bound      = port == 0 ? server.bind_to_any_port(host) :
                               (server.bind_to_port(host, port) ? port : -1);
    // cpp-httplib listens with a backlog of 5 connections: the kernel drops
    // the next ones that arrive before they are accepted, and their
    // clients try again after 1 s (then 3 s, 7 s). A burst of connections
    // (a page's first requests, or clients that mean harm) made the others
    // wait. Listening again on the same socket sets a longer queue.
    if (s.bound > 0 && s.listening >= 0)
      ::listen(s.listening, SOMAXCONN);
    if (s.bound <= 0)
      throw cannot_listen(host, port);
    // The names a request may address it by (Impl::refusal()): the host
    // it was given; on the loopback interface, or on every interface,
    // also the loopback's names; on every interface, this machine's name
    // and addresses (as they are now).
    s.hosts.insert(as_url_host(host));
    if (loopback(host) || every_interface(host))
      s.hosts.insert({"127.0.0.1", "localhost", "[::1]"});
    if (every_interface(host))
      for (const auto &name : machine_names())
        s.hosts.insert(name);
    std::string here = as_url_host(host);
    if (every_interface(host))
      {
        char name[256] = {};
        here = gethostname(name, sizeof name - 1) == 0 && name[0] != 0 ?
                 lower_case(name) :
                 "127.0.0.1";
      }
    s.address = "http://" + here + ":" + std::to_string(s.bound) + "/";
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
        // A long session's list is cut: every change was printed as it
        // was made.
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



  int
  run_serve(std::ostream      &out,
            const Scene       &scene,
            const std::string &host,
            const int          port)
  {
    const auto       &p = scene.parameters;
    const std::string stem =
      scene.file().empty() ?
        "default" :
        std::filesystem::path(scene.file()).stem().string();
    // One live view of a scene per output directory: two overwrote each
    // other's force log and summary (the seventh re-run).
    std::shared_ptr<void> output_lock;
    if (p.effects.force_log || !p.output.summary_formats.empty())
      {
        check_output_directory(scene);
        output_lock = lock_outputs(scene, stem + "-serve");
      }
    LiveServer server(scene, host, port, 0.05, &out);
    // Listening on every interface: the address to open is this machine's
    // (LiveServer::address()); the others it answers to are listed, since
    // a request that names it otherwise is refused.
    out << "Live view: open " << server.address();
    if (every_interface(host))
      {
        out << " (listening on every interface; it answers requests "
               "addressed to";
        for (const auto &name : server.accepted_hosts())
          out << " " << name;
        out << ", port " << server.port() << ")";
      }
    out << " in a browser. A drag on the organ moves the probe in the view "
           "plane (with Alt held, in depth); a drag elsewhere or with the "
           "right button turns the view, the middle button (or Shift and "
           "the right) pans it, the wheel zooms; keys: f look at the probe, "
           "v the first view, a attach, d detach, r back to rest, m a "
           "material constant, shift-click another active node. Ctrl-C "
           "ends.\n"
        << std::flush;
    if (p.effects.shape_output)
      out << "Effects / Shape output: not written by palpate serve (the "
             "browser shows the shape; an interaction run, palpate "
          << (scene.file().empty() ? "SCENE.prm" : scene.file())
          << ", records its frames for ParaView).\n";
    // The force log is written as the view runs, a few times a second
    // (the haptic loop only fills a ring): a run that ends however it
    // ends keeps it.
    const std::string log_file =
      p.output.directory + "/" + stem + "-serve-forces.csv";
    std::ofstream            log;
    std::size_t              log_rows = 0;
    std::vector<std::string> failures;
    if (p.effects.force_log)
      {
        log.open(log_file);
        log << "t_s,x_m,y_m,z_m,fx_N,fy_N,fz_N\n" << std::setprecision(9);
        out << "Force log: " << log_file
            << " (t in s since the view started)\n";
      }
    out << std::flush;
    // The view runs until a stop signal (Ctrl-C, SIGTERM, SIGHUP: its
    // normal end, status 0), until nobody can read what it prints, or
    // until every MPI solver server is lost (nothing could compute a state
    // any more; status 5, as for an interaction).
    std::string stopped_by;
    int         stop_signal = 0;
    {
      const StopRequest stop;
      while (!stop.requested() && out && !server.interaction().engine_lost())
        {
          std::this_thread::sleep_for(std::chrono::milliseconds(100));
          if (log.is_open() && log)
            log_rows += server.write_force_log(log);
        }
      stopped_by =
        stop.requested() ?
          "by " + stop.description() + " (the live view's end)" :
        !out ? std::string("because standard output could not be written") :
               std::string("because every solver server was lost (the LOST "
                           "lines): none was left to compute a state");
      stop_signal = stop.signal_number();
    }
    server.stop();
    if (log.is_open())
      {
        log_rows += server.write_force_log(log);
        log.close();
      }
    out << "Live view ended.\n";
    RunSummary summary = server.interaction().summary();
    server.add_to(summary);
    summary.stopped_by  = stopped_by;
    summary.stop_signal = stop_signal;
    summary.print(out);
    server.print_summary(out);
    if (const std::string store = server.interaction().store_report();
        !store.empty())
      {
        out << "  state store:       " << store << "\n";
        if (server.interaction().store_write_failed())
          failures.push_back("the state store " + p.state_space.store +
                             " stopped taking states: " + store);
      }
    if (p.effects.force_log)
      {
        if (log)
          out << "  wrote " << log_file << " (" << log_rows << " rows"
              << (server.force_log_dropped() > 0 ?
                    ", " + std::to_string(server.force_log_dropped()) +
                      " ticks not logged: the writer fell behind" :
                    std::string())
              << ")\n";
        else
          failures.push_back(log_file + ": could not be written whole (is "
                                        "the disk full?)");
      }

    // The machine-readable summaries, as after an interaction.
    for (const auto &format : p.output.summary_formats)
      {
        const std::string file =
          p.output.directory + "/" + stem + "-serve-summary." + format;
        try
          {
            std::filesystem::create_directories(p.output.directory);
            if (format == "csv")
              summary.write_csv(file);
            else
              summary.write_json(file);
            out << "  wrote " << file << "\n";
          }
        catch (const std::exception &e)
          {
            failures.push_back(file + ": " + e.what());
          }
      }
    if (!failures.empty())
      {
        std::string what;
        for (const auto &f : failures)
          what += "\n  " + f;
        throw OutputError("the live view ended (its summary is above), but " +
                          std::to_string(failures.size()) +
                          " output(s) could not be written:" + what);
      }
    return summary.lost_servers.empty() ? ExitStatus::success :
                                          ExitStatus::server_lost;
  }
} // namespace palpate
