// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

#include <palpate/base/exceptions.h>

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <sstream>

namespace palpate
{
  namespace
  {
    std::string
    format_input_error(const std::string &file,
                       const unsigned int line,
                       const std::string &entry,
                       const std::string &problem,
                       const std::string &fix)
    {
      std::ostringstream s;
      s << "in file '" << file << "'";
      if (line > 0)
        s << ", line " << line;
      s << "\n  entry:   " << entry << "\n  problem: " << problem
        << "\n  fix:     " << fix;
      return s.str();
    }
  } // namespace



  InputError::InputError(const std::string &file,
                         const unsigned int line,
                         const std::string &entry,
                         const std::string &problem,
                         const std::string &fix)
    : std::runtime_error(format_input_error(file, line, entry, problem, fix))
    , file_(file)
    , line_(line)
    , entry_(entry)
    , problem_(problem)
    , fix_(fix)
  {}



  NotAvailableError::NotAvailableError(const std::string &what,
                                       const std::string &where)
    : std::runtime_error(what +
                         " is not available in this version of palpate."
                         "\n  " +
                         where)
  {}
} // namespace palpate

namespace palpate
{
  void
  check_file_size(const std::string   &file,
                  const std::string   &entry,
                  const std::uintmax_t max_bytes,
                  const std::string   &typical)
  {
    namespace fs = std::filesystem;
    std::error_code       error;
    const fs::file_status status = fs::status(file, error);
    if (error || !fs::exists(status) || fs::is_directory(status))
      return; // the reader says what is wrong with it
    if (!fs::is_regular_file(status))
      throw InputError(file,
                       0,
                       entry,
                       "this is not a regular file but a device, a pipe or "
                       "a socket: it would be read without end",
                       "name the file itself.");
    const std::uintmax_t size = fs::file_size(file, error);
    if (!error && size > max_bytes)
      throw InputError(file,
                       0,
                       entry,
                       "the file has " + std::to_string(size >> 20) +
                         " MiB, more than the " +
                         std::to_string(max_bytes >> 20) +
                         " MiB palpate reads for it (" + typical + ")",
                       "check that this is the right file; a body with more "
                       "nodes than a few hundred thousand cannot be solved "
                       "at haptic rates: make a coarser mesh (palpate mesh "
                       "SURFACE OUT.msh --nodes 4000).");
  }



  std::string
  why_cannot_open(const std::string &file, bool *missing)
  {
    // O_NONBLOCK: a named pipe must not wait here for a writer.
    const int fd  = ::open(file.c_str(), O_RDONLY | O_CLOEXEC | O_NONBLOCK);
    const int why = fd < 0 ? errno : 0;
    if (fd >= 0)
      ::close(fd);
    const bool none = why == ENOENT || why == ENOTDIR;
    if (missing != nullptr)
      *missing = none;
    if (fd >= 0)
      return "";
    if (const std::string link = dangling_link(file); none && !link.empty())
      return "it " + link.substr(link.find("' is ") + 2);
    return none                ? "it does not exist" :
           why == EACCES       ? "it is not readable (permissions)" :
           why == ELOOP        ? "it is a loop of symbolic links" :
           why == ENAMETOOLONG ? "the path is longer than the system allows" :
                                 std::strerror(why);
  }



  std::string
  dangling_link(const std::string &path)
  {
    namespace fs = std::filesystem;
    std::error_code error;
    // A trailing slash would make the system follow the link.
    fs::path plain(path);
    while (plain.has_relative_path() && !plain.has_filename())
      plain = plain.parent_path();
    // A loop of links is not "not_found" (ELOOP), and is said as a loop.
    if (!fs::is_symlink(fs::symlink_status(plain, error)) ||
        fs::status(plain, error).type() != fs::file_type::not_found)
      return "";
    const fs::path target = fs::read_symlink(plain, error);
    return "'" + plain.string() + "' is a symbolic link to '" +
           target.string().substr(0, 300) + "', which does not exist";
  }
} // namespace palpate
