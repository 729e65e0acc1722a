// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

#include <palpate/app/connection_pool.h>

#include <netdb.h>
#include <poll.h>
#include <sys/socket.h>

#include <algorithm>
#include <cerrno>
#include <cstdlib>
#include <system_error>
#include <utility>

namespace palpate
{
  ConnectionThreads::ConnectionThreads(const std::size_t     keep,
                                       const std::size_t     most,
                                       std::function<bool()> evict)
    : keep(keep)
    , most(most)
    , evict(std::move(evict))
  {
    // Evictions also while no connection arrives: otherwise a queued
    // connection (the page's) waits behind threads whose clients stopped
    // reading until their write timeout (5 s), since enqueue() evicts
    // only when a new connection comes.
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



  ConnectionThreads::~ConnectionThreads()
  {
    shutdown();
  }



  void
  ConnectionThreads::enqueue(std::function<void()> job)
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
  ConnectionThreads::shutdown()
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
  ConnectionThreads::on_idle()
  {
    std::lock_guard<std::mutex> lock(mutex);
    reap();
  }



  void
  ConnectionThreads::work()
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
            auto       job    = std::move(newest ? jobs.back() : jobs.front());
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



  void
  ConnectionThreads::reap()
  {
    for (const auto id : finished)
      if (const auto it = threads.find(id); it != threads.end())
        {
          it->second.join();
          threads.erase(it);
        }
    finished.clear();
  }



  namespace
  {
    using Clock = GuardedServer::Clock;

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
  } // namespace



  GuardedServer::GuardedServer(const double request_limit)
    : request_limit(std::chrono::duration_cast<Clock::duration>(
        std::chrono::duration<double>(request_limit)))
  {}



  bool
  GuardedServer::evict_slowest()
  {
    std::lock_guard<std::mutex> lock(mutex);
    Connection                 *slowest = nullptr;
    const auto                  now     = Clock::now();
    for (auto &[socket, c] : connections)
      if (c.waiting && !c.closed &&
          now - c.waiting_since > std::chrono::milliseconds(100) &&
          (slowest == nullptr || c.waiting_since < slowest->waiting_since))
        slowest = &c;
    // Clients that pipeline requests (for three.js, say) and never read
    // the answers hold every thread in its write for the whole write
    // timeout, again and again, and the page's /frame waits behind them.
    // The page reads its answers within milliseconds: every connection
    // whose answer has not been taken for 1 s is closed, all at once,
    // since a thread freed from one goes to the next such client's
    // reconnect.
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



  bool
  GuardedServer::process_and_close_socket(socket_t sock)
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
    const auto     read_limit = seconds(read_timeout_sec_, read_timeout_usec_);
    const auto     keep_alive = seconds(keep_alive_timeout_sec_, 0);
    bool           result     = false;
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
  GuardedServer::set_waiting(const socket_t sock, const bool waiting)
  {
    std::lock_guard<std::mutex> lock(mutex);
    auto                       &c = connections[sock];
    c.waiting                     = waiting;
    c.waiting_since               = Clock::now();
  }
} // namespace palpate
