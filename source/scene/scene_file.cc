// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

// A scene file as text, before deal.II's ParameterHandler reads it: a name
// that is no regular file, a file that cannot be opened or read, one larger
// than a scene, UTF-16 or binary text, and an 'include' line are refused
// with what to give instead; and its lines, statements and subsections, by
// which the reader's messages point at the line that holds a mistake.

#include <palpate/scene/scene_impl.h>

#include <algorithm>
#include <cctype>
#include <filesystem>
#include <fstream>

namespace palpate
{
  namespace internal
  {
    namespace
    {
      /** @p line without its comment ('#' not after a backslash), trimmed. */
      std::string
      without_comment(const std::string &line)
      {
        for (std::size_t i = 0; i < line.size(); ++i)
          if (line[i] == '#' && (i == 0 || line[i - 1] != '\\'))
            return Utilities::trim(line.substr(0, i));
        return Utilities::trim(line);
      }

      /**
       * The error for a scene file that cannot be opened, with the reason the
       * file system gives.
       */
      InputError
      cannot_open(const std::string &filename)
      {
        bool              none = false;
        const std::string why  = why_cannot_open(filename, &none);
        return InputError(
          filename.substr(0, 300),
          0,
          "(the scene file itself)",
          "the file cannot be opened: " +
            (why.empty() ? std::string("it is not readable") : why),
          none ? "check the path; shipped scenes are in parameters/, e.g. "
                 "'palpate parameters/default.prm'." :
                 "name the scene's .prm file itself (check the links on "
                 "the way and the permissions).");
      }
    } // namespace



    /** The physical lines of a scene file, without line ends. */
    std::vector<std::string>
    split_lines(const std::string &content)
    {
      std::vector<std::string> lines;
      std::istringstream       in(content);
      std::string              line;
      while (std::getline(in, line))
        {
          if (!line.empty() && line.back() == '\r')
            line.pop_back();
          lines.push_back(line);
        }
      return lines;
    }

    bool
    starts_with_keyword(const std::string &line,
                        const std::string &keyword,
                        std::string       &rest)
    {
      if (line.size() < keyword.size())
        return false;
      for (unsigned int i = 0; i < keyword.size(); ++i)
        if (std::tolower(static_cast<unsigned char>(line[i])) != keyword[i])
          return false;
      if (line.size() == keyword.size())
        {
          rest.clear();
          return true;
        }
      if (line[keyword.size()] != ' ' && line[keyword.size()] != '\t')
        return false;
      rest = Utilities::trim(line.substr(keyword.size()));
      return true;
    }


    /**
     * The statement that ends on line @p last (1-based): its first line
     * and its text, continuation lines ('\' at the end) joined.
     */
    std::pair<unsigned int, std::string>
    statement_at(const std::vector<std::string> &lines, const unsigned int last)
    {
      if (last == 0 || last > lines.size())
        return {last, ""};
      unsigned int first = last;
      while (first > 1)
        {
          const std::string previous = without_comment(lines[first - 2]);
          if (previous.empty() || previous.back() != '\\')
            break;
          --first;
        }
      std::string text;
      for (unsigned int l = first; l <= last; ++l)
        {
          std::string piece = without_comment(lines[l - 1]);
          if (l < last && !piece.empty() && piece.back() == '\\')
            piece.pop_back();
          text += (text.empty() ? "" : " ") + piece;
        }
      return {first, Utilities::trim(text)};
    }

    /**
     * The subsection path in force before line @p line (1-based), and
     * where each of its subsections was opened. deal.II's ParameterHandler
     * has accepted these lines: this only finds where a message points.
     */
    std::vector<std::string>
    path_before(const std::vector<std::string> &lines,
                const unsigned int              line,
                std::vector<unsigned int>      *opened_at)
    {
      std::vector<std::string>  path;
      std::vector<unsigned int> opened;
      for (unsigned int l = 1; l < line && l <= lines.size(); ++l)
        {
          std::string       rest;
          const std::string t = without_comment(lines[l - 1]);
          if (starts_with_keyword(t, "subsection", rest))
            {
              path.push_back(rest);
              opened.push_back(l);
            }
          else if (starts_with_keyword(t, "end", rest) && rest.empty() &&
                   !path.empty())
            {
              path.pop_back();
              opened.pop_back();
            }
        }
      if (opened_at != nullptr)
        *opened_at = opened;
      return path;
    }

    /**
     * Refuse a name that is not a scene file before opening it: a directory
     * (named with the .prm files in it), or a pipe, a device or a socket.
     */
    void
    check_is_regular_file(const std::string &filename)
    {
      namespace fs = std::filesystem;
      std::error_code ec;
      if (fs::is_directory(filename, ec))
        {
          std::vector<std::string> scenes;
          for (const auto &e : fs::directory_iterator(filename, ec))
            if (e.path().extension() == ".prm")
              scenes.push_back(e.path().string());
          std::sort(scenes.begin(), scenes.end());
          throw InputError(
            filename,
            0,
            "(the scene file itself)",
            "this is a directory, not a scene file",
            scenes.empty() ?
              std::string("give a .prm scene file; shipped scenes are in "
                          "parameters/, e.g. 'palpate "
                          "parameters/default.prm'.") :
              "give one of the " + std::to_string(scenes.size()) +
                " .prm files in it, e.g. 'palpate " + scenes.front() + "'.");
        }
      if (const auto status = fs::status(filename, ec);
          !ec && fs::exists(status) && !fs::is_regular_file(status))
        throw InputError(filename.substr(0, 300),
                         0,
                         "(the scene file itself)",
                         "this is not a regular file but a pipe, a device or "
                         "a socket: palpate would wait for it, or read it "
                         "without end",
                         "name the scene's .prm file itself.");
    }

    /**
     * The scene file's bytes: an error that says why if it cannot be opened
     * or read, or if it is too large to be a scene.
     */
    std::string
    read_scene_bytes(const std::string &filename)
    {
      std::ifstream in(filename, std::ios::binary);
      if (!in)
        throw cannot_open(filename);
      // A scene is a few kB of text: refuse to read gigabytes by mistake.
      constexpr std::size_t max_bytes = std::size_t(4) << 20;
      std::string           content(max_bytes + 1, '\0');
      in.read(content.data(), content.size());
      if (in.bad())
        throw InputError(filename,
                         0,
                         "(the scene file itself)",
                         "the file cannot be read (an input/output error)",
                         "check the disk and the path.");
      content.resize(in.gcount());
      if (content.size() > max_bytes)
        throw InputError(filename,
                         0,
                         "(the scene file itself)",
                         "the file is larger than 4 MiB; a scene file is a "
                         "few kB of text",
                         "check that this is the scene (.prm) and not a mesh "
                         "or an output file.");
      return content;
    }

    /**
     * Drop a UTF-8 byte order mark from @p content; refuse UTF-16 text.
     */
    void
    strip_byte_order_mark(std::string &content, const std::string &filename)
    {
      // A byte order mark: some editors (Notepad) begin UTF-8 with one; it
      // is not part of the text. UTF-16 is not a scene file palpate reads:
      // named, instead of "a NUL byte" in column 2.
      if (content.rfind("\xEF\xBB\xBF", 0) == 0)
        content.erase(0, 3);
      else if (content.rfind("\xFF\xFE", 0) == 0 ||
               content.rfind("\xFE\xFF", 0) == 0)
        throw InputError(filename,
                         1,
                         "(the scene file itself)",
                         "the file is UTF-16 text (it begins with a UTF-16 "
                         "byte order mark); a scene file is plain text (ASCII "
                         "or UTF-8)",
                         "save it as UTF-8 (in Notepad: Save as, Encoding "
                         "UTF-8), or convert it: iconv -f UTF-16 -t UTF-8 '" +
                           filename + "' > scene.prm");
    }

    /**
     * Refuse NUL bytes and control characters (other than tabs and carriage
     * returns), naming the line and column of the first.
     */
    void
    check_plain_text(const std::string &content, const std::string &filename)
    {
      unsigned int line = 1, column = 1;
      for (const char c : content)
        {
          const auto byte = static_cast<unsigned char>(c);
          if (c == '\n')
            {
              ++line;
              column = 1;
              continue;
            }
          if (byte < 0x20 && c != '\t' && c != '\r')
            throw InputError(
              filename,
              line,
              "column " + std::to_string(column) + " of line " +
                std::to_string(line),
              "the line holds " +
                std::string(byte == 0 ? "a NUL byte" :
                                        "a control character (byte " +
                                          std::to_string(byte) + ")") +
                ", which a scene file (plain text) cannot contain",
              "delete the character, or check that this is the scene file "
              "and not a binary file.");
          ++column;
        }
    }

    /** Refuse the first 'include' line: a scene is one file. */
    void
    check_no_includes(const std::vector<std::string> &lines,
                      const std::string              &filename)
    {
      for (unsigned int l = 1; l <= lines.size(); ++l)
        {
          std::string rest;
          if (starts_with_keyword(without_comment(lines[l - 1]),
                                  "include",
                                  rest))
            throw InputError(filename,
                             l,
                             without_comment(lines[l - 1]),
                             "scene files cannot include other files",
                             "copy the entries you need into this file.");
        }
    }
  } // namespace internal
} // namespace palpate
