#!/usr/bin/env bash
# Times tum2rawlog and yesslam-eval on the real TUM material in ../shared and prints medians.
# Usage: bench/bench_io_eval.sh [RUNS]   (default 7; build first with ./scripts/build.sh)
set -euo pipefail
ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
SHARED="$(cd "$ROOT/.." && pwd)/shared"
BIN="$ROOT/build/rawlog_tools"
RUNS="${1:-7}"
TMP="$(mktemp -d)"; trap 'rm -rf "$TMP"' EXIT
[ -x "$BIN/yesslam-eval" ] || { echo "bench: build first (./scripts/build.sh)" >&2; exit 1; }

median() { sort -g | awk '{a[NR]=$1} END {if (NR%2) print a[(NR+1)/2]; else printf "%.6f\n", (a[NR/2]+a[NR/2+1])/2}'; }
timeit() { local s e; s=$(date +%s.%N); "$@" >/dev/null 2>&1; e=$(date +%s.%N); awk -v a="$s" -v b="$e" 'BEGIN{printf "%.6f\n", b-a}'; }
div() { awk -v a="$1" -v b="$2" 'BEGIN{printf "%.6f", a/b}'; }

DESK="$SHARED/data/tum_fr1_desk_9frames"
TRAJ="$SHARED/data/tum_eval_trajectories"
# A longer TUM folder: the 9 real frames listed 10 times with shifted stamps (90 frames, 640x480).
BIG="$TMP/rgbd_dataset_freiburg1_bench"; mkdir -p "$BIG"
ln -s "$DESK/rgb" "$BIG/rgb"; ln -s "$DESK/depth" "$BIG/depth"
for f in rgb depth; do
  grep -v '^#' "$DESK/$f.txt" | awk -v r=10 '{for (k=0;k<r;k++) printf "%.6f %s\n", $1 + k*0.3 + 0, $2}' | sort -g > "$BIG/$f.txt"
done
frames=$(wc -l < "$BIG/rgb.txt")

echo "machine: $(nproc) cores, $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | sed 's/^ //')"
echo "runs per figure: $RUNS (median)"
t=$(for i in $(seq "$RUNS"); do timeit "$BIN/tum2rawlog" --input "$BIG" --output "$TMP/big.rawlog" --quiet; done | median)
printf "tum2rawlog inline images, %d frames 640x480: %.3f s = %.1f frames/s\n" "$frames" "$t" "$(div "$frames" "$t")"
t=$(for i in $(seq "$RUNS"); do timeit "$BIN/tum2rawlog" --input "$BIG" --output "$TMP/ext.rawlog" --external-images --quiet; done | median)
printf "tum2rawlog external images, %d frames 640x480: %.3f s = %.1f frames/s\n" "$frames" "$t" "$(div "$frames" "$t")"
t=$(for i in $(seq "$RUNS"); do timeit "$BIN/yesslam-eval" --gt "$TRAJ/evo_fr2_desk_groundtruth.txt" --est "$TRAJ/evo_fr2_desk_ORB.txt"; done | median)
printf "yesslam-eval fr2_desk (20957 gt x 2893 est, ATE+RPE): %.3f s\n" "$t"
t=$(for i in $(seq "$RUNS"); do timeit "$BIN/yesslam-eval" --gt "$TRAJ/evo_freiburg1_xyz-groundtruth.txt" --est "$TRAJ/evo_freiburg1_xyz-rgbdslam.txt"; done | median)
printf "yesslam-eval fr1_xyz (3000 gt x 788 est, ATE+RPE): %.3f s\n" "$t"
