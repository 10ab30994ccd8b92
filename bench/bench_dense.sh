#!/usr/bin/env bash
# Dense semantic map (issue 15 item 6): on yesslam-sim walking and sitting sequences of 600 frames
# (seeds the settings were never tuned on), with the simulator's YOLO-like detector noise: voxels
# people swept and how many stay occupied (ghosts), label accuracy of occupied voxels against the
# simulator's labels, the 2D grid (issue 67: true path cells free, static surface cells in the band
# occupied within a cell, share of the cells only people swept left occupied), file sizes,
# dense-stage time per keyframe and end-of-run build time, and tracking fps (parallel mode, file
# detector) - with the dynamic filter and with --no-dynamic-filter.
# Usage: bench/bench_dense.sh [SEEDS]   (default "41 42"; sequences are kept in bench_out/dense/)
# SIM_FLAGS="--real-sensor" bench/bench_dense.sh ...: the sequences made with those yesslam-sim
# flags too (kept apart, in bench_out/dense--real-sensor/).
set -euo pipefail
ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
BUILD="${YESSLAM_BUILD:-$ROOT/build}"	# another Release build folder with bench/ (YESSLAM_BUILD=...)
BIN="$BUILD/rawlog_tools"
# shellcheck source=bench/sim_sequence.sh
source "$(dirname "${BASH_SOURCE[0]}")/sim_sequence.sh"
BENCH="$BUILD/bench/bench_dense"
SEEDS="${1:-41 42}"
for t in "$BIN/yesslam-sim" "$BENCH"; do
  [ -x "$t" ] || { echo "bench: build first (./scripts/build.sh builds the tools and bench/)" >&2; exit 1; }
done
OUT="$(bench_out dense)"; mkdir -p "$OUT/runs"
[ -z "$SIM_FLAGS" ] || echo "sequences: yesslam-sim $SIM_FLAGS"
kv() { tr ' ' '\n' | awk -F= -v k="$1" '$1 == k {print $2}'; }

echo "| sequence | seed | filter | ATE mm | fps | fps without dense map | dense ms/kf | build s | swept voxels | ghosts | label acc. | object precision | object recall | .ply MB | .ot MB | .bt MB | grid: path free | grid: static occupied | grid: swept cells occupied |"
echo "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|"
for preset in walking_xyz walking_halfsphere sitting_xyz; do
  for seed in $SEEDS; do
    seq="$OUT/${preset}_s$seed"
    sim_sequence "$seq" --preset "$preset" --seed "$seed" --frames 600 --no-rawlog --quiet "${SIMX[@]}"
    for filter in on off; do
      extra=""; [ $filter = off ] && extra="--no-dynamic-filter"
      line=$("$BENCH" "$seq" "$OUT/runs/${preset}_s${seed}_$filter" $extra | head -1)
      # The same run without the dense stage, straight after: the fps ratio is the dense stage's cost.
      plain=$("$BENCH" "$seq" "$OUT/runs/${preset}_s${seed}_${filter}_nodense" $extra --no-dense-map | head -1)
      printf "| %s | %s | %s | %s | %s | %s | %s | %s | %s | %s | %s | %s | %s | %s | %s | %s | %s | %s | %s of %s |\n" "$preset" "$seed" "$filter" \
        "$(kv ate_mm <<< "$line")" "$(kv fps <<< "$line")" "$(kv fps <<< "$plain")" "$(kv dense_ms <<< "$line")" "$(kv build_s <<< "$line")" \
        "$(kv swept <<< "$line")" "$(kv ghost <<< "$line")" "$(kv label_acc <<< "$line")" "$(kv object_precision <<< "$line")" \
        "$(kv object_recall <<< "$line")" "$(kv ply_mb <<< "$line")" "$(kv ot_mb <<< "$line")" "$(kv bt_mb <<< "$line")" \
        "$(kv grid_path_free <<< "$line")" "$(kv grid_static_occupied <<< "$line")" "$(kv grid_swept_occupied <<< "$line")" "$(kv grid_swept_cells <<< "$line")"
    done
  done
done
