// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

#include <palpate/engine/mpi_protocol.h>

#include <algorithm>
#include <cstring>
#include <stdexcept>
#include <thread>

namespace palpate
{
  namespace MpiProtocol
  {
    static_assert(std::is_trivially_copyable<Header>::value,
                  "headers travel as plain bytes");

    void
    Header::set_text(const std::string &s)
    {
      const std::size_t n = std::min(s.size(), sizeof(text) - 1);
      std::memcpy(text, s.data(), n);
      text[n] = '\0';
    }



    std::vector<char>
    pack(const Header &header)
    {
      std::vector<char> bytes(sizeof(Header));
      std::memcpy(bytes.data(), &header, sizeof(Header));
      return bytes;
    }



    // A state travels as: header, the two lengths, the active node's
    // displacement and force, the solution and the multipliers. The rest
    // of a State (its Newton history) stays with the server that computed
    // it: nobody downstream needs it.
    std::vector<char>
    pack(const Header &header, const State &state)
    {
      const std::uint64_t n[2] = {state.solution.size(),
                                  state.multipliers.size()};
      std::vector<char>   bytes(sizeof(Header) + sizeof(n) +
                              (6 + n[0] + n[1]) * sizeof(double));
      char               *p = bytes.data();
      std::memcpy(p, &header, sizeof(Header));
      p += sizeof(Header);
      std::memcpy(p, n, sizeof(n));
      p += sizeof(n);
      std::memcpy(p, state.active_displacement.data(), 3 * sizeof(double));
      p += 3 * sizeof(double);
      std::memcpy(p, state.force.data(), 3 * sizeof(double));
      p += 3 * sizeof(double);
      std::memcpy(p, state.solution.data(), n[0] * sizeof(double));
      p += n[0] * sizeof(double);
      std::memcpy(p, state.multipliers.data(), n[1] * sizeof(double));
      return bytes;
    }



    // A patch travels as its header and its bytes (patch_bytes()). Its id
    // is the receiving process's own.
    std::vector<char>
    pack(const Header &header, const ContactPatch &patch)
    {
      const std::vector<char> bytes = patch_bytes(patch);
      std::vector<char>       out(sizeof(Header) + bytes.size());
      std::memcpy(out.data(), &header, sizeof(Header));
      std::memcpy(out.data() + sizeof(Header), bytes.data(), bytes.size());
      return out;
    }



    std::shared_ptr<const ContactPatch>
    patch_of(const std::vector<char> &message)
    {
      if (message.size() < sizeof(Header))
        throw std::runtime_error(
          "MPI engine: a contact patch message is truncated");
      try
        {
          return patch_from_bytes(message.data() + sizeof(Header),
                                  message.size() - sizeof(Header));
        }
      catch (const std::runtime_error &e)
        {
          throw std::runtime_error(std::string("MPI engine: ") + e.what() +
                                   " (message of " +
                                   std::to_string(message.size()) + " bytes)");
        }
    }



    Header
    header_of(const std::vector<char> &message)
    {
      if (message.size() < sizeof(Header))
        throw std::runtime_error("MPI engine: a message of " +
                                 std::to_string(message.size()) +
                                 " bytes is shorter than its header");
      Header h;
      std::memcpy(&h, message.data(), sizeof(Header));
      return h;
    }



    State
    state_of(const std::vector<char> &message)
    {
      std::uint64_t n[2];
      if (message.size() < sizeof(Header) + sizeof(n))
        throw std::runtime_error("MPI engine: a state message is truncated");
      const char *p = message.data() + sizeof(Header);
      std::memcpy(n, p, sizeof(n));
      p += sizeof(n);
      if (message.size() !=
          sizeof(Header) + sizeof(n) + (6 + n[0] + n[1]) * sizeof(double))
        throw std::runtime_error("MPI engine: a state message has the wrong "
                                 "length");
      State s;
      std::memcpy(s.active_displacement.data(), p, 3 * sizeof(double));
      p += 3 * sizeof(double);
      std::memcpy(s.force.data(), p, 3 * sizeof(double));
      p += 3 * sizeof(double);
      s.solution.resize(n[0]);
      std::memcpy(s.solution.data(), p, n[0] * sizeof(double));
      p += n[0] * sizeof(double);
      s.multipliers.resize(n[1]);
      std::memcpy(s.multipliers.data(), p, n[1] * sizeof(double));
      return s;
    }



    Messenger::Messenger(MPI_Comm communicator)
      : communicator(communicator)
    {
      MPI_Comm_rank(communicator, &my_rank);
      MPI_Comm_size(communicator, &n_ranks);
      // A peer that died must give an error code, not abort this process.
      MPI_Comm_set_errhandler(communicator, MPI_ERRORS_RETURN);
    }



    Messenger::~Messenger()
    {
      // Sends to a peer that never received them cannot complete; their
      // buffers are left to the MPI library rather than freed under it.
      for (auto &p : pending)
        {
          int done = 0;
          MPI_Test(&p.request, &done, MPI_STATUS_IGNORE);
          if (!done)
            new std::vector<char>(std::move(p.buffer)); // deliberately kept
        }
    }



    bool
    Messenger::send(const int rank, std::vector<char> message)
    {
      pending.push_back({MPI_REQUEST_NULL, rank, std::move(message)});
      Pending  &p   = pending.back();
      const int err = MPI_Isend(p.buffer.data(),
                                static_cast<int>(p.buffer.size()),
                                MPI_BYTE,
                                rank,
                                tag,
                                communicator,
                                &p.request);
      if (err != MPI_SUCCESS)
        {
          pending.pop_back();
          return false;
        }
      ++messages_sent;
      bytes_sent += p.buffer.size();
      return true;
    }



    bool
    Messenger::receive(int &rank, std::vector<char> &message)
    {
      int        flag = 0;
      MPI_Status status;
      if (MPI_Iprobe(MPI_ANY_SOURCE, tag, communicator, &flag, &status) !=
            MPI_SUCCESS ||
          !flag)
        return false;
      int count = 0;
      MPI_Get_count(&status, MPI_BYTE, &count);
      message.resize(count);
      if (MPI_Recv(message.data(),
                   count,
                   MPI_BYTE,
                   status.MPI_SOURCE,
                   tag,
                   communicator,
                   MPI_STATUS_IGNORE) != MPI_SUCCESS)
        return false;
      rank = status.MPI_SOURCE;
      return true;
    }



    void
    Messenger::progress()
    {
      for (auto p = pending.begin(); p != pending.end();)
        {
          int done = 0;
          if (MPI_Test(&p->request, &done, MPI_STATUS_IGNORE) != MPI_SUCCESS)
            done = 1; // failed: nothing more will happen to it
          p = done ? pending.erase(p) : std::next(p);
        }
    }



    bool
    Messenger::flush(const double seconds, const std::vector<bool> &skip)
    {
      const auto waited_for = [&skip](const Pending &p) {
        return p.rank < 0 || p.rank >= static_cast<int>(skip.size()) ||
               !skip[p.rank];
      };
      const auto end = std::chrono::steady_clock::now() +
                       std::chrono::duration<double>(seconds);
      while (true)
        {
          progress();
          if (std::none_of(pending.begin(), pending.end(), waited_for))
            return true;
          if (std::chrono::steady_clock::now() > end)
            return false;
          std::this_thread::sleep_for(std::chrono::microseconds(200));
        }
    }
  } // namespace MpiProtocol
} // namespace palpate
