// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

#include <palpate/app/http_guard.h>
#include <palpate/app/live_server.h>
#include <palpate/base/utilities.h>

#include <arpa/inet.h>
#include <httplib.h>
#include <ifaddrs.h>
#include <netinet/in.h>
#include <unistd.h>

#include <cctype>
#include <cstdint>
#include <random>
#include <sstream>

namespace palpate
{
  namespace http_guard
  {
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



    std::string
    printable(const std::string &text, const std::size_t most)
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



    std::string
    as_url_host(const std::string &host)
    {
      return host.find(':') != std::string::npos && host[0] != '[' ?
               "[" + lower_case(host) + "]" :
               lower_case(host);
    }



    bool
    every_interface(const std::string &host)
    {
      return host == "0.0.0.0" || host == "::" || host == "[::]";
    }



    bool
    loopback(const std::string &host)
    {
      return host == "localhost" || host == "::1" || host == "[::1]" ||
             host.rfind("127.", 0) == 0;
    }



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



    std::string
    media_type(const std::string &content_type)
    {
      return lower_case(
        Utilities::trim(content_type.substr(0, content_type.find(';'))));
    }



    std::string
    refusal(const httplib::Request      &request,
            const std::string           &token,
            const int                    port,
            const std::set<std::string> &hosts,
            const std::string           &address,
            std::string                 &kind)
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
          authority->port != port || hosts.count(authority->host) == 0)
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
  } // namespace http_guard
} // namespace palpate
