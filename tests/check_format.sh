#!/usr/bin/env bash
# SPDX-License-Identifier: LGPL-2.1-or-later
# Fails if a C++ file of the project is not formatted with .clang-format.
#   check_format.sh CLANG_FORMAT SOURCE_DIR
set -u
clang_format=$1
cd "$2"
bad=0
for f in $(find include source tests benchmarks doc/examples -name '*.h' -o -name '*.cc' | sort); do
  if ! "$clang_format" --dry-run --Werror "$f" >/dev/null 2>&1; then
    echo "not formatted: $f"
    bad=1
  fi
done
[ $bad = 0 ] && echo "all C++ files are formatted" || echo "run: clang-format -i <file> (clang-format 14, .clang-format)"
exit $bad
