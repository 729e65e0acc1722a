// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

#ifndef palpate_base_utilities_h
#define palpate_base_utilities_h

#include <array>
#include <chrono>
#include <string>
#include <vector>

namespace palpate
{
  /**
   * Small string and geometry helpers shared by every part of palpate. They
   * depend on the standard library only, so the real-time side may use them.
   */
  namespace Utilities
  {
    /** A point or vector in 3-D space, in metres unless stated otherwise. */
    using Point3 = std::array<double, 3>;

    /** Wall-clock seconds since @p start, on the steady clock that every
     * timing in palpate uses. */
    inline double
    seconds_since(const std::chrono::steady_clock::time_point start)
    {
      return std::chrono::duration<double>(std::chrono::steady_clock::now() -
                                           start)
        .count();
    }

    /** @p s without leading and trailing white space. */
    std::string
    trim(const std::string &s);

    /** Whether the whole of @p s is a base-10 whole number that fits a
     * long (then in @p value): "3x", "", "3.0" and 1e30 are not. */
    bool
    parse_whole_number(const std::string &s, long &value);

    /** @p s split at @p separator, each piece trimmed; empty pieces kept. */
    std::vector<std::string>
    split(const std::string &s, const char separator);

    /** Levenshtein edit distance between @p a and @p b, case-insensitive. */
    unsigned int
    edit_distance(const std::string &a, const std::string &b);

    /**
     * The candidate closest to @p word by edit distance, or "" if none is
     * close enough to be a plausible typo (distance more than a third of the
     * word's length, at least 3).
     */
    std::string
    closest_match(const std::string              &word,
                  const std::vector<std::string> &candidates);

    /** Euclidean norm of @p v. */
    double
    norm(const Point3 &v);

    /** Euclidean distance between @p a and @p b. */
    double
    distance(const Point3 &a, const Point3 &b);

    /** a - b. */
    Point3
    minus(const Point3 &a, const Point3 &b);

    /** a . b. */
    double
    dot(const Point3 &a, const Point3 &b);

    /** a x b. */
    Point3
    cross(const Point3 &a, const Point3 &b);

    /** The point of triangle (@p a, @p b, @p c) closest to @p p (Ericson,
     * Real-Time Collision Detection, 5.1.5). */
    Point3
    closest_on_triangle(const Point3 &p,
                        const Point3 &a,
                        const Point3 &b,
                        const Point3 &c);

    /** s a. */
    Point3
    scaled(const Point3 &a, const double s);

    /** Format @p x with @p precision significant digits (no trailing
     * zeros, scientific notation for very small or large numbers). */
    std::string
    to_string(const double x, const unsigned int precision = 6);

    /**
     * @p x as to_string() shows it (six significant digits) unless that
     * reads back as another double; then with the fewest digits that read
     * back as @p x: 0.5 stays "0.5", 0.1 stays "0.1", 0.4999999 stays
     * "0.4999999" (which six digits would show as 0.5), 1/3 gets its 16-17
     * digits. For values the user set, echoed back (a material's
     * constants, the JSON summary).
     */
    std::string
    to_string_exact(const double x);

    /**
     * @p x with @p precision significant digits, or as many more as it
     * takes to tell it from @p from as to_string() shows that: a value
     * just over a limit must not read as the limit ("0.0271 m deep, more
     * than ... 0.0271 m"; "1e+13 Pa, more than 1e+13 Pa").
     */
    std::string
    to_string_apart(const double       x,
                    const double       from,
                    const unsigned int precision = 3);

    /** Format @p p as "x, y, z" with @p precision significant digits. */
    std::string
    to_string(const Point3 &p, const unsigned int precision = 6);

    /**
     * Parse "x, y, z" (three numbers separated by commas) into a Point3.
     * Throws std::invalid_argument with a readable message otherwise.
     */
    Point3
    parse_point(const std::string &text);

    /**
     * Text read from a file, for a message: in quotes, at most
     * @p max_characters characters (then "..."), bytes that are neither
     * printable ASCII nor valid UTF-8 as \xNN; if more than a quarter of
     * it is such bytes, "binary data (N bytes that are not text)" instead
     * of echoing it to the terminal.
     */
    std::string
    quoted_excerpt(const std::string &text,
                   const std::size_t  max_characters = 60);

    /**
     * @p text as a JSON string, quotes included (RFC 8259, section 7):
     * quotes, backslashes and every control character escaped, bytes that
     * are not valid UTF-8 as U+FFFD. The one JSON escaper of the run
     * summaries and the live view.
     */
    std::string
    json_string(const std::string &text);
  } // namespace Utilities
} // namespace palpate

#endif
