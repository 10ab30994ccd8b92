#!/usr/bin/env bash
# Docs that cannot drift (issue 66 item 4): every class, source file, option key and command-line
# flag README.md and docs/*.md name in `code` exists. Classes (CName, TName) must be words of the
# sources; paths with a source-like extension must be files of the repository (or of the library's
# include/src folders); `[Section] key` must be a key of that section of default.ini; a --flag must be
# one our tools print in --help or our scripts and benches take (flags of other programs, named after
# the program inside the same code span, are not checked).
# Usage: check_doc_names.sh SOURCE_DIR TOOLS_DIR
set -euo pipefail
src="$1"; tools="$2"
cd "$src"
[ -f README.md ] && [ -d docs ] || { echo "check_doc_names: $src: no README.md and docs/" >&2; exit 1; }
[ -x "$tools/yesslam" ] || { echo "check_doc_names: $tools: no yesslam (build the tools first)" >&2; exit 1; }
ini=share/mrpt_yesslam/config/default.ini
tmp=$(mktemp -d); trap 'rm -rf "$tmp"' EXIT
# Code spans outside fenced blocks, one per line, with the file they are in.
for md in README.md docs/*.md; do
  awk -v f="$md" '/^```/ { fence = !fence; next } !fence { while (match($0, /`[^`]+`/)) { print f "\t" substr($0, RSTART + 1, RLENGTH - 2); $0 = substr($0, RSTART + RLENGTH) } }' "$md"
done > "$tmp/spans"
find mrpt_yesslam apps rawlog_tools bench tests examples scripts -type f \( -name '*.cpp' -o -name '*.h' -o -name '*.sh' \) -print0 \
  | xargs -0 cat > "$tmp/sources"
for t in "$tools"/*; do [ -x "$t" ] && [ -f "$t" ] && "$t" --help 2>&1 || true; done > "$tmp/help"
cat "$tmp/help" scripts/*.sh bench/*.sh bench/*.cpp .ci/run 2>/dev/null > "$tmp/flags_known"
bad=0; n=0
fail() { echo "check_doc_names: $1" >&2; bad=1; }
while IFS=$'\t' read -r md span; do
  # Classes: CName or TName alone in the span (or before :: / a call).
  if [[ "$span" =~ ^([CT][A-Z][A-Za-z0-9]+)(::[A-Za-z0-9_]+)?(\(\))?$ ]]; then
    n=$((n + 1)); grep -qw "${BASH_REMATCH[1]}" "$tmp/sources" || fail "$md: \`$span\`: no class ${BASH_REMATCH[1]} in the sources"
  fi
  # Paths of the repository: a folder, a name and a source-like extension, no placeholders.
  if [[ "$span" =~ ^[A-Za-z0-9_.-]+(/[A-Za-z0-9_.-]+)*/[A-Za-z0-9_.-]+\.(sh|md|cpp|h|ini|cmake)$ ]] && [[ "$span" != ../* ]]; then
    n=$((n + 1)); found=0
    for base in . mrpt_yesslam/include/mrpt_yesslam mrpt_yesslam/src mrpt_yesslam/tools/include/mrpt_yesslam mrpt_yesslam/tools/src; do
      [ -e "$base/$span" ] && found=1
    done
    [ "$found" = 1 ] || fail "$md: \`$span\`: no such file"
  fi
  # Options: [Section] key (several keys may follow, separated by commas or "and").
  if [[ "$span" =~ ^\[([A-Za-z]+)\]\ ([A-Za-z][A-Za-z0-9]*)( |$|=) ]]; then
    n=$((n + 1)); sec="${BASH_REMATCH[1]}"; key="${BASH_REMATCH[2]}"
    awk -v s="[$sec]" -v k="$key" '$0 == s { on = 1; next } /^\[/ { on = 0 } on && $1 == k { f = 1 } END { exit !f }' "$ini" \
      || fail "$md: \`$span\`: no key $key in [$sec] of $ini"
  fi
  # Flags, unless the span runs another program.
  first="${span%% *}"
  case "$first" in
    yesslam* | tum2rawlog | ./scripts/* | scripts/* | bench/* | build/* | --* | -*) ;;
    *) continue ;;
  esac
  for flag in $(grep -oE '(^| )--[a-z][a-z0-9-]+' <<< "$span"); do
    n=$((n + 1))
    grep -q -- "$flag" "$tmp/flags_known" || fail "$md: \`$span\`: no tool or script of ours takes $flag"
  done
done < "$tmp/spans"
[ "$n" -gt 100 ] || { echo "check_doc_names: only $n names checked: is the extraction broken?" >&2; exit 1; }
[ "$bad" = 0 ] || exit 1
echo "check_doc_names: $n names in README.md and docs/ exist"
