// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

#include <palpate/base/utilities.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <iomanip>
#include <sstream>
#include <stdexcept>

namespace palpate
{
  namespace Utilities
  {
    std::string
    trim(const std::string &s)
    {
      const auto first = s.find_first_not_of(" \t\r\n");
      if (first == std::string::npos)
        return "";
      const auto last = s.find_last_not_of(" \t\r\n");
      return s.substr(first, last - first + 1);
    }



    bool
    parse_whole_number(const std::string &s, long &value)
    {
      std::size_t used = 0;
      try
        {
          value = std::stol(s, &used);
        }
      catch (const std::exception &)
        {
          return false;
        }
      return used > 0 && used == s.size();
    }



    std::vector<std::string>
    split(const std::string &s, const char separator)
    {
      std::vector<std::string> pieces;
      std::string::size_type   begin = 0;
      while (true)
        {
          const auto end = s.find(separator, begin);
          pieces.push_back(trim(s.substr(begin, end - begin)));
          if (end == std::string::npos)
            break;
          begin = end + 1;
        }
      return pieces;
    }



    unsigned int
    edit_distance(const std::string &a, const std::string &b)
    {
      std::vector<unsigned int> previous(b.size() + 1), current(b.size() + 1);
      for (unsigned int j = 0; j <= b.size(); ++j)
        previous[j] = j;
      for (unsigned int i = 1; i <= a.size(); ++i)
        {
          current[0] = i;
          for (unsigned int j = 1; j <= b.size(); ++j)
            {
              const bool same =
                std::tolower(static_cast<unsigned char>(a[i - 1])) ==
                std::tolower(static_cast<unsigned char>(b[j - 1]));
              current[j] = std::min({previous[j] + 1,
                                     current[j - 1] + 1,
                                     previous[j - 1] + (same ? 0 : 1)});
            }
          std::swap(previous, current);
        }
      return previous[b.size()];
    }



    std::string
    closest_match(const std::string              &word,
                  const std::vector<std::string> &candidates)
    {
      std::string  best;
      unsigned int best_distance = static_cast<unsigned int>(-1);
      for (const auto &c : candidates)
        {
          const unsigned int d = edit_distance(word, c);
          if (d < best_distance)
            {
              best          = c;
              best_distance = d;
            }
        }
      const unsigned int allowed =
        std::max<unsigned int>(3, static_cast<unsigned int>(word.size() / 3));
      return (best_distance <= allowed) ? best : std::string();
    }



    double
    norm(const Point3 &v)
    {
      return std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
    }



    double
    distance(const Point3 &a, const Point3 &b)
    {
      return norm({{a[0] - b[0], a[1] - b[1], a[2] - b[2]}});
    }



    std::string
    to_string(const double x, const unsigned int precision)
    {
      // x + 0 turns -0 into 0: a coordinate that is zero reads "0", not
      // "-0" (a HIP at rest along an axis, a mirrored point).
      std::ostringstream s;
      s << std::setprecision(precision) << x + 0.0;
      return s.str();
    }



    std::string
    to_string_exact(const double x)
    {
      // As to_string() shows it (six significant digits, %g: 0.0001,
      // 20000, 1e+13) unless that reads back as another number; then the
      // fewest digits that read back as x. A fixed precision either loses
      // digits (6) or shows round-off noise (17 digits print 0.1 as
      // 0.10000000000000001).
      char buffer[64];
      for (int digits = 6; digits <= 17; ++digits)
        {
          std::snprintf(buffer, sizeof(buffer), "%.*g", digits, x);
          if (std::strtod(buffer, nullptr) == x)
            break;
        }
      return buffer;
    }



    std::string
    to_string_apart(const double       x,
                    const double       from,
                    const unsigned int precision)
    {
      unsigned int digits = precision;
      while (digits < 17 && x != from &&
             to_string(x, digits) == to_string(from, digits))
        ++digits;
      return to_string(x, digits);
    }



    std::string
    to_string(const Point3 &p, const unsigned int precision)
    {
      return to_string(p[0], precision) + ", " + to_string(p[1], precision) +
             ", " + to_string(p[2], precision);
    }



    Point3
    parse_point(const std::string &text)
    {
      const std::vector<std::string> pieces = split(text, ',');
      if (pieces.size() != 3)
        throw std::invalid_argument("'" + text +
                                    "' is not three numbers separated by "
                                    "commas (x, y, z)");
      Point3 p;
      for (unsigned int d = 0; d < 3; ++d)
        {
          std::size_t used = 0;
          try
            {
              p[d] = std::stod(pieces[d], &used);
            }
          catch (const std::exception &)
            {
              used = 0;
            }
          if (used == 0 || used != pieces[d].size() || !std::isfinite(p[d]))
            throw std::invalid_argument("'" + pieces[d] + "' in '" + text +
                                        "' is not a finite number");
        }
      return p;
    }
    Point3
    minus(const Point3 &a, const Point3 &b)
    {
      return {{a[0] - b[0], a[1] - b[1], a[2] - b[2]}};
    }



    double
    dot(const Point3 &a, const Point3 &b)
    {
      return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
    }



    Point3
    cross(const Point3 &a, const Point3 &b)
    {
      return {{a[1] * b[2] - a[2] * b[1],
               a[2] * b[0] - a[0] * b[2],
               a[0] * b[1] - a[1] * b[0]}};
    }



    Point3
    closest_on_triangle(const Point3 &p,
                        const Point3 &a,
                        const Point3 &b,
                        const Point3 &c)
    {
      const auto at = [&](const double v, const double w) {
        return Point3{{a[0] + v * (b[0] - a[0]) + w * (c[0] - a[0]),
                       a[1] + v * (b[1] - a[1]) + w * (c[1] - a[1]),
                       a[2] + v * (b[2] - a[2]) + w * (c[2] - a[2])}};
      };
      const Point3 ab = minus(b, a), ac = minus(c, a), ap = minus(p, a);
      const double d1 = dot(ab, ap), d2 = dot(ac, ap);
      if (d1 <= 0 && d2 <= 0)
        return a;
      const Point3 bp = minus(p, b);
      const double d3 = dot(ab, bp), d4 = dot(ac, bp);
      if (d3 >= 0 && d4 <= d3)
        return b;
      const double vc = d1 * d4 - d3 * d2;
      if (vc <= 0 && d1 >= 0 && d3 <= 0)
        return at(d1 / (d1 - d3), 0);
      const Point3 cp = minus(p, c);
      const double d5 = dot(ab, cp), d6 = dot(ac, cp);
      if (d6 >= 0 && d5 <= d6)
        return c;
      const double vb = d5 * d2 - d1 * d6;
      if (vb <= 0 && d2 >= 0 && d6 <= 0)
        return at(0, d2 / (d2 - d6));
      const double va = d3 * d6 - d5 * d4;
      if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0)
        {
          const double w = (d4 - d3) / ((d4 - d3) + (d5 - d6));
          return at(1 - w, w);
        }
      const double denominator = 1 / (va + vb + vc);
      return at(vb * denominator, vc * denominator);
    }



    Point3
    scaled(const Point3 &a, const double s)
    {
      return {{s * a[0], s * a[1], s * a[2]}};
    }


    namespace
    {
      /**
       * The length of the valid UTF-8 sequence at text[i] (a byte >= 0x80):
       * a lead byte 110xxxxx, 1110xxxx or 11110xxx and that many
       * continuation bytes 10xxxxxx, not an overlong form, a surrogate or
       * beyond U+10FFFF; 0 if it is not one.
       */
      unsigned int
      utf8_length(const std::string &text, const std::size_t i)
      {
        const auto         c      = static_cast<unsigned char>(text[i]);
        const unsigned int length = c >= 0xc2 && c <= 0xdf ? 2 :
                                    c >= 0xe0 && c <= 0xef ? 3 :
                                    c >= 0xf0 && c <= 0xf4 ? 4 :
                                                             0;
        bool               valid  = length > 0 && i + length <= text.size();
        for (unsigned int k = 1; valid && k < length; ++k)
          valid = (static_cast<unsigned char>(text[i + k]) & 0xc0) == 0x80;
        if (valid && length > 2)
          {
            const auto second = static_cast<unsigned char>(text[i + 1]);
            valid             = !(c == 0xe0 && second < 0xa0) && // overlong
                    !(c == 0xed && second > 0x9f) &&             // surrogate
                    !(c == 0xf0 && second < 0x90) &&             // overlong
                    !(c == 0xf4 && second > 0x8f);               // > U+10FFFF
          }
        return valid ? length : 0;
      }
    } // namespace



    std::string
    quoted_excerpt(const std::string &text, const std::size_t max_characters)
    {
      static const char hex[] = "0123456789abcdef";
      std::string       out;
      std::size_t       shown = 0, unprintable = 0, i = 0;
      for (; i < text.size() && shown < max_characters; ++i, ++shown)
        {
          const auto c = static_cast<unsigned char>(text[i]);
          if (c >= 0x20 && c < 0x7f)
            out += static_cast<char>(c);
          else if (const unsigned int length =
                     c >= 0x80 ? utf8_length(text, i) : 0;
                   length > 0)
            {
              out.append(text, i, length);
              i += length - 1;
            }
          else
            {
              out += "\\x";
              out += hex[c >> 4];
              out += hex[c & 0xf];
              ++unprintable;
            }
        }
      if (4 * unprintable > shown)
        return "binary data (" + std::to_string(text.size()) +
               " bytes that are not text)";
      return "'" + out + (i < text.size() ? "...'" : "'");
    }



    /**
     * @p text as a JSON string (RFC 8259, section 7): quotes, backslashes
     * and every control character below 0x20 escaped (the short forms
     * where JSON has them, \u00XX otherwise). JSON text must be UTF-8
     * (section 8.1), and a scene path may hold any bytes: a byte that does
     * not belong to a valid UTF-8 sequence becomes U+FFFD.
     */
    std::string
    json_string(const std::string &text)
    {
      std::string out = "\"";
      for (std::size_t i = 0; i < text.size(); ++i)
        {
          const auto c = static_cast<unsigned char>(text[i]);
          switch (c)
            {
              case '"':
                out += "\\\"";
                continue;
              case '\\':
                out += "\\\\";
                continue;
              case '\b':
                out += "\\b";
                continue;
              case '\f':
                out += "\\f";
                continue;
              case '\n':
                out += "\\n";
                continue;
              case '\r':
                out += "\\r";
                continue;
              case '\t':
                out += "\\t";
                continue;
              default:
                break;
            }
          if (c < 0x20)
            {
              static const char hex[] = "0123456789abcdef";
              out += "\\u00";
              out += hex[c >> 4];
              out += hex[c & 0xf];
              continue;
            }
          if (c < 0x80)
            {
              out += static_cast<char>(c);
              continue;
            }
          const unsigned int length = utf8_length(text, i);
          if (length > 0)
            {
              out.append(text, i, length);
              i += length - 1;
            }
          else
            out += "\\ufffd";
        }
      return out + "\"";
    }


  } // namespace Utilities
} // namespace palpate
