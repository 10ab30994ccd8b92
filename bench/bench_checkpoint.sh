#!/usr/bin/env bash
# What a map checkpoint costs the frames (issue 68 item 2): the same folder run RUNS times with
# --save-map and [System] checkpointSeconds = EVERY, and RUNS times with checkpoints off
# (checkpointSeconds = 0: the map saved at the end only), interleaved, default configuration
# (parallel stages, dense map on). Per run: fps, the frame's own time (ORB + waiting for the
# detector + mask + tracking + keyframe, from frames.csv) at the median, p95 and worst, the
# checkpoints saved and the longest; a median row per setting.
# Usage: bench/bench_checkpoint.sh [RUNS [FOLDER [EVERY [OUT]]]]   (defaults: 3,
#        ../shared/data/bonn_crowd_dev, 1 s, bench_out/checkpoint); extra yesslam arguments in ARGS.
set -euo pipefail
ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
BIN="${BIN:-$ROOT/build/rawlog_tools}"
RUNS="${1:-3}"
SRC="${2:-$ROOT/../shared/data/bonn_crowd_dev}"
EVERY="${3:-1}"
OUT="${4:-$ROOT/bench_out/checkpoint}"
[ -x "$BIN/yesslam" ] || { echo "bench_checkpoint: build first (./scripts/build.sh)" >&2; exit 1; }
[[ "$RUNS" =~ ^[1-9][0-9]*$ ]] || { echo "bench_checkpoint: RUNS must be a positive whole number, not '$RUNS'" >&2; exit 1; }
[[ "$EVERY" =~ ^[0-9]*\.?[0-9]+$ ]] && awk -v e="$EVERY" 'BEGIN {exit !(e > 0)}' ||
  { echo "bench_checkpoint: EVERY must be a positive number of seconds, not '$EVERY'" >&2; exit 1; }
[ -e "$SRC" ] || { echo "bench_checkpoint: $SRC: no such input" >&2; exit 1; }
mkdir -p "$OUT"
# shellcheck disable=SC2206
EXTRA=(${ARGS:-})
case "$(basename "$SRC")" in *bonn*) EXTRA+=(--gt-format bonn) ;; esac
field() { grep -o "\"$1\": [0-9.]*" "$2" | head -1 | awk '{print $2}'; }
printf '| setting | run | fps | frame ms median | p95 | worst | checkpoints | longest checkpoint ms |\n|---|---|---|---|---|---|---|---|\n'
rows=()
for r in $(seq 1 "$RUNS"); do
  for setting in "every $EVERY s" off; do
    tag="${setting// /_}"; s="$EVERY"; [ "$setting" = off ] && s=0
    printf '[System]\ncheckpointSeconds = %s\n' "$s" > "$OUT/$tag.ini"
    run="$OUT/run_${tag}_$r"
    t0=$(date +%s.%N)
    "$BIN/yesslam" --input "$SRC" --out "$run" --quiet --config "$OUT/$tag.ini" --save-map "$OUT/map_$tag.ysm" \
      "${EXTRA[@]}" > "$run.log" 2>&1 || { echo "bench_checkpoint: yesslam failed, see $run.log" >&2; exit 1; }
    t1=$(date +%s.%N)
    frames=$(field frames "$run/stats.json")
    fps=$(awk -v n="$frames" -v a="$t0" -v b="$t1" 'BEGIN {printf "%.1f", n / (b - a)}')
    # The frame's own time: orb_ms + detect_wait_ms + mask_ms + track_ms + keyframe_ms.
    times=$(awk -F, 'NR == 1 {for (i = 1; i <= NF; i++) c[$i] = i; next}
      {print $c["orb_ms"] + $c["detect_wait_ms"] + $c["mask_ms"] + $c["track_ms"] + $c["keyframe_ms"]}' "$run/frames.csv" |
      sort -g | awk '{a[NR] = $1} END {printf "%.1f %.1f %.1f", a[int((NR + 1) / 2)], a[int(0.95 * NR + 0.5)], a[NR]}')
    read -r med p95 worst <<< "$times"
    ck=$(grep -o '"map_checkpoints": {[^}]*}' "$run/stats.json" || true)  # none with checkpoints off
    saved=$(grep -o '"saved": [0-9]*' <<< "$ck" | awk '{print $2}' || true)
    longest=$(grep -o '"max_ms": [0-9.]*' <<< "$ck" | awk '{print $2}' || true)
    row="| $setting | $r | $fps | $med | $p95 | $worst | ${saved:-0} | ${longest:--} |"
    echo "$row"; rows+=("$setting $fps $med $p95 $worst")
  done
done
for setting in "every $EVERY s" off; do
  printf '%s\n' "${rows[@]}" | awk -v s="$setting" 'index($0, s) == 1 {n++; f[n] = $(NF - 3); m[n] = $(NF - 2); p[n] = $(NF - 1); w[n] = $NF}
    function med(a, n,   i, j, t) {for (i = 1; i <= n; i++) for (j = i + 1; j <= n; j++) if (a[j] < a[i]) {t = a[i]; a[i] = a[j]; a[j] = t}
      return a[int((n + 1) / 2)]}
    END {printf "| %s | median | %s | %s | %s | %s | | |\n", s, med(f, n), med(m, n), med(p, n), med(w, n)}'
done
