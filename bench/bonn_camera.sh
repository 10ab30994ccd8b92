#!/usr/bin/env bash
# Writes a camera file for ../shared/data/bonn_crowd_dev: its calibration.txt intrinsics and, on a
# second line, the distortion the dataset publishes (a comment there, which the reader skips); on a
# third, the Xtion's rolling-shutter readout (0.028 s, as yesslam assumes for a Bonn folder).
# Usage: bench/bonn_camera.sh BONN_FOLDER OUT_FILE   (used by bench_real.sh and bench_paper.sh)
set -euo pipefail
CAL="$1/calibration.txt"; OUTF="$2"
{
  grep -v '^#' "$CAL" | awk 'NF >= 4 {print; exit}'
  grep '^#' "$CAL" | awk '{n = 0; for (i = 2; i <= NF; i++) if ($i ~ /^-?[0-9.]+(e-?[0-9]+)?$/) n++} n == 5 && NF == 6 {$1 = ""; print; exit}'
  echo 0.028
} > "$OUTF"
[ "$(wc -l < "$OUTF")" -eq 3 ] || { echo "bench: could not read the intrinsics and distortion of $CAL" >&2; exit 1; }
