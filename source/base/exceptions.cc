// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

#include <palpate/base/exceptions.h>

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
