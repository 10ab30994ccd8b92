#!/usr/bin/env bash
# Does the map stop growing in a place it already knows, and does per-frame cost stay flat as the
# run gets longer? (issue 12, item 2). Renders one static_office sequence of FRAMES frames (seed 1;
# the camera keeps revisiting the same 6 x 5 m room), then runs yesslam with sim.ini RUNS times on
# its first 300 frames, on the first half and on all of it (mapping in its own thread), and prints
# the medians: keyframes in the map, map points, tracking median / p95 and local mapping median per
# keyframe (ms, from stats.json), fps, peak RSS and ATE; then the ratios of the full run to the first
# 300 frames, both across runs and within each full run (its frames.csv: the tracking times of all
# its frames against those of its own first 300, so the machine's load drifting between runs does not
# enter the ratio).
# Usage: bench/bench_scaling.sh [FRAMES] [RUNS] [BUILD_DIR]   (the sequence is kept in bench_out/scaling/)
# SIM_FLAGS="--real-sensor" bench/bench_scaling.sh ...: the sequence made with those yesslam-sim
# flags too (kept apart, in bench_out/scaling--real-sensor/).
set -euo pipefail
ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
FRAMES="${1:-3000}"; RUNS="${2:-3}"; BUILD="${3:-$ROOT/build}"
BIN="$BUILD/rawlog_tools"
# shellcheck source=bench/sim_sequence.sh
source "$(dirname "${BASH_SOURCE[0]}")/sim_sequence.sh"
CFG="${BENCH_CONFIG:-$ROOT/share/mrpt_yesslam/config/sim.ini}"  # BENCH_CONFIG: another config to compare
for t in yesslam yesslam-sim; do [ -x "$BIN/$t" ] || { echo "bench: build first (./scripts/build.sh)" >&2; exit 1; }; done
OUT="$(bench_out scaling)"; SEQ="$OUT/static_office_$FRAMES"; mkdir -p "$OUT/runs"
[ -z "$SIM_FLAGS" ] || echo "sequence: yesslam-sim $SIM_FLAGS"
sim_sequence "$SEQ" --preset static_office --seed 1 --frames "$FRAMES" --no-rawlog --quiet "${SIMX[@]}"
TIMECMD=(); [ -x /usr/bin/time ] && TIMECMD=(/usr/bin/time -f "maxrss_kb: %M")
median() { sort -g | awk '{a[NR]=$1} END {print (NR%2) ? a[(NR+1)/2] : (a[NR/2]+a[NR/2+1])/2}'; }
num() { awk -F'[:,]' -v k="\"$1\"" '$1 ~ k {gsub(/ /,"",$2); print $2; exit}' "$2"; }
stage() { grep -o "\"$1\": {\"median\": [0-9.]*, \"p95\": [0-9.]*" "$2" | awk -v w="$3" '{gsub(/,/,""); print (w=="median") ? $3 : $5}'; }
echo "machine: $(nproc) cores, $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | sed 's/^ //'); build: $BUILD"
echo
echo "| frames | keyframes in map (inserted) | map points | tracking median / p95 ms | local mapping ms / keyframe | fps | peak RSS MB | ATE mm |"
echo "|---|---|---|---|---|---|---|---|"
declare -A TM TP MP
for n in 300 $((FRAMES / 2)) "$FRAMES"; do
  for i in $(seq "$RUNS"); do
    d="$OUT/runs/$n-$i"
    "${TIMECMD[@]}" "$BIN/yesslam" --input "$SEQ" --config "$CFG" --max-frames "$n" --out "$d" --quiet > "$d.log" 2>&1 || true
  done
  col() { for i in $(seq "$RUNS"); do "$@" "$OUT/runs/$n-$i"; done | median; }
  kfm() { num keyframes_in_map "$1/stats.json"; }; kfi() { num keyframes "$1/stats.json"; }; mp() { num map_points "$1/stats.json"; }
  tm() { stage track "$1/stats.json" median; }; tp() { stage track "$1/stats.json" p95; }; mm() { stage mapping "$1/stats.json" median; }
  fps() { awk '/^fps:/ {print $2}' "$1.log"; }; rss() { awk '/^maxrss_kb:/ {print int($2/1024)}' "$1.log"; }
  ate() { awk '/^ate_rmse:/ {printf "%.1f\n", 1000*$2}' "$1.log"; }
  TM[$n]=$(col tm); TP[$n]=$(col tp); MP[$n]=$(col mm)
  printf "| %s | %s (%s) | %s | %s / %s | %s | %s | %s | %s |\n" "$n" "$(col kfm)" "$(col kfi)" "$(col mp)" "${TM[$n]}" "${TP[$n]}" "${MP[$n]}" "$(col fps)" "$(col rss)" "$(col ate)"
done
# Within each full run: median and p95 of track_ms over all frames / over its first 300 (medians over runs).
pct() { sort -g | awk -v q="$1" '{a[NR]=$1} END {print a[int(q*(NR-1)+1.5)]}'; }
trackcol() { awk -F, 'NR == 1 {for (c = 1; c <= NF; c++) if ($c == "track_ms") k = c; next} {print $k}' "$1"; }
within() {
  for i in $(seq "$RUNS"); do
    f="$OUT/runs/$FRAMES-$i/frames.csv"
    awk -v a="$(trackcol "$f" | pct "$1")" -v b="$(trackcol "$f" | head -300 | pct "$1")" 'BEGIN {printf "%.3f\n", a/b}'
  done | median
}
echo
echo "within each $FRAMES-frame run (frames.csv, all frames / its first 300): tracking median $(within 0.5), p95 $(within 0.95)"
awk -v a="${TM[$FRAMES]}" -v b="${TM[300]}" -v c="${TP[$FRAMES]}" -v d="${TP[300]}" -v e="${MP[$FRAMES]}" -v f="${MP[300]}" \
  'BEGIN {printf "\nratios %s frames / 300 frames: tracking median %.2f (target <= 1.2), p95 %.2f (<= 1.5), local mapping %.2f (<= 1.3)\n", "'"$FRAMES"'", a/b, c/d, e/f}'
