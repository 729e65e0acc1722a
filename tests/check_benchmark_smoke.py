#!/usr/bin/env python3
# SPDX-License-Identifier: LGPL-2.1-or-later
#
#   check_benchmark_smoke.py NAME DIRECTORY PROGRAM [ARGUMENT...]
#
# Runs a benchmark's smoke (PROGRAM --smoke, registered by
# benchmarks/CMakeLists.txt) in DIRECTORY, made empty first so that the
# files a benchmark writes where it runs (CSV, meshes, stores) stay out of
# the build tree's other directories and a run never reads an earlier one's.
# Passes if the program exits with 0, prints at least one line
# "RESULT NAME ..." and every line that begins with "RESULT " is
# "RESULT NAME" followed by key=value tokens, neither side empty: what
# benchmarks/run promises and what the results' readers split on.
# Prints the benchmark's output, then what is wrong, if anything.

import os
import re
import shutil
import subprocess
import sys
import time

TOKEN = re.compile(r"[^=\s]+=\S+")


def problems(name, status, output):
    """Every way the run breaks the promise, one sentence each."""
    found = []
    if status != 0:
        found.append(f"benchmark_{name} exited with status {status}, not 0")
    results = [line for line in output.splitlines() if line.startswith("RESULT ")]
    if not any(line.startswith(f"RESULT {name} ") for line in results):
        found.append(f"no line 'RESULT {name} key=value ...' was printed")
    for line in results:
        words = line.split()
        if words[1] != name:
            found.append(f"a RESULT line names '{words[1]}', not '{name}': {line}")
            continue
        bad = [w for w in words[2:] if not TOKEN.fullmatch(w)]
        if len(words) < 3 or bad:
            found.append(
                "a RESULT line is not 'RESULT NAME key=value ...' "
                f"({', '.join(bad) if bad else 'no key=value'}): {line}"
            )
    return found


def main():
    if len(sys.argv) < 4:
        sys.exit("usage: check_benchmark_smoke.py NAME DIRECTORY PROGRAM [ARGUMENT...]")
    name, directory, command = sys.argv[1], sys.argv[2], sys.argv[3:]
    # The program runs in DIRECTORY: a relative path is the caller's.
    if os.sep in command[0]:
        command[0] = os.path.abspath(command[0])
    shutil.rmtree(directory, ignore_errors=True)
    os.makedirs(directory)
    start = time.monotonic()
    run = subprocess.run(
        command,
        cwd=directory,
        stdout=subprocess.PIPE,
        stderr=subprocess.STDOUT,
        text=True,
        errors="replace",
    )
    seconds = time.monotonic() - start
    sys.stdout.write(run.stdout)
    found = problems(name, run.returncode, run.stdout)
    print(f"\ncheck_benchmark_smoke: {' '.join(command)}: {seconds:.1f} s")
    for p in found:
        print(f"check_benchmark_smoke: {p}")
    sys.exit(1 if found else 0)


if __name__ == "__main__":
    main()
