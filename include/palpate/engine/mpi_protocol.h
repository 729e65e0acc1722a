// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

#ifndef palpate_engine_mpi_protocol_h
#define palpate_engine_mpi_protocol_h

// The messages between the MPI engine's client (rank 0) and its solver
// servers (ranks 1..N-1). Only source/engine/mpi_*.cc include this header:
// it pulls in <mpi.h>, which the haptic side never needs.

#include <palpate/hyperelastic/contact_patch.h>
#include <palpate/hyperelastic/state.h>

#include <mpi.h>

#include <chrono>
#include <cstdint>
#include <deque>
#include <memory>
#include <string>
#include <vector>

namespace palpate
{
  namespace MpiProtocol
  {
    /** The rank of the client: scheduler, cache and haptic side. */
    constexpr int client_rank = 0;

    /** The one MPI tag palpate uses: the kind of a message is in its
     * header, so that messages between two ranks keep their order. */
    constexpr int tag = 7301;

    /** What a message says. */
    enum class Kind : std::int32_t
    {
      /** server -> client: set up, ready for tasks (text: linear solver,
       * or the set-up error if flags has failed). */
      ready = 1,
      /** client -> server: compute point from source, whose whole state
       * the server holder has. */
      task,
      /** server -> client: a task ended (converged, failure point, or
       * aborted because its source could not be had); carries the force,
       * so the haptic side never waits for a vector. */
      result,
      /** any -> server: send me your whole state of point. */
      request_state,
      /** server -> any: the whole state of point (header + payload). */
      state,
      /** server -> any: I do not hold point (any more). */
      state_missing,
      /** server -> client: I dropped the whole state of point (memory). */
      dropped,
      /** server -> client: alive, with the server's counters. */
      heartbeat,
      /** client -> server: end. */
      shutdown,
      /** client -> server: the server `holder` was lost; whatever is asked
       * of it will not come (a partitioned server's peers would otherwise
       * wait 10 s for each source it held). */
      peer_lost,
      /** client -> server: give up the task for point (the HIP moved away
       * from it); its result comes with SolveStatus::stopped. */
      cancel
    };

    /** Bits of Header::flags. */
    namespace Flags
    {
      /** result: the state converged (else a failure point). */
      constexpr std::uint32_t converged = 1;
      /** result: the source was fetched from another server, and is now
       * held by this one too. */
      constexpr std::uint32_t fetched_source = 2;
      /** result: the source could not be had (evicted, its holder lost):
       * nothing was computed; not a failure point. */
      constexpr std::uint32_t source_missing = 4;
      /** result: the solve threw (text holds the message); ready: set-up
       * failed. */
      constexpr std::uint32_t error = 8;
      /** result, ready: stiffness holds the active-node stiffness. */
      constexpr std::uint32_t stiffness = 16;
      /** shutdown: a server was lost (finalise without waiting for it). */
      constexpr std::uint32_t peers_lost = 32;
      /** result, ready (of the rest state): the state's contact patch
       * follows the header (Interpolation = contact patch). */
      constexpr std::uint32_t patch = 64;
    } // namespace Flags

    /** Every message starts with this header (plain bytes). */
    struct Header
    {
      Kind          kind              = Kind::heartbeat;
      std::uint32_t point             = 0;
      std::uint32_t source            = 0;
      std::int32_t  holder            = 0;
      std::uint64_t generation        = 0;
      std::int32_t  status            = 0;
      std::uint32_t newton_iterations = 0;
      std::uint32_t flags             = 0;
      /** Seconds the solve took, and the wait for a remote source. */
      double duration = 0, fetch_seconds = 0;
      /** result: the force on the probe (N). */
      double force[3] = {0, 0, 0};
      /** result, and ready (of the rest state): the active-node stiffness
       * (N/m), if flags has Flags::stiffness. */
      double stiffness[9] = {};
      /** task: the active node's displacement at the target (m). */
      double position[3] = {0, 0, 0};
      /** The sender's counters so far (servers, in results and
       * heartbeats): messages and bytes sent. */
      std::uint64_t messages_sent = 0, bytes_sent = 0;
      /** ready: linear solver; result and ready: an error message. */
      char text[200] = {};

      /** Set text (cut to fit). */
      void
      set_text(const std::string &s);
    };

    /** A header alone, as bytes. */
    std::vector<char>
    pack(const Header &header);

    /** A header followed by a whole state (solution, multipliers). */
    std::vector<char>
    pack(const Header &header, const State &state);

    /** A result header followed by the state's contact patch: the haptic
     * process solves the contact against it at every tick. */
    std::vector<char>
    pack(const Header &header, const ContactPatch &patch);

    /** The contact patch carried by a result with Flags::patch (throws
     * if the message is truncated). */
    std::shared_ptr<const ContactPatch>
    patch_of(const std::vector<char> &message);

    /** The header of a received message (throws if too short). */
    Header
    header_of(const std::vector<char> &message);

    /** The state carried by a Kind::state message. */
    State
    state_of(const std::vector<char> &message);

    /**
     * One rank's side of the conversation. Sends are non-blocking (a dead
     * or slow peer never blocks the sender; completed sends are reaped by
     * progress()); receives poll (a blocking receive would spin a core in
     * Open MPI, which on an oversubscribed machine steals it from the
     * solvers). Only one thread of a process uses a Messenger.
     */
    class Messenger
    {
    public:
      explicit Messenger(MPI_Comm communicator);

      ~Messenger();

      /** Send @p message to @p rank (without waiting). False if MPI
       * refused it (the peer is gone). */
      bool
      send(const int rank, std::vector<char> message);

      /** Receive one message, if one is waiting: true, and its sender and
       * bytes set. */
      bool
      receive(int &rank, std::vector<char> &message);

      /** Reap completed sends. */
      void
      progress();

      /** Wait until every send completed, at most @p seconds; false if
       * some did not (a peer that died). Sends to a rank r with
       * @p skip[r] set are not waited for (a peer known to be lost, which
       * may never take them). */
      bool
      flush(const double seconds, const std::vector<bool> &skip = {});

      /** This rank and the number of ranks. */
      int
      rank() const
      {
        return my_rank;
      }
      int
      size() const
      {
        return n_ranks;
      }

      /** Messages and bytes sent so far. */
      std::uint64_t messages_sent = 0, bytes_sent = 0;

    private:
      struct Pending
      {
        MPI_Request       request;
        int               rank;
        std::vector<char> buffer;
      };
      MPI_Comm            communicator;
      int                 my_rank = 0, n_ranks = 1;
      std::deque<Pending> pending;
    };
  } // namespace MpiProtocol
} // namespace palpate

#endif
