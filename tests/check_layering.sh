#!/usr/bin/env bash
# SPDX-License-Identifier: LGPL-2.1-or-later
# Fails if a file of the library includes a header of an area above its own
# (doc/architecture.md, "Layers"). The areas, lowest first:
#   base <- scene <- mesh <- hyperelastic <- state_space <- engine <- haptics <- app
# A file in source/AREA or include/palpate/AREA may include
# <palpate/OTHER/...> only if OTHER is AREA or below it. The includes that
# break this today are listed in tests/layering-exceptions.txt, each with its
# reason: a new one fails, and one that is fixed must leave the list.
#   check_layering.sh SOURCE_DIR
set -u
cd "$1"
layers="base scene mesh hyperelastic state_space engine haptics app"
rank() {
  local i=0
  for l in $layers; do
    [ "$l" = "$1" ] && { echo $i; return; }
    i=$((i + 1))
  done
  echo -1
}
exceptions=tests/layering-exceptions.txt
found=$(mktemp)
trap 'rm -f "$found"' EXIT
for f in $(find source include/palpate -name '*.h' -o -name '*.cc' | sort); do
  case $f in
    source/*) area=$(echo "$f" | cut -d/ -f2) ;;
    include/palpate/*) area=$(echo "$f" | cut -d/ -f3) ;;
  esac
  mine=$(rank "$area")
  [ "$mine" -lt 0 ] && continue # source/main.cc: the program, above all
  grep -o '^[[:space:]]*#[[:space:]]*include[[:space:]]*<palpate/[a-z_]*/[^>]*>' "$f" |
    sed 's/.*<palpate\/\([a-z_]*\)\/\([^>]*\)>.*/\1 \2/' |
    while read -r other header; do
      theirs=$(rank "$other")
      if [ "$theirs" -gt "$mine" ]; then
        echo "$f palpate/$other/$header" >> "$found"
      fi
    done
done
bad=0
while read -r file header; do
  if ! grep -q "^$file $header " "$exceptions"; then
    echo "upward include: $file includes <$header>, an area above its own"
    bad=1
  fi
done < "$found"
while read -r file header reason; do
  case $file in ''|'#'*) continue ;; esac
  if ! grep -q "^$file $header\$" "$found"; then
    echo "fixed, or gone: '$file $header' is in $exceptions but not in the code; remove its line"
    bad=1
  fi
done < "$exceptions"
if [ $bad = 0 ]; then
  echo "the include layering holds ($(wc -l < "$found") listed exceptions)"
else
  echo "layers, lowest first: $layers (doc/architecture.md)"
fi
exit $bad
