// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

// A bad option to palpate serve under mpirun (-np 3) with the MPI engine:
// the servers read the scene and wait as solver servers before rank 0 reads
// the options. Rank 0 reports the option and ends with the input-error
// status, and releases the servers, which end too (before, they waited
// for an engine that never came, and the run hung; the harness's time
// limit fails this test then).

#include <palpate/app/application.h>
#include <palpate/engine/mpi_engine.h>

#include <mpi.h>

#include <sstream>

#include "../tests.h"

int
main(int argc, char **argv)
{
  palpate::Environment env(argc, argv);
  // The shipped beam with the MPI engine (the later Engine subsection
  // overrides the first).
  if (palpate::mpi_rank() == 0)
    write_file("beam-mpi.prm",
               read_file(palpate_source_dir + "/parameters/beam.prm") +
                 "\nsubsection Engine\n  set Type = mpi\nend\n");
  MPI_Barrier(MPI_COMM_WORLD);

  const char *args[] = {"palpate", "serve", "beam-mpi.prm", "--port", "x"};
  std::ostringstream out, err;
  const int          status =
    palpate::run_application(5, const_cast<char **>(args), out, err);
  if (palpate::mpi_rank() > 0)
    return status == palpate::ExitStatus::success ? 0 : 1;

  initlog();
  deallog << "input-error status: "
          << ok(status == palpate::ExitStatus::input_error)
          << ", the option named: "
          << ok(err.str().find("--port x") != std::string::npos)
          << ", with the fix: "
          << ok(err.str().find("--port 8080") != std::string::npos)
          << std::endl;
  deallog << "the servers were released (this line is reached on every rank)"
          << std::endl;
}
