// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

#ifndef palpate_app_http_guard_h
#define palpate_app_http_guard_h

#include <cstddef>
#include <optional>
#include <set>
#include <string>
#include <vector>

namespace httplib
{
  struct Request;
}

namespace palpate
{
  /**
   * Who may ask the live view (LiveServer) for anything: the checks on a
   * request's Host, Origin, content type and token, and the names and
   * addresses they are checked against. The rules are LiveServer's
   * (include/palpate/app/live_server.h, doc/serve.md).
   */
  namespace http_guard
  {
    /**
     * The run's secret: 128 bits from /dev/urandom (the kernel's
     * cryptographic generator; libstdc++'s random_device reads it when
     * named), as 32 hexadecimal digits.
     */
    std::string
    make_token();

    /**
     * Whether @p given is @p secret, in a time that does not depend on
     * where they differ: an attacker who can time the answers learns
     * nothing from them about the secret's digits.
     */
    bool
    same_secret(const std::string &given, const std::string &secret);

    /**
     * @p text as it may be printed: what a client sent is shown to the
     * user, so control characters (a terminal's escape sequences) become
     * '?', and it is cut to @p most characters.
     */
    std::string
    printable(const std::string &text, const std::size_t most = 80);

    /** @p text in lower case (ASCII). */
    std::string
    lower_case(std::string text);

    /**
     * The host (lower case; an IPv6 address in brackets) and port of a
     * Host header or of an origin after its "http://".
     */
    struct Authority
    {
      /** The host name or address, lower case, IPv6 in brackets. */
      std::string host;
      /** The TCP port (80 if the text gave none). */
      int port;

      /** Same host and same port. */
      bool
      operator==(const Authority &other) const
      {
        return host == other.host && port == other.port;
      }
    };

    /**
     * "host", "host:port", "[v6]" or "[v6]:port" (the port 80 if none,
     * as browsers leave it out then), or nothing if @p text is not one of
     * these (a user name, a path or a second colon included).
     */
    std::optional<Authority>
    parse_authority(const std::string &text);

    /** @p host as a Host header names it: IPv6 addresses in brackets. */
    std::string
    as_url_host(const std::string &host);

    /** Whether --host @p host means every interface. */
    bool
    every_interface(const std::string &host);

    /** Whether --host @p host is this machine's loopback interface. */
    bool
    loopback(const std::string &host);

    /**
     * This machine's name and the addresses of its interfaces now, as a
     * Host header gives them: a browser that opens the view listening on
     * every interface names it by one of these.
     */
    std::vector<std::string>
    machine_names();

    /**
     * The media type of a Content-Type header, without its parameters
     * ("; charset=..."), in lower case.
     */
    std::string
    media_type(const std::string &content_type);

    /**
     * Why @p request must be refused, with its kind (LiveServer::refused())
     * in @p kind, or "" if it may go on. Every request must name this
     * server by one of @p hosts with the @p port it listens on (DNS
     * rebinding: a page of another site whose name was made to point to
     * this machine names that site). A POST changes the model: it must
     * come from the page this run served, which is what its @p token
     * proves; no Origin but this server's (browsers send one with every
     * POST; "null" from sandboxed frames and files), and none of the
     * content types a form or a script of another site may send without
     * asking first (a CORS preflight, which is refused here: so a script
     * of another site cannot send the token's header either). @p address
     * is the address to open, for the messages.
     */
    std::string
    refusal(const httplib::Request      &request,
            const std::string           &token,
            const int                    port,
            const std::set<std::string> &hosts,
            const std::string           &address,
            std::string                 &kind);
  } // namespace http_guard
} // namespace palpate

#endif
