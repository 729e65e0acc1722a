// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

// The JSON and CSV run summaries are exact and well-formed whatever they
// hold: counts print as whole numbers however large (1440000 ticks, not
// 1.44e+06), times keep their digits (0.5 stays 0.5, 0.1 stays 0.1), NaN
// and infinities become JSON null (and nan/inf in CSV), and text with
// quotes, backslashes and control characters is escaped. The JSON is
// checked with a strict RFC 8259 parser, and its numbers are read back.

#include <palpate/haptics/run_summary.h>

#include <cmath>
#include <limits>
#include <map>

#include "../tests.h"

namespace
{
  /**
   * A strict JSON (RFC 8259) parser for the summary: one object of
   * strings, numbers, true, false and null. It accepts nothing else and
   * records every member as text (strings decoded, numbers as written).
   */
  class StrictJson
  {
  public:
    explicit StrictJson(const std::string &text)
      : s(text)
    {}

    /** Parse the whole text; false, with error() set, if it is not JSON. */
    bool
    parse(std::map<std::string, std::string> &members)
    {
      try
        {
          space();
          expect('{');
          space();
          if (peek() != '}')
            while (true)
              {
                space();
                const std::string key = string();
                space();
                expect(':');
                space();
                members[key] = value();
                space();
                if (peek() == ',')
                  {
                    ++i;
                    continue;
                  }
                break;
              }
          expect('}');
          space();
          if (i != s.size())
            fail("text after the object");
          return true;
        }
      catch (const std::runtime_error &e)
        {
          error = e.what();
          return false;
        }
    }

    std::string error;

  private:
    const std::string &s;
    std::size_t        i = 0;

    [[noreturn]] void
    fail(const std::string &what) const
    {
      throw std::runtime_error(what + " at byte " + std::to_string(i));
    }

    char
    peek() const
    {
      return i < s.size() ? s[i] : '\0';
    }

    void
    expect(const char c)
    {
      if (peek() != c)
        fail(std::string("expected '") + c + "'");
      ++i;
    }

    void
    space()
    {
      while (i < s.size() &&
             (s[i] == ' ' || s[i] == '\t' || s[i] == '\n' || s[i] == '\r'))
        ++i;
    }

    bool
    digit() const
    {
      return peek() >= '0' && peek() <= '9';
    }

    std::string
    value()
    {
      if (peek() == '"')
        return string();
      for (const std::string word : {"true", "false", "null"})
        if (s.compare(i, word.size(), word) == 0)
          {
            i += word.size();
            return word;
          }
      return number();
    }

    // number = [ minus ] int [ frac ] [ exp ]
    std::string
    number()
    {
      const std::size_t begin = i;
      if (peek() == '-')
        ++i;
      if (peek() == '0')
        ++i;
      else if (digit())
        while (digit())
          ++i;
      else
        fail("not a value");
      if (peek() == '.')
        {
          ++i;
          if (!digit())
            fail("a digit must follow the decimal point");
          while (digit())
            ++i;
        }
      if (peek() == 'e' || peek() == 'E')
        {
          ++i;
          if (peek() == '+' || peek() == '-')
            ++i;
          if (!digit())
            fail("a digit must follow the exponent");
          while (digit())
            ++i;
        }
      return s.substr(begin, i - begin);
    }

    std::string
    string()
    {
      expect('"');
      std::string out;
      while (true)
        {
          if (i >= s.size())
            fail("unterminated string");
          const unsigned char c = s[i++];
          if (c == '"')
            return out;
          if (c < 0x20)
            fail("unescaped control character");
          if (c != '\\')
            {
              out += static_cast<char>(c);
              continue;
            }
          const char e = peek();
          ++i;
          switch (e)
            {
              case '"':
              case '\\':
              case '/':
                out += e;
                break;
              case 'b':
                out += '\b';
                break;
              case 'f':
                out += '\f';
                break;
              case 'n':
                out += '\n';
                break;
              case 'r':
                out += '\r';
                break;
              case 't':
                out += '\t';
                break;
              case 'u':
                {
                  if (i + 4 > s.size())
                    fail("short \\u escape");
                  const std::string hex = s.substr(i, 4);
                  for (const char h : hex)
                    if (!std::isxdigit(static_cast<unsigned char>(h)))
                      fail("bad \\u escape");
                  i += 4;
                  const unsigned long code = std::stoul(hex, nullptr, 16);
                  if (code >= 0x80)
                    fail("the test expects ASCII \\u escapes only");
                  out += static_cast<char>(code);
                  break;
                }
              default:
                fail("invalid escape");
            }
        }
    }
  };

  /** @p text with control characters made visible, for the log. */
  std::string
  visible(const std::string &text)
  {
    std::string out;
    for (const char c : text)
      if (static_cast<unsigned char>(c) < 0x20 && c != '\n')
        out += "<" + std::to_string(static_cast<int>(c)) + ">";
      else
        out += c;
    return out;
  }
} // namespace

int
main(int argc, char **argv)
{
  palpate::Environment env(argc, argv);
  initlog();

  palpate::RunSummary s;
  s.scene                = "my \"liver\" C:\\scenes\\a.prm";
  s.engine               = "line one\nline two\ttabbed";
  s.trajectory           = std::string("control \x01 character and \x1f");
  s.ticks                = 1440000;   // 24 minutes at 1 kHz
  s.messages             = 123456789; // a long MPI run
  s.bytes                = 12345678901234ull;
  s.corner_reads         = 1ull << 53;
  s.states_computed      = 4000000000u;
  s.states_used          = 1000001;
  s.motion_duration      = 0.5;
  s.motion_start         = 0.1;
  s.loop_rate            = 1000;
  s.median_state_ms      = 1.0 / 3.0;
  s.largest_force        = std::numeric_limits<double>::quiet_NaN();
  s.largest_force_change = std::numeric_limits<double>::infinity();
  s.missing_seconds      = -std::numeric_limits<double>::infinity();
  s.period_max_ms        = 1e-300;

  s.write_json("summary.json");
  s.write_csv("summary.csv");
  const std::string json = read_file("summary.json");
  const std::string csv  = read_file("summary.csv");
  deallog << "JSON:" << std::endl << visible(json);
  deallog << "CSV:" << std::endl << visible(csv);

  // The JSON is valid, and its values are what went in.
  std::map<std::string, std::string> members;
  StrictJson                         parser(json);
  const bool                         valid = parser.parse(members);
  deallog << "the JSON is valid RFC 8259: "
          << (valid ? "yes" : "NO (" + parser.error + ")") << std::endl;
  if (!valid)
    return 0;
  const auto same = [&](const std::string &key, const std::string &value) {
    deallog << key << " reads back exactly: "
            << (members[key] == value ? "yes" : "NO: " + members[key])
            << std::endl;
  };
  same("scene", s.scene);
  same("engine", s.engine);
  same("trajectory", s.trajectory);
  same("ticks", "1440000");
  same("messages", "123456789");
  same("bytes", "12345678901234");
  same("corner_reads", "9007199254740992");
  same("states_computed", "4000000000");
  same("motion_duration_s", "0.5");
  same("motion_start_s", "0.1");
  same("largest_force_N", "null");
  same("largest_force_change_N", "null");
  same("missing_data_seconds", "null");
  deallog << "median_state_ms round-trips: "
          << (std::stod(members["median_state_ms"]) == s.median_state_ms ?
                "yes" :
                "NO")
          << std::endl;
  deallog << "period_max_ms round-trips: "
          << (std::stod(members["period_max_ms"]) == s.period_max_ms ? "yes" :
                                                                       "NO")
          << std::endl;
}
