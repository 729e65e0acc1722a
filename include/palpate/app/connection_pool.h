// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

#ifndef palpate_app_connection_pool_h
#define palpate_app_connection_pool_h

#include <httplib.h>

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstddef>
#include <deque>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <thread>
#include <vector>

namespace palpate
{
  /**
   * cpp-httplib's task queue for the live view's server: each connection
   * is served on a thread of its own, up to @p most at once (more wait for
   * one to end), so that a client that holds a connection without
   * finishing its request (slow, idle, or on purpose: a "slow loris")
   * holds one thread and nobody waits for it. With a fixed number of
   * threads, as cpp-httplib's ThreadPool has, a handful of clients that
   * send a header line every few seconds would keep /frame waiting. The
   * read timeout (LiveServer) ends each such connection after a pause of
   * 2 s; a client must keep sending to keep its thread, and @p most of
   * them at once to make the view wait. Threads beyond @p keep end after
   * 10 s without work.
   */
  class ConnectionThreads : public httplib::TaskQueue
  {
  public:
    /**
     * Keep @p keep threads, run at most @p most. @p evict, when every
     * thread is taken, closes the connection that has waited longest for
     * a request (GuardedServer::evict_slowest()), so that a new one (the
     * page's) gets a thread; it returns false if there was none.
     */
    ConnectionThreads(const std::size_t     keep,
                      const std::size_t     most,
                      std::function<bool()> evict);

    /** Stops and joins every thread (shutdown()). */
    ~ConnectionThreads() override;

    /** Queue a connection's @p job: a thread of its own if one may be
     * started, else it waits (and the slowest connections are evicted). */
    void
    enqueue(std::function<void()> job) override;

    /** Stop: the queued connections are closed by the threads on their
     * way out; returns when every thread has ended. */
    void
    shutdown() override;

    /** Join the threads that ended (called by the server when idle). */
    void
    on_idle() override;

  private:
    /** A thread's loop: run jobs, end after 10 s without one. */
    void
    work();

    /** Join the threads that ended (mutex held). */
    void
    reap();

    /** Threads kept without work, and the most at once. */
    const std::size_t keep, most;
    /** Closes the slowest connection; false if there was none. */
    const std::function<bool()> evict;
    /** Guards everything below. */
    std::mutex mutex;
    /** Wakes a worker for a job; wakes the watchdog to stop. */
    std::condition_variable wake, wake_watchdog;
    /** Evicts also while no connection arrives (with @p evict). */
    std::thread watchdog;
    /** The connections waiting for a thread. */
    std::deque<std::function<void()>> jobs;
    /** The running threads, by id. */
    std::map<std::thread::id, std::thread> threads;
    /** The threads that ended and wait to be joined. */
    std::vector<std::thread::id> finished;
    /** The threads waiting for a job. */
    std::size_t waiting = 0;
    /** shutdown() was called. */
    bool stopping = false;
  };



  /**
   * cpp-httplib's server with a deadline on every request: a client must
   * send a request whole within @p request_limit seconds of connecting
   * or of its last answer, or its connection is closed. cpp-httplib's
   * own read timeout is per read, so a client that sends a header line
   * every second (slowloris) would hold a thread for ever. The page's
   * requests come whole at once.
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
    /** The clock of the deadlines. */
    using Clock = std::chrono::steady_clock;

    /** @p request_limit in seconds. */
    explicit GuardedServer(const double request_limit);

    /**
     * Close the connection that has waited longest (at least 0.1 s)
     * for its request; if none waits, every one whose answer has taken
     * longer than 1 s (a client that does not read what it asked for);
     * false if there is neither.
     */
    bool
    evict_slowest();

  private:
    /** One connection being served. */
    struct Connection
    {
      /** Its socket. */
      socket_t socket = -1;
      /** Since when it waits for a request, or its answer is served. */
      Clock::time_point waiting_since;
      /** It waits for a request; it was closed by evict_slowest(). */
      bool waiting = true, closed = false;
      /** Since when its answer waits for the client to take it (steady
       * clock ticks; 0: not waiting), set by its DeadlineStream. */
      std::shared_ptr<std::atomic<Clock::rep>> write_blocked_since =
        std::make_shared<std::atomic<Clock::rep>>(0);
    };

    /** Serve the connection @p sock until it closes, each request within
     * its deadline. */
    bool
    process_and_close_socket(socket_t sock) override;

    /** Mark @p sock as waiting for a request (or not) from now on. */
    void
    set_waiting(const socket_t sock, const bool waiting);

    /** A request must come whole within this much time. */
    const Clock::duration request_limit;
    /** Guards connections. */
    std::mutex mutex;
    /** The connections being served, by socket. */
    std::map<socket_t, Connection> connections;
  };
} // namespace palpate

#endif
