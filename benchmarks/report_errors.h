// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

// How a benchmark's main() reports an error: as the palpate program does.

#ifndef palpate_benchmarks_report_errors_h
#define palpate_benchmarks_report_errors_h

#include <palpate/app/application.h>
#include <palpate/base/exceptions.h>

#include <exception>
#include <iostream>
#include <string>

/**
 * Runs the benchmark @p body with @p argc and @p argv and returns its exit
 * status. An exception that leaves @p body is printed as the palpate
 * program prints it (palpate::run_application()): an InputError as "the
 * input has a problem" with its file, entry and fix, and exit status
 * ExitStatus::input_error; any other exception with its message and exit
 * status 1 (in a benchmark that is as often the machine, e.g. no network
 * namespaces, as a bug). An exception that left main() would end the
 * benchmark in std::terminate, which names the exception's type and not
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
