#!/usr/bin/env bash
# No source file of the library grows past MAX lines (issue 28 item 8: a 1,081-line CSparseMap held
# storage, culling rules, window selection, correction maths and serialisation together; it is
# split by responsibility now, and a file this long again is a sign that one has taken on more).
# Usage: check_sizes.sh LIBRARY_FOLDER MAX
set -euo pipefail
lib="$1"; max="$2"
[ -d "$lib/src" ] || { echo "check_sizes: $lib: not the library's folder" >&2; exit 1; }
over=0; n=0
while IFS= read -r f; do
  n=$((n + 1))
  lines=$(wc -l < "$f")
  if [ "$lines" -gt "$max" ]; then echo "check_sizes: ${f#$lib/}: $lines lines (at most $max)" >&2; over=1; fi
done < <(find "$lib/src" "$lib/include" "$lib/tools" -name '*.cpp' -o -name '*.h')
[ "$n" -gt 0 ] || { echo "check_sizes: no sources under $lib" >&2; exit 1; }
[ "$over" = 0 ] || exit 1
echo "check_sizes: $n files, none over $max lines"
