#!/usr/bin/env bash
# Every C++ file of the project is as Debian 12's clang-format 14 formats it with .clang-format
# (issue 66 item 2: 120 columns). Usage: check_format.sh SOURCE_DIR. To format: scripts/format.sh.
set -euo pipefail
src="$1"
cd "$src"
[ -f .clang-format ] || { echo "check_format: $src: no .clang-format" >&2; exit 1; }
cf=$(command -v clang-format-14 || true)
[ -n "$cf" ] || { echo "check_format: clang-format-14 is not installed (apt install clang-format-14; scripts/install_deps.sh does)" >&2; exit 1; }
mapfile -t files < <(find mrpt_yesslam apps rawlog_tools tests bench examples -name '*.cpp' -o -name '*.h' | sort)
[ "${#files[@]}" -gt 100 ] || { echo "check_format: only ${#files[@]} C++ files under $src" >&2; exit 1; }
if ! log=$("$cf" --dry-run -Werror "${files[@]}" 2>&1); then
  bad=$(printf '%s\n' "$log" | grep -oE '^[^:]+\.(cpp|h):[0-9]+' | cut -d: -f1 | sort -u)
  echo "check_format: $(printf '%s\n' "$bad" | wc -l) of ${#files[@]} files are not formatted (run scripts/format.sh): $(printf '%s\n' "$bad" | head -10 | tr '\n' ' ')" >&2
  exit 1
fi
echo "check_format: ${#files[@]} files formatted"
