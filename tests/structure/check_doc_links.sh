#!/usr/bin/env bash
# Every link in README.md and docs/*.md leads somewhere (issue 42 item 3): a relative link names a
# file or folder of the repository, and a #anchor names a heading of the file it points into (GitHub's
# anchors: lower case, punctuation dropped, spaces as hyphens). README stays a page a newcomer reads:
# at most MAX lines. Usage: check_doc_links.sh SOURCE_DIR MAX
set -euo pipefail
src="$1"; max="$2"
cd "$src"
[ -f README.md ] && [ -d docs ] || { echo "check_doc_links: $src: no README.md and docs/" >&2; exit 1; }
lines=$(wc -l < README.md)
[ "$lines" -le "$max" ] || { echo "check_doc_links: README.md has $lines lines (at most $max: details go to docs/)" >&2; exit 1; }
# The anchors of a markdown file's headings, outside code blocks.
anchors() {
  awk '/^```/ { fence = !fence; next } !fence && /^#+ / { sub(/^#+ +/, ""); print }' "$1" \
    | tr 'A-Z' 'a-z' | sed -E 's/[^a-z0-9 _-]//g; s/ /-/g'
}
bad=0; n=0
for md in README.md docs/*.md; do
  dir="$(dirname "$md")"
  # Links outside code blocks: ](target) with no scheme.
  while IFS= read -r link; do
    n=$((n + 1))
    path="${link%%#*}"; anchor=""
    [[ "$link" == *"#"* ]] && anchor="${link#*#}"
    target="$md"
    [ -n "$path" ] && target="$dir/$path"
    if [ ! -e "$target" ]; then
      echo "check_doc_links: $md: link '$link': $target does not exist" >&2; bad=1; continue
    fi
    if [ -n "$anchor" ] && ! anchors "$target" | grep -qxF -- "$anchor"; then
      echo "check_doc_links: $md: link '$link': no heading with anchor #$anchor in $target" >&2; bad=1
    fi
  done < <(awk '/^```/ { fence = !fence; next } !fence' "$md" | grep -oE '\]\([^) ]+\)' | sed -E 's/^\]\(//; s/\)$//' | grep -vE '^[a-z]+:' || true)
done
[ "$n" -gt 0 ] || { echo "check_doc_links: no links found" >&2; exit 1; }
[ "$bad" = 0 ] || exit 1
echo "check_doc_links: $n links in README.md and docs/ lead somewhere; README.md $lines lines"
