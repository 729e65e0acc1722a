// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

// palpate serve lets in only its user (issue 26), on the small beam, with
// requests written byte for byte on raw sockets (as an attacker writes
// them; a browser's own are in tests/browser):
// - the page carries the run's token (32 hexadecimal digits, another for
//   another server) and may not be framed or cached;
// - every state-changing request (POST /material, /active, /hip, /attach,
//   /detach, /reset) is refused with 403 and the reason: from another
//   origin with text/plain (the body an HTML form sends), with a forged
//   Host (DNS rebinding; even with the token), with Origin: null, without
//   the token, with a token one digit off, with the token but a content
//   type a form or a script of another site can send (text/plain,
//   application/x-www-form-urlencoded, multipart/form-data) or none, from
//   the same site on another port; a CORS preflight is refused, and no
//   answer carries Access-Control-Allow-Origin;
// - reads (/, /mesh, /frame, /material, three.js) are refused with a
//   forged Host, with none, with two, with another port or none; they are
//   answered addressed as 127.0.0.1:PORT, localhost:PORT and [::1]:PORT;
// - after all that nothing changed: Young's modulus is the scene's, the
//   active node is the scene's, the probe attached and at rest, no change
//   recorded; each refusal is counted by kind (exact counts), the first
//   of each kind printed;
// - the page's own requests (same origin, the token, its content type)
//   change the model, and each change is printed as it is made ("live
//   view: Young's modulus 100000 -> 200000 Pa") before its answer comes,
//   and listed in order by the summary with the constants in force at the
//   end and the scene's;
// - slow clients cannot freeze it: with 20 clients that send a header line
//   every 3 s (which made /frame wait more than a minute with the fixed
//   pool of 8 threads), and 300 more that send one every 0.5 s (more than
//   the 256 threads: with a thread per connection and only per-read
//   timeouts they froze /frame), /frame
//   answers every time within 1 s (it takes milliseconds); a request must
//   come whole within 2 s of its first byte: the 3 s ones are closed after
//   their first pause, the 0.5 s ones after 2 s (or earlier, to make room
//   for a new connection), a connection that sends nothing after 1 s;
// - listening on every interface it answers this machine's name and
//   127.0.0.1, and refuses another name.

#include <palpate/app/serve.h>
#include <palpate/haptics/interaction.h>
#include <palpate/mesh/mesh.h>
#include <palpate/mesh/node_selection.h>

#include <httplib.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/resource.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cctype>
#include <chrono>
#include <map>
#include <sstream>
#include <thread>
#include <vector>

#include "../tests.h"

namespace
{
  using Clock = std::chrono::steady_clock;

  double
  seconds_since(const Clock::time_point start)
  {
    return std::chrono::duration<double>(Clock::now() - start).count();
  }

  /** A TCP connection to the server on 127.0.0.1:@p port (-1 if none). */
  int
  connect_to(const int port)
  {
    const int s = socket(AF_INET, SOCK_STREAM, 0);
    if (s < 0)
      return -1;
    sockaddr_in address{};
    address.sin_family      = AF_INET;
    address.sin_port        = htons(port);
    address.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    if (connect(s, reinterpret_cast<sockaddr *>(&address), sizeof address) != 0)
      {
        close(s);
        return -1;
      }
    return s;
  }

  bool
  send_all(const int s, const std::string &text)
  {
    std::size_t sent = 0;
    while (sent < text.size())
      {
        const auto n =
          send(s, text.data() + sent, text.size() - sent, MSG_NOSIGNAL);
        if (n <= 0)
          return false;
        sent += n;
      }
    return true;
  }

  /** Whether the server has answered on @p s or closed it (something to
   * read, or end of file) within @p ms. */
  bool
  answered(const int s, const int ms)
  {
    pollfd p{s, POLLIN, 0};
    return poll(&p, 1, ms) > 0;
  }

  /** An answer: its status (0 if none came) and body. */
  struct Answer
  {
    int         status = 0;
    std::string head, body;

    bool
    refused(const std::string &reason) const
    {
      return status == 403 && body.rfind("refused: ", 0) == 0 &&
             body.find(reason) != std::string::npos;
    }
  };

  /** Send @p request on a new connection as it is, and read the answer
   * until the server closes the connection (the request asks it to). */
  Answer
  round_trip(const int port, const std::string &request)
  {
    Answer    a;
    const int s = connect_to(port);
    if (s < 0 || !send_all(s, request))
      {
        if (s >= 0)
          close(s);
        return a;
      }
    std::string text;
    char        buffer[4096];
    const auto  start = Clock::now();
    while (seconds_since(start) < 20 && answered(s, 1000))
      {
        const auto n = recv(s, buffer, sizeof buffer, 0);
        if (n <= 0)
          break;
        text.append(buffer, n);
      }
    close(s);
    const auto end = text.find("\r\n\r\n");
    if (text.rfind("HTTP/1.1 ", 0) == 0 && end != std::string::npos)
      {
        a.status = std::stoi(text.substr(9, 3));
        a.head   = text.substr(0, end);
        a.body   = text.substr(end + 4);
      }
    return a;
  }

  /** A request with the headers @p headers ("Name: value\r\n" each) and,
   * for a POST, @p body. */
  std::string
  request(const std::string &method,
          const std::string &path,
          const std::string &headers,
          const std::string &body = "")
  {
    return method + " " + path + " HTTP/1.1\r\n" + headers +
           (method == "POST" ?
              "Content-Length: " + std::to_string(body.size()) + "\r\n" :
              "") +
           "Connection: close\r\n\r\n" + body;
  }

  /** The Host header naming the server as 127.0.0.1:@p port. */
  std::string
  host(const int port)
  {
    return "Host: 127.0.0.1:" + std::to_string(port) + "\r\n";
  }

  /** The token in the page: <meta name="palpate-token" content="...">. */
  std::string
  token_in(const std::string &page)
  {
    const std::string before = "<meta name=\"palpate-token\" content=\"";
    const auto        at     = page.find(before);
    if (at == std::string::npos)
      return "";
    const auto from = at + before.size();
    return page.substr(from, page.find('"', from) - from);
  }

  /** The six state-changing requests with bodies that would change
   * something: the body a form sends for Young's modulus, another active
   * node, a target 2 mm in. */
  const std::vector<std::pair<std::string, std::string>> change_requests = {
    {"/material", "Young's modulus=1e13"},
    {"/active", "0.1,0.01,0.01"},
    {"/hip", "0,0,-0.002"},
    {"/attach", ""},
    {"/detach", ""},
    {"/reset", ""}};

  /** Send each state-changing request with @p headers; "yes" for each
   * refused with @p reason, in one line. Counts them in @p sent. */
  std::string
  each_refused(const int          port,
               const std::string &headers,
               const std::string &reason,
               unsigned int      &sent)
  {
    std::ostringstream line;
    for (const auto &[path, body] : change_requests)
      {
        const auto a = round_trip(port, request("POST", path, headers, body));
        line << (path == change_requests.front().first ? "" : ", ") << path
             << " " << ok(a.refused(reason));
        ++sent;
      }
    return line.str();
  }

  /** The Young's modulus of the server's material now (Pa). */
  double
  youngs_modulus(const palpate::LiveServer &server)
  {
    const auto &m = server.interaction().scene().parameters.material_model;
    return m.get_double(m.model_name, "Young's modulus");
  }

  long
  active_node(const palpate::LiveServer &server)
  {
    const auto &i = server.interaction();
    return i.mesh().node_id(i.nodes().active_vertex);
  }

  /** The lines of @p text that begin with @p prefix. */
  std::vector<std::string>
  lines_with(const std::string &text, const std::string &prefix)
  {
    std::vector<std::string> found;
    std::istringstream       s(text);
    std::string              line;
    while (std::getline(s, line))
      if (line.rfind(prefix, 0) == 0)
        found.push_back(line);
    return found;
  }
} // namespace

int
main(int argc, char **argv)
{
  palpate::Environment env(argc, argv);
  initlog();

  const palpate::Scene scene = small_beam_scene();
  std::ostringstream   log;
  palpate::LiveServer  server(scene, "127.0.0.1", 0, 0.05, &log);
  const int            port  = server.port();
  const std::string    P     = std::to_string(port);
  const long           first = active_node(server);

  // The page and its token.
  const auto  page  = round_trip(port, request("GET", "/", host(port)));
  const auto  token = token_in(page.body);
  std::string other_token;
  {
    palpate::LiveServer other(scene, "127.0.0.1", 0, 0.05);
    other_token = token_in(
      round_trip(other.port(), request("GET", "/", host(other.port()))).body);
    other.stop();
  }
  deallog << "the page carries the run's token: "
          << ok(page.status == 200 && token == server.token() &&
                token.size() == 32 &&
                token.find_first_not_of("0123456789abcdef") ==
                  std::string::npos)
          << ", another server's is another: "
          << ok(other_token.size() == 32 && other_token != token)
          << "; the page may not be framed, nor cached: "
          << ok(page.head.find("X-Frame-Options: DENY") != std::string::npos &&
                page.head.find("Content-Security-Policy: frame-ancestors "
                               "'none'") != std::string::npos &&
                page.head.find("Cache-Control: no-store") != std::string::npos)
          << std::endl;

  // What the page sends with every change, and variations of it.
  const std::string same_origin = "Origin: http://127.0.0.1:" + P + "\r\n";
  const std::string with_token  = "X-Palpate-Token: " + token + "\r\n";
  const std::string command_type =
    "Content-Type: " + std::string(palpate::LiveServer::command_type) + "\r\n";
  std::string wrong_token  = token;
  wrong_token.back()       = wrong_token.back() == '0' ? '1' : '0';
  unsigned int sent_origin = 0, sent_host = 0, sent_type = 0, sent_token = 0;

  deallog << "from another origin, as a form sends it (Origin: "
             "http://evil.example, text/plain), refused: "
          << each_refused(port,
                          host(port) + "Origin: http://evil.example\r\n"
                                       "Content-Type: text/plain\r\n",
                          "another site (Origin: http://evil.example)",
                          sent_origin)
          << std::endl;
  deallog << "with a forged Host (evil.example:PORT: DNS rebinding), even "
             "with the token, refused: "
          << each_refused(port,
                          "Host: evil.example:" + P + "\r\n" +
                            "Origin: http://evil.example:" + P + "\r\n" +
                            command_type + with_token,
                          "not to 'evil.example:" + P + "'",
                          sent_host)
          << std::endl;
  deallog << "with Origin: null (a sandboxed frame, a file), even with the "
             "token, refused: "
          << each_refused(port,
                          host(port) + "Origin: null\r\n" + command_type +
                            with_token,
                          "(Origin: null)",
                          sent_origin)
          << std::endl;
  deallog << "from the same host on another port (another local site), "
             "refused: "
          << each_refused(port,
                          host(port) + "Origin: http://127.0.0.1:" +
                            std::to_string(port + 1) + "\r\n" + command_type +
                            with_token,
                          "another site",
                          sent_origin)
          << std::endl;
  deallog << "without the token, refused: "
          << each_refused(port,
                          host(port) + same_origin + command_type,
                          "no X-Palpate-Token",
                          sent_token)
          << std::endl;
  deallog << "with a token one digit off, refused: "
          << each_refused(port,
                          host(port) + same_origin + command_type +
                            "X-Palpate-Token: " + wrong_token + "\r\n",
                          "a wrong X-Palpate-Token",
                          sent_token)
          << std::endl;
  std::ostringstream types;
  for (const std::string type : {"text/plain",
                                 "text/plain; charset=utf-8",
                                 "application/x-www-form-urlencoded",
                                 "multipart/form-data; boundary=x",
                                 ""})
    {
      types << (type == "text/plain" ? "" : ", ")
            << (type.empty() ? "none" : "'" + type + "'") << " "
            << ok(round_trip(port,
                             request("POST",
                                     "/material",
                                     host(port) + same_origin + with_token +
                                       (type.empty() ?
                                          "" :
                                          "Content-Type: " + type + "\r\n"),
                                     "Young's modulus=1e13"))
                    .refused("must be sent as Content-Type: "
                             "application/x-palpate"));
      ++sent_type;
    }
  deallog << "with the token but a content type a page of another site can "
             "send, refused: "
          << types.str() << std::endl;

  // A CORS preflight, as a browser sends it before a script of another
  // site may send the token's header.
  const auto preflight = round_trip(
    port,
    request("OPTIONS",
            "/material",
            host(port) +
              "Origin: http://evil.example\r\n"
              "Access-Control-Request-Method: POST\r\n"
              "Access-Control-Request-Headers: x-palpate-token\r\n"));
  deallog << "a CORS preflight refused: "
          << ok(preflight.refused("CORS preflight") &&
                preflight.head.find("Access-Control-Allow") ==
                  std::string::npos)
          << std::endl;

  // Reads: a forged Host, none, two, another port, no port (80).
  std::ostringstream reads;
  unsigned int       read_refusals = 0;
  for (const std::string path :
       {"/", "/mesh", "/frame", "/material", "/three.module.js"})
    {
      reads << (path == "/" ? "" : ", ") << path << " "
            << ok(round_trip(
                    port,
                    request("GET", path, "Host: evil.example:" + P + "\r\n"))
                    .refused("not to 'evil.example:" + P + "'"));
      ++read_refusals;
    }
  std::ostringstream hosts;
  for (const auto &[name, headers] :
       std::vector<std::pair<std::string, std::string>>{
         {"none", ""},
         {"two", host(port) + "Host: evil.example:" + P + "\r\n"},
         {"another port",
          "Host: 127.0.0.1:" + std::to_string(port + 1) + "\r\n"},
         {"no port", "Host: 127.0.0.1\r\n"},
         {"a name that ends in localhost",
          "Host: evil-localhost:" + P + "\r\n"}})
    {
      hosts << (name == "none" ? "" : ", ") << name << " "
            << ok(round_trip(port, request("GET", "/frame", headers))
                    .refused("answers only requests addressed to it"));
      ++read_refusals;
    }
  std::ostringstream addressed;
  for (const std::string name :
       {"127.0.0.1:" + P, "localhost:" + P, "LocalHost:" + P, "[::1]:" + P})
    {
      const auto a =
        round_trip(port, request("GET", "/frame", "Host: " + name + "\r\n"));
      addressed << (name[0] == '1' ? "" : ", ")
                << name.substr(0, name.rfind(':')) << ":PORT "
                << ok(a.status == 200 &&
                      a.body.find("\"hip\":") != std::string::npos &&
                      a.head.find("Access-Control-Allow") == std::string::npos);
    }
  deallog << "reads with a forged Host refused: " << reads.str() << std::endl;
  deallog << "reads with a Host header that is: " << hosts.str() << std::endl;
  deallog << "reads addressed to it answered, with no "
             "Access-Control-Allow-Origin: "
          << addressed.str() << std::endl;

  // After all that: nothing changed, every refusal counted, the first of
  // each kind printed.
  const auto frame = round_trip(port, request("GET", "/frame", host(port)));
  const bool at_rest =
    frame.body.find("\"target\":[0,0,0]") != std::string::npos;
  deallog << "nothing changed: Young's modulus the scene's (100000 Pa): "
          << ok(youngs_modulus(server) == 1e5)
          << ", the active node the scene's: "
          << ok(active_node(server) == first) << " (node " << first
          << "), attached: " << ok(server.interaction().attached())
          << ", the target at rest: " << ok(at_rest)
          << ", no change recorded: " << ok(server.changes().empty())
          << std::endl;
  const auto refused = server.refused();
  const auto count   = [&](const std::string &kind) {
    const auto it = refused.find(kind);
    return it == refused.end() ? 0u : it->second;
  };
  deallog << "refusals counted by kind: Origin " << count("Origin") << " of "
          << sent_origin << ", Host " << count("Host") << " of "
          << sent_host + read_refusals << ", token " << count("token") << " of "
          << sent_token << ", content type " << count("content type") << " of "
          << sent_type << ", preflight " << count("preflight") << " of 1; "
          << "the first of each kind printed: "
          << ok(lines_with(log.str(), "live view: refused ").size() == 5 &&
                log.str().find("live view: refused POST /material: a change "
                               "sent by a page of another site (Origin: "
                               "http://evil.example)") != std::string::npos)
          << std::endl;

  // A header holding a NUL (or another control character) is not HTTP: 400
  // with the reason, for a read and for a change with everything else right.
  {
    const std::string nul(1, '\0');
    const auto        read = round_trip(
      port,
      request("GET", "/frame", host(port) + "X-Probe: a" + nul + "b\r\n"));
    const auto change =
      round_trip(port,
                 request("POST",
                         "/material",
                         host(port) + same_origin + command_type + with_token +
                           "X-Probe: a" + nul + "b\r\n",
                         "Young's modulus=1e13"));
    const auto malformed = [](const Answer &a) {
      return a.status == 400 &&
             a.body.find("holds a control character") != std::string::npos;
    };
    deallog << "a header holding a NUL: a read refused (400) "
            << ok(malformed(read)) << ", a change refused (400) "
            << ok(malformed(change)) << ", the modulus still the scene's "
            << ok(youngs_modulus(server) == 1e5) << std::endl;
  }

  // The page's own requests: same origin, the token, its content type,
  // as the browser sends them. Each change is printed before its answer
  // comes.
  const std::string page_headers = host(port) + same_origin + command_type +
                                   with_token +
                                   "Sec-Fetch-Site: same-origin\r\n";
  const auto post = [&](const std::string &path, const std::string &body) {
    return round_trip(port, request("POST", path, page_headers, body));
  };
  std::vector<bool> printed;
  const auto        printed_now = [&](const std::string &line) {
    printed.push_back(log.str().find("live view: " + line) !=
                      std::string::npos);
    return printed.back();
  };
  const auto modulus = post("/material", "Young's modulus=2e5");
  printed_now("Young's modulus 100000 -> 200000 Pa");
  const auto moved = post("/active", "0.1,0.01,0.01");
  const long now   = active_node(server);
  printed_now("active node: node " + std::to_string(first));
  const auto detached = post("/detach", "");
  printed_now("detached (the force fades to zero)");
  const auto again    = post("/detach", ""); // changes nothing: not recorded
  const auto attached = post("/attach", "");
  printed_now("attached");
  const auto rest = post("/reset", "");
  printed_now("the probe sent back to rest");
  bool all_printed = true;
  for (const bool p : printed)
    all_printed = all_printed && p;
  const auto made = server.changes();
  deallog << "the page's own requests: Young's modulus changed: "
          << ok(modulus.status == 200 && youngs_modulus(server) == 2e5)
          << ", another active node: "
          << ok(moved.status == 200 && now != first)
          << ", detached and attached: "
          << ok(detached.status == 200 && again.status == 200 &&
                attached.status == 200 && server.interaction().attached())
          << ", back to rest: " << ok(rest.status == 200)
          << "; each change printed as it was made: " << ok(all_printed)
          << ", 5 recorded, in order: "
          << ok(made.size() == 5 &&
                made[0].what == "Young's modulus 100000 -> 200000 Pa" &&
                made[1].what.rfind("active node: node " +
                                     std::to_string(first) + " at (",
                                   0) == 0 &&
                made[1].what.find(" -> node " + std::to_string(now) +
                                  " at (") != std::string::npos &&
                made[2].what == "detached (the force fades to zero)" &&
                made[3].what == "attached" &&
                made[4].what == "the probe sent back to rest" &&
                made[0].time <= made[4].time)
          << std::endl;
  std::ostringstream summary;
  server.print_summary(summary);
  const std::string s = summary.str();
  deallog << "the summary gives the material in force at the end and the "
             "scene's: "
          << ok(s.find("  material:          St.Venant-Kirchhoff, E = "
                       "200000 Pa, nu = 0.3 (the scene's: "
                       "St.Venant-Kirchhoff, E = 100000 Pa, nu = 0.3)\n") !=
                std::string::npos)
          << ", the active node: "
          << ok(s.find("  active node:       node " + std::to_string(now) +
                       " at (") != std::string::npos &&
                s.find("(the scene's: node " + std::to_string(first) +
                       " at (") != std::string::npos)
          << ", the 5 changes in order: "
          << ok(s.find("  changes:           5 made through the view, in "
                       "order:\n") != std::string::npos &&
                lines_with(s, "    ").size() == 5 &&
                lines_with(s, "    ")[0].find(
                  " s: Young's modulus 100000 -> 200000 Pa") !=
                  std::string::npos &&
                lines_with(s, "    ")[4].find(
                  " s: the probe sent back to rest") != std::string::npos)
          << ", the refusals: "
          << ok(s.find("  refused:           " +
                       std::to_string(sent_origin + sent_host + read_refusals +
                                      sent_token + sent_type + 1 + 2) +
                       " requests (403, malformed 400;") != std::string::npos)
          << std::endl;

  // Slow clients. 20 send a request line, then a header line every 3 s;
  // 300 more every 0.5 s (more than the 256 threads). Meanwhile /frame is asked
  // for every 0.2 s, each time on a new connection, for 7 s.
  {
    const std::string start_line =
      "GET /frame HTTP/1.1\r\n" + host(port) + "X-Slow: 0\r\n";
    // Each sends its request line at once (one that sent nothing would be
    // closed after 1 s, below).
    std::vector<int> slow, slower;
    for (unsigned int i = 0; i < 320; ++i)
      {
        const int c = connect_to(port);
        send_all(c, start_line);
        (i < 20 ? slower : slow).push_back(c);
      }
    const auto        begun = Clock::now();
    std::atomic<bool> done{false};
    // When the server closed each of the 3 s clients (s after their
    // line; 0 if it did not).
    std::vector<double> closed(slower.size(), 0.0);
    // When each 0.5 s client was first closed (s; 0 if it was not).
    std::vector<double> slow_closed(slow.size(), 0.0);
    std::thread         trickle([&] {
      unsigned int tick = 0;
      while (!done.load())
        {
          std::this_thread::sleep_for(std::chrono::milliseconds(50));
          ++tick;
          for (std::size_t i = 0; i < slow.size(); ++i)
            if (slow_closed[i] == 0 && answered(slow[i], 0))
              slow_closed[i] = seconds_since(begun);
          if (tick % 10 == 0)
            for (const int c : slow)
              send_all(c, "X-Slow-" + std::to_string(tick) + ": 1\r\n");
          for (std::size_t i = 0; i < slower.size(); ++i)
            {
              if (closed[i] == 0 && answered(slower[i], 0))
                closed[i] = seconds_since(begun);
              if (tick % 60 == 0 && closed[i] == 0)
                send_all(slower[i],
                         "X-Slower-" + std::to_string(tick) + ": 1\r\n");
            }
        }
    });
    std::this_thread::sleep_for(std::chrono::milliseconds(300));
    double       slowest = 0;
    unsigned int asked = 0, answered_frames = 0;
    while (seconds_since(begun) < 7.3)
      {
        httplib::Client client("127.0.0.1", port);
        client.set_read_timeout(20, 0);
        const auto sent_at = Clock::now();
        const auto a       = client.Get("/frame");
        slowest            = std::max(slowest, seconds_since(sent_at));
        ++asked;
        if (a && a->status == 200)
          ++answered_frames;
        std::this_thread::sleep_for(std::chrono::milliseconds(200));
      }
    done.store(true);
    trickle.join();
    // The 0.5 s clients' requests never came whole: each was closed 2-4 s
    // after it connected (2 s after its request began, or to make room).
    bool slow_dropped = true;
    for (const double t : slow_closed)
      slow_dropped = slow_dropped && t > 0 && t < 4;
    bool dropped_after_pause = true;
    for (const double t : closed)
      dropped_after_pause = dropped_after_pause && t > 0 && t < 3;
    for (const int c : slow)
      close(c);
    for (const int c : slower)
      close(c);
    deallog << "with 20 clients sending a header line every 3 s and 300 "
               "every 0.5 s: /frame answered every time: "
            << ok(asked > 20 && answered_frames == asked)
            << ", within 1 s: " << ok(slowest < 1.0)
            << "; the 0.5 s clients closed, their requests never whole: "
            << ok(slow_dropped)
            << ", the 3 s ones closed within 3 s (to make room, the oldest "
               "first, or after their first pause): "
            << ok(dropped_after_pause) << std::endl;
    // For the log (not compared: timings).
    std::cout << "/frame under slow clients: " << asked << " asked, slowest "
              << slowest << " s; the 3 s clients closed after "
              << *std::min_element(closed.begin(), closed.end()) << " to "
              << *std::max_element(closed.begin(), closed.end()) << " s"
              << std::endl;
  }
  {
    // A connection that sends nothing.
    const int  c     = connect_to(port);
    const auto begun = Clock::now();
    answered(c, 5000);
    const double t = seconds_since(begun);
    close(c);
    deallog << "a connection that sends nothing is closed after 1 s: "
            << ok(t > 0.5 && t < 2.5) << std::endl;
  }
  {
    // A flood: 3,000 connections opened at once that send nothing (more
    // than 10 times the threads). The page's next request, on a new
    // connection behind them, waited 10 s; under a flood the newest
    // connection is served first.
    rlimit files{};
    getrlimit(RLIMIT_NOFILE, &files);
    const rlim_t wanted = 3100;
    if (files.rlim_cur < wanted && files.rlim_max >= wanted)
      {
        files.rlim_cur = wanted;
        setrlimit(RLIMIT_NOFILE, &files);
      }
    const unsigned int n =
      std::min<rlim_t>(3000, files.rlim_cur > 100 ? files.rlim_cur - 100 : 0);
    std::vector<int> flood;
    sockaddr_in      to{};
    to.sin_family      = AF_INET;
    to.sin_port        = htons(port);
    to.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    for (unsigned int i = 0; i < n; ++i)
      {
        const int c = socket(AF_INET, SOCK_STREAM | SOCK_NONBLOCK, 0);
        if (c < 0)
          break;
        connect(c, reinterpret_cast<const sockaddr *>(&to), sizeof to);
        flood.push_back(c);
      }
    std::this_thread::sleep_for(std::chrono::milliseconds(500));
    httplib::Client client("127.0.0.1", port);
    client.set_read_timeout(30, 0);
    client.set_connection_timeout(30, 0);
    const auto   sent_at = Clock::now();
    const auto   a       = client.Get("/frame");
    const double t       = seconds_since(sent_at);
    for (const int c : flood)
      close(c);
    deallog << "a flood of " << (flood.size() >= 1000 ? ">= 1000" : "FEWER")
            << " idle connections: /frame on a new connection answered "
            << ok(a && a->status == 200) << " within 1 s " << ok(t < 1)
            << std::endl;
    std::cout << "/frame behind " << flood.size() << " idle connections: " << t
              << " s" << std::endl;
  }
  {
    // 300 clients that ask for three.js 20 times at once and never read
    // the answers would hold every thread blocked in a write until its
    // timeout, and the page's /frame would wait for one. A connection
    // whose answer has not been taken for 1 s is closed when a new one
    // needs its thread.
    std::vector<int> greedy;
    sockaddr_in      to{};
    to.sin_family      = AF_INET;
    to.sin_port        = htons(port);
    to.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    std::string asks;
    for (unsigned int k = 0; k < 20; ++k)
      asks += "GET /three.module.js HTTP/1.1\r\nHost: 127.0.0.1:" +
              std::to_string(port) + "\r\n\r\n";
    for (unsigned int i = 0; i < 300; ++i)
      {
        const int c = socket(AF_INET, SOCK_STREAM, 0);
        if (c < 0 ||
            connect(c, reinterpret_cast<const sockaddr *>(&to), sizeof to) != 0)
          break;
        send(c, asks.data(), asks.size(), MSG_NOSIGNAL);
        greedy.push_back(c);
      }
    std::this_thread::sleep_for(std::chrono::milliseconds(2500));
    double slowest = 0;
    bool   all     = true;
    for (unsigned int k = 0; k < 5; ++k)
      {
        httplib::Client client("127.0.0.1", port);
        client.set_read_timeout(30, 0);
        client.set_connection_timeout(30, 0);
        const auto sent_at = Clock::now();
        const auto a       = client.Get("/frame");
        slowest            = std::max(slowest, seconds_since(sent_at));
        all                = all && a && a->status == 200;
      }
    for (const int c : greedy)
      close(c);
    deallog << (greedy.size() == 300 ? "300" : "FEWER")
            << " clients that never read their answers: /frame answered "
            << ok(all) << ", within 2 s " << ok(slowest < 2) << std::endl;
    std::cout << "/frame beside " << greedy.size()
              << " clients that do not read: slowest " << slowest << " s"
              << std::endl;
  }
  server.stop();

  // On every interface: this machine's name and addresses, 127.0.0.1.
  {
    palpate::LiveServer every(scene, "0.0.0.0", 0, 0.05);
    const std::string   Q         = std::to_string(every.port());
    char                name[256] = {};
    gethostname(name, sizeof name - 1);
    std::string machine = name;
    for (char &c : machine)
      c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    const auto by_name = round_trip(
      every.port(),
      request("GET", "/frame", "Host: " + machine + ":" + Q + "\r\n"));
    const auto by_loopback =
      round_trip(every.port(),
                 request("GET", "/frame", "Host: 127.0.0.1:" + Q + "\r\n"));
    const auto by_other =
      round_trip(every.port(),
                 request("GET", "/frame", "Host: evil.example:" + Q + "\r\n"));
    deallog << "on every interface: the machine's name answered: "
            << ok(!machine.empty() && by_name.status == 200)
            << ", 127.0.0.1: " << ok(by_loopback.status == 200)
            << ", another name refused: " << ok(by_other.status == 403)
            << ", the address to open names the machine: "
            << ok(every.address() == "http://" + machine + ":" + Q + "/")
            << std::endl;
    every.stop();
  }
}
