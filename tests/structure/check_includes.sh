#!/usr/bin/env bash
# The library boundary and the stage folders (issue 28 item 8, issue 42 item 5):
# - the SLAM library (include/ and src/) includes only its own headers: every #include
#   "mrpt_yesslam/..." of it names a file in include/, never one of the tools' tree (tools/: the
#   simulator, renderer, evaluator and command-line jobs), which the installed library does not have;
# - its stage folders, and the tools' folders above them, depend on each other without cycles: an
#   edge A -> B for every #include "mrpt_yesslam/B/..." in folder A, and coreutils' tsort finds any loop.
# Usage: check_includes.sh LIBRARY_FOLDER (mrpt_yesslam/ of the source tree).
set -euo pipefail
lib="$1"
[ -d "$lib/src" ] && [ -d "$lib/include/mrpt_yesslam" ] && [ -d "$lib/tools/src" ] \
  || { echo "check_includes: $lib: not the library's folder (src/, include/, tools/)" >&2; exit 1; }
bad=""
while IFS= read -r hit; do
  file="${hit%%:*}"; inc="$(sed -E 's|.*#include "([^"]+)".*|\1|' <<< "${hit#*:}")"
  [ -f "$lib/include/$inc" ] || bad+="$file includes $inc, which is not a header of the SLAM library"$'\n'
done < <(grep -rHoE '#include "mrpt_yesslam/[^"]+"' "$lib/src" "$lib/include")
if [ -n "$bad" ]; then
  echo "check_includes: the SLAM library reaches outside itself:" >&2
  head -20 <<< "$bad" >&2
  exit 1
fi
edges=""
for tree in "$lib" "$lib/tools"; do
  for dir in "$tree"/src/*/; do
    m="$(basename "$dir")"
    for dep in $(grep -rhoE '#include "mrpt_yesslam/[a-z_]+/' "$tree/src/$m" "$tree/include/mrpt_yesslam/$m" 2>/dev/null | sed -E 's|.*mrpt_yesslam/([a-z_]+)/|\1|' | sort -u); do
      [ "$dep" = "$m" ] || edges+="$dep $m"$'\n'
    done
  done
done
[ -n "$edges" ] || { echo "check_includes: no includes found under $lib" >&2; exit 1; }
if ! out="$(tsort <<< "$edges" 2>&1 >/dev/null)" || [ -n "$out" ]; then
  echo "check_includes: the stage folders include each other in a cycle:" >&2
  head -20 <<< "$out" >&2
  exit 1
fi
echo "check_includes: the SLAM library includes only its own headers; $(wc -l <<< "$edges") dependencies between folders, no cycle"
