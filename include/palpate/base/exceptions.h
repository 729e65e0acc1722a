// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

#ifndef palpate_base_exceptions_h
#define palpate_base_exceptions_h

#include <cstdint>
#include <stdexcept>
#include <string>

namespace palpate
{
  /**
   * palpate could not write an output file (the directory removed, the disk
   * full) after the work itself was done: the message names the file and
   * the reason; what was computed is reported before it.
   */
  class OutputError : public std::runtime_error
  {
  public:
    using std::runtime_error::runtime_error;
  };



  /**
   * An error in what the user gave us: a scene file, a mesh file, a command
   * line. It always says where (file and, if known, line), which entry, what
   * is wrong with it, and what to do about it. `main()` prints it as a banner
   * and exits with status 2; tests print it verbatim.
   */
  class InputError : public std::runtime_error
  {
  public:
    /**
     * @param file    The file that holds the bad input (scene, mesh, CSV),
     *                or "command line".
     * @param line    Line number in @p file, 0 if unknown or not applicable.
     * @param entry   The entry, e.g. "Material model / Model name", or the
     *                mesh element, e.g. "element 17".
     * @param problem One or two sentences: what is wrong.
     * @param fix     One or two sentences: what the user should do.
     */
    InputError(const std::string &file,
               const unsigned int line,
               const std::string &entry,
               const std::string &problem,
               const std::string &fix);

    /** The file that holds the bad input. */
    const std::string &
    file() const
    {
      return file_;
    }

    /** Line number in file(), 0 if unknown. */
    unsigned int
    line() const
    {
      return line_;
    }

    /** The entry that is wrong. */
    const std::string &
    entry() const
    {
      return entry_;
    }

    /** What is wrong. */
    const std::string &
    problem() const
    {
      return problem_;
    }

    /** What to do about it. */
    const std::string &
    fix() const
    {
      return fix_;
    }

  private:
    std::string  file_;
    unsigned int line_;
    std::string  entry_;
    std::string  problem_;
    std::string  fix_;
  };

  /**
   * Before a file other than the scene is read whole (a mesh, a surface, a
   * recording): throws an InputError naming @p file and @p entry if it is
   * not a regular file (a device such as /dev/zero, a pipe, a directory
   * would be read without end) or has more than @p max_bytes, with
   * @p typical ("a liver of 8,000 nodes has about 2 MiB") in the message.
   * A file that does not exist or cannot be examined passes: the reader's
   * own message says so. Nothing is allocated before this check.
   */
  void
  check_file_size(const std::string   &file,
                  const std::string   &entry,
                  const std::uintmax_t max_bytes,
                  const std::string   &typical);

  /**
   * Why @p file cannot be opened for reading, as the file system says it
   * ("it does not exist", "it is a loop of symbolic links", "the path is
   * longer than the system allows", "it is not readable (permissions)"),
   * or an empty string if it can. @p missing, if given, is set when the
   * file does not exist (so the caller can say where it looked). Every
   * reader of a user's file reports a refused path through this, so a loop
   * of links is never called a missing file.
   */
  std::string
  why_cannot_open(const std::string &file, bool *missing = nullptr);

  /**
   * If @p path is a symbolic link whose target does not exist, says so
   * ("'a.h5' is a symbolic link to '/mnt/x/a.h5', which does not exist");
   * otherwise an empty string. A writer that followed such a link would
   * make a file somewhere else or fail at its end, and "does not exist,
   * mkdir -p" would be the wrong fix: the path is there, its target is not.
   */
  std::string
  dangling_link(const std::string &path);

  /**
   * A capability that a scene asks for but that this version of palpate
   * does not have yet. Reported like an InputError, but it is not the
   * user's fault, so the message says which capability and where it is
   * tracked.
   */
  class NotAvailableError : public std::runtime_error
  {
  public:
    /**
     * @param what  The capability, e.g. "the Mooney-Rivlin solver".
     * @param where What the user can do instead.
     */
    NotAvailableError(const std::string &what, const std::string &where);
  };
} // namespace palpate

#endif
