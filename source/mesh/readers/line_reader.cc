// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

#include <palpate/mesh/readers/line_reader.h>

#include <cerrno>
#include <cstring>
#include <filesystem>

namespace palpate
{
  namespace mesh_readers
  {
    InputError
    unreadable(const std::string &filename, const std::string &reason)
    {
      return InputError(filename,
                        0,
                        "mesh file",
                        "the file cannot be read" + (reason.empty() ?
                                                       std::string() :
                                                       " (" + reason + ")"),
                        "check that the path names the mesh file itself and "
                        "that you may read it (permissions, the disk, a "
                        "network mount).");
    }

    std::string
    system_reason()
    {
      return errno != 0 ? std::strerror(errno) : "";
    }

    LineReader::LineReader(const std::string &filename)
      : filename(filename)
      , in(filename)
    {}

    bool
    LineReader::next(std::string &line)
    {
      std::string raw;
      while (std::getline(in, raw))
        {
          ++number;
          // A byte order mark (some Windows tools begin UTF-8 with one)
          // is not part of the first line; UTF-16 is no mesh text.
          if (number == 1 && raw.rfind("\xEF\xBB\xBF", 0) == 0)
            raw.erase(0, 3);
          else if (number == 1 && (raw.rfind("\xFF\xFE", 0) == 0 ||
                                   raw.rfind("\xFE\xFF", 0) == 0))
            throw error("the file is UTF-16 text (it begins with a UTF-16 "
                        "byte order mark); mesh files are ASCII",
                        "export it again as ASCII, or convert it: iconv -f "
                        "UTF-16 -t UTF-8 '" +
                          filename + "' > mesh" +
                          std::filesystem::path(filename).extension().string());
          line = Utilities::trim(raw);
          if (!line.empty())
            return true;
        }
      // A read error ends getline() as the end of the file does; only
      // the stream state tells them apart.
      if (!in.is_open() || in.bad())
        throw unreadable(filename, errno != 0 ? std::strerror(errno) : "");
      return false;
    }

    std::string
    LineReader::expect(const std::string &what)
    {
      std::string line;
      if (!next(line))
        throw error("the file ends where " + what + " was expected",
                    "the file is truncated; write it again from the mesh "
                    "generator.");
      return line;
    }

    InputError
    LineReader::error(const std::string &problem, const std::string &fix) const
    {
      return InputError(filename, number, "mesh file", problem, fix);
    }

    std::vector<std::string>
    tokens_of(const std::string &line)
    {
      std::istringstream       s(line);
      std::vector<std::string> tokens;
      std::string              t;
      while (s >> t)
        tokens.push_back(t);
      return tokens;
    }
  } // namespace mesh_readers
} // namespace palpate
