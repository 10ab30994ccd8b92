#!/usr/bin/env bash
# Mask quality of the three masking methods on yesslam-sim walking sequences (simulated YOLO-like
# detections), against the simulator's labels. Usage: bench/bench_masking.sh [FRAMES] (default 150)
set -euo pipefail
ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
FRAMES="${1:-150}"
BIN="$ROOT/build"
[ -x "$BIN/bench/bench_masking" ] || { echo "bench: build first (./scripts/build.sh)" >&2; exit 1; }
TMP="$(mktemp -d)"; trap 'rm -rf "$TMP"' EXIT
dirs=()
for p in walking_xyz walking_static walking_rpy walking_halfsphere; do
  "$BIN/rawlog_tools/yesslam-sim" --preset "$p" --frames "$FRAMES" --seed 1 --out "$TMP/$p" --no-rawlog --quiet >/dev/null
  dirs+=("$TMP/$p")
done
echo "yesslam-sim seed 1, $FRAMES frames each, --det-noise yolo; mask IoU over all frames; keypoints: 1000 ORB per frame"
"$BIN/bench/bench_masking" "${dirs[@]}"
