#!/usr/bin/env bash
# The library's stage folders depend on each other without cycles (issue 28 item 8): an edge
# A -> B for every #include "mrpt_yesslam/B/..." in include/mrpt_yesslam/A or src/A, and coreutils'
# tsort finds any loop. Usage: check_includes.sh LIBRARY_FOLDER (mrpt_yesslam/ of the source tree).
set -euo pipefail
lib="$1"
[ -d "$lib/src" ] && [ -d "$lib/include/mrpt_yesslam" ] || { echo "check_includes: $lib: not the library's folder" >&2; exit 1; }
edges=""
for dir in "$lib"/src/*/; do
  m="$(basename "$dir")"
  for dep in $(grep -rhoE '#include "mrpt_yesslam/[a-z_]+/' "$lib/src/$m" "$lib/include/mrpt_yesslam/$m" 2>/dev/null | sed -E 's|.*mrpt_yesslam/([a-z_]+)/|\1|' | sort -u); do
    [ "$dep" = "$m" ] || edges+="$dep $m"$'\n'
  done
done
[ -n "$edges" ] || { echo "check_includes: no includes found under $lib" >&2; exit 1; }
if ! out="$(tsort <<< "$edges" 2>&1 >/dev/null)" || [ -n "$out" ]; then
  echo "check_includes: the stage folders include each other in a cycle:" >&2
  head -20 <<< "$out" >&2
  exit 1
fi
echo "check_includes: $(wc -l <<< "$edges") dependencies between stage folders, no cycle"
