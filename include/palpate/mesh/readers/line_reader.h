// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

#ifndef palpate_mesh_readers_line_reader_h
#define palpate_mesh_readers_line_reader_h

#include <palpate/base/exceptions.h>
#include <palpate/base/utilities.h>

#include <fstream>
#include <sstream>
#include <string>
#include <vector>

namespace palpate
{
  /**
   * What the mesh file readers (read_mesh_file()) share: reading a text
   * file by lines with their numbers, its tokens and numbers, and the
   * errors they report.
   */
  namespace mesh_readers
  {
    /**
     * The error for a file that exists but cannot be read: not "empty" and
     * not "not a mesh file", which would send the user looking for the
     * wrong problem. @p reason is the system's, e.g. "Permission denied".
     */
    InputError
    unreadable(const std::string &filename, const std::string &reason);

    /** The system's reason for the last failed call, "" if it gave none. */
    std::string
    system_reason();

    /** Reads a text file line by line, keeping line numbers for messages. */
    class LineReader
    {
    public:
      /** Open @p filename; a file that cannot be opened is reported by
       * next(). */
      explicit LineReader(const std::string &filename);

      /** The next non-empty line, trimmed; false at the end of the file. */
      bool
      next(std::string &line);

      /** The next line; an error naming @p what if the file ends. */
      std::string
      expect(const std::string &what);

      /** An InputError at the current line of the file. */
      InputError
      error(const std::string &problem, const std::string &fix) const;

      /** The file read. */
      const std::string filename;
      /** Its stream. */
      std::ifstream in;
      /** The number of the line read last (from 1). */
      unsigned int number = 0;
    };

    /** @p token as a number of type T; an error naming @p what at the
     * reader's line if it is not one as a whole. */
    template <typename T>
    T
    parse_number(LineReader &reader, const std::string &token, const char *what)
    {
      std::istringstream s(token);
      T                  value;
      s >> value;
      if (s.fail() || !s.eof())
        throw reader.error(Utilities::quoted_excerpt(token) +
                             " is not a valid " + what,
                           "check the line; the file may be damaged.");
      return value;
    }

    /** The white-space separated tokens of @p line. */
    std::vector<std::string>
    tokens_of(const std::string &line);
  } // namespace mesh_readers
} // namespace palpate

#endif
