#!/usr/bin/env bash
# Frames per second of yesslam-sim (rendering, noise, labels, detections and writing every file),
# median of RUNS runs of FRAMES frames of walking_xyz, pinned to one core (taskset -c 0: the
# issue's target is 10 frames/s on one core) and on all cores; then the time per stage of one
# more one-core run. Usage: bench/bench_sim.sh [RUNS] [FRAMES]
set -euo pipefail
ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
BIN="$ROOT/build/rawlog_tools/yesslam-sim"
RUNS="${1:-3}"; FRAMES="${2:-150}"
[ -x "$BIN" ] || { echo "bench: build first (./scripts/build.sh)" >&2; exit 1; }
command -v taskset >/dev/null || { echo "bench: taskset (util-linux) is needed to pin to one core" >&2; exit 1; }
TMP="$(mktemp -d)"; trap 'rm -rf "$TMP"' EXIT
echo "machine: $(nproc) cores, $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | sed 's/^ //')"
median() { sort -g | awk '{a[NR]=$1} END {print (NR%2) ? a[(NR+1)/2] : (a[NR/2]+a[NR/2+1])/2}'; }
for cores in 1 all; do
  pin=(); [ "$cores" = 1 ] && pin=(taskset -c 0)
  for mode in "" "--no-rawlog"; do
    fps=$(for i in $(seq "$RUNS"); do
      rm -rf "$TMP/out"
      "${pin[@]}" "$BIN" --preset walking_xyz --frames "$FRAMES" --out "$TMP/out" --quiet $mode | awk '/^time:/ {gsub(/[(]/,"",$4); print $4}'
    done | median)
    echo "yesslam-sim walking_xyz ${FRAMES} frames 640x480, ${cores} core(s), ${mode:-all outputs}: ${fps} frames/s (median of ${RUNS})"
  done
done
echo "time per stage, one core (png encoding runs in writer threads and overlaps the others):"
rm -rf "$TMP/out"
taskset -c 0 "$BIN" --preset walking_xyz --frames "$FRAMES" --out "$TMP/out" --quiet --verbose | grep -E '^  '
