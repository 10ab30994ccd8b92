#!/usr/bin/env bash
# Frames per second of yesslam-sim (rendering, noise, labels, detections and writing every file),
# median of RUNS runs of FRAMES frames of walking_xyz. Usage: bench/bench_sim.sh [RUNS] [FRAMES]
set -euo pipefail
ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
BIN="$ROOT/build/rawlog_tools/yesslam-sim"
RUNS="${1:-3}"; FRAMES="${2:-90}"
[ -x "$BIN" ] || { echo "bench: build first (./scripts/build.sh)" >&2; exit 1; }
TMP="$(mktemp -d)"; trap 'rm -rf "$TMP"' EXIT
echo "machine: $(nproc) cores, $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | sed 's/^ //')"
for mode in "" "--no-rawlog"; do
  fps=$(for i in $(seq "$RUNS"); do
    rm -rf "$TMP/out"
    "$BIN" --preset walking_xyz --frames "$FRAMES" --out "$TMP/out" --quiet $mode | awk '/^time:/ {gsub(/[(]/,"",$4); print $4}'
  done | sort -g | awk '{a[NR]=$1} END {print (NR%2) ? a[(NR+1)/2] : (a[NR/2]+a[NR/2+1])/2}')
  echo "yesslam-sim walking_xyz ${FRAMES} frames 640x480 ${mode:-(all outputs)}: ${fps} frames/s (median of ${RUNS})"
done
