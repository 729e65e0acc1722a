// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

// How a benchmark's main() reports an error: as the palpate program does.

#ifndef palpate_benchmarks_report_errors_h
#define palpate_benchmarks_report_errors_h

#include <palpate/app/application.h>
#include <palpate/base/exceptions.h>

#include <exception>
#include <iostream>
#include <limits>
#include <stdexcept>
#include <string>

/**
 * The value @p text of the command-line option @p option as a whole
 * number from @p low to @p high. std::stoul takes "-1" and "3x" (as
 * 2^64 - 1 and 3): a count of runs or targets read so would never end.
 * This refuses them, naming the option (report_errors() reports it as an
 * input error).
 */
inline unsigned int
whole_number(const std::string &option,
             const std::string &text,
             const unsigned int low  = 0,
             const unsigned int high = std::numeric_limits<unsigned int>::max())
{
  std::size_t end   = 0;
  long long   value = -1;
  try
    {
      value = std::stoll(text, &end);
    }
  catch (const std::logic_error &)
    {
      end = 0;
    }
  if (text.empty() || end != text.size() || value < low || value > high)
    throw std::invalid_argument(option + " must be a whole number from " +
                                std::to_string(low) + " to " +
                                std::to_string(high) + ", not '" + text + "'");
  return static_cast<unsigned int>(value);
}

/**
 * Runs the benchmark @p body with @p argc and @p argv and returns its exit
 * status. An exception that leaves @p body is printed as the palpate
 * program prints it (palpate::run_application()): an InputError as "the
 * input has a problem" with its file, entry and fix, and exit status
 * ExitStatus::input_error (so is an option's value that std::stoi and
 * the like, or the benchmark's own check, refuses); any other exception with
 * its message and exit status 1 (in a benchmark that is as often the machine,
 * e.g. no network namespaces, as a bug). An exception that left main() would
 * end the benchmark in std::terminate, which names the exception's type and not
 * the file and entry at fault. @p name is the benchmark's name
 * (benchmarks/NAME.cc), for the banner.
 */
inline int
report_errors(const std::string &name,
              int (*body)(int, char **),
              int    argc,
              char **argv)
{
  const std::string who = "\nbenchmarks/run " + name + ": ";
  try
    {
      return body(argc, argv);
    }
  catch (const palpate::InputError &e)
    {
      std::cout.flush();
      std::cerr << who << "the input has a problem, " << e.what() << std::endl;
      return palpate::ExitStatus::input_error;
    }
  catch (const palpate::NotAvailableError &e)
    {
      std::cout.flush();
      std::cerr << who << e.what() << std::endl;
      return palpate::ExitStatus::not_available;
    }
  catch (const palpate::OutputError &e)
    {
      std::cout.flush();
      std::cerr << who << "output failed: " << e.what() << std::endl;
      return palpate::ExitStatus::output_failed;
    }
  catch (const std::logic_error &e)
    {
      // An option's value the benchmark could not read: std::stoi, stoul,
      // stod (whose message is only the function's name), or its own check
      // of the option (whose message begins with the option, "--engine
      // must be ...").
      std::cout.flush();
      const std::string what = e.what();
      const bool        sto =
        what.rfind("sto", 0) == 0 && what.find(' ') == std::string::npos;
      if (sto || what.rfind("--", 0) == 0)
        {
          std::cerr << who
                    << "the input has a problem, in file 'command line': "
                    << (sto ? "a value given to an option is not a number, or "
                              "is out of range (" +
                                what + ")" :
                              what)
                    << ".\n  fix:     see the usage (benchmarks/run " << name
                    << " --help prints it)." << std::endl;
          return palpate::ExitStatus::input_error;
        }
      std::cerr << who << what << std::endl;
      return palpate::ExitStatus::internal_error;
    }
  catch (const std::exception &e)
    {
      std::cout.flush();
      std::cerr << who << e.what() << std::endl;
      return palpate::ExitStatus::internal_error;
    }
  catch (...)
    {
      std::cout.flush();
      std::cerr << who << "an exception of unknown type." << std::endl;
      return palpate::ExitStatus::internal_error;
    }
}

#endif
