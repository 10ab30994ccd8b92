#!/usr/bin/env bash
# The simulator held against real frames (issue 27 item 3): sensor statistics of the real
# sequences in ../shared and of yesslam-sim sequences side by side (build/bench/bench_realism:
# valid depth (all, on dark and on light surfaces away from the border), missing depth in holes
# under 16 px, textured cells, sharpness, colour noise, depth noise against distance as the plane residual of
# 8 x 8 patches, flying pixels), then what SLAM makes of each with the default configuration
# (median inliers per feature, jitter: the median per-frame error of the estimate's steps).
# Usage: bench/bench_realism.sh [FRAMES] [PRESETS...]   (sim sequences in bench_out/realism/)
set -euo pipefail
ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
BIN="$ROOT/build/rawlog_tools"; STATS="$ROOT/build/bench/bench_realism"
# shellcheck source=bench/sim_sequence.sh
source "$(dirname "${BASH_SOURCE[0]}")/sim_sequence.sh"
FRAMES="${1:-250}"; shift || true
PRESETS=("$@"); [ ${#PRESETS[@]} -gt 0 ] || PRESETS=(static_office walking_xyz)
SHARED="$ROOT/../shared/data"
for t in "$BIN/yesslam" "$BIN/yesslam-sim" "$STATS"; do [ -x "$t" ] || { echo "bench: build first ($t missing)" >&2; exit 1; }; done
OUT="$ROOT/bench_out/realism"; mkdir -p "$OUT"
field() { awk -v k="$1:" '$1==k {print $2}' "$2"; }
declare -A INPUT ARGS
NAMES=(bonn_crowd_dev tum_fr1_desk_9frames)
INPUT[bonn_crowd_dev]="$SHARED/bonn_crowd_dev"; ARGS[bonn_crowd_dev]="--gt-format bonn"
INPUT[tum_fr1_desk_9frames]="$SHARED/tum_fr1_desk_9frames"; ARGS[tum_fr1_desk_9frames]=""
for p in "${PRESETS[@]}"; do
  sensors=(kinect real); [ "$p" = crowd ] && sensors=(real)  # the crowd preset has the real sensor on
  for sensor in "${sensors[@]}"; do
    seq="$OUT/$p-$sensor"; flag=(); [ $sensor = real ] && flag=(--real-sensor)
    sim_sequence "$seq" --preset "$p" --seed 3 --frames "$FRAMES" --det-noise yolo --no-rawlog --quiet "${flag[@]}"
    n="sim $p ($sensor sensor)"; NAMES+=("$n"); INPUT["$n"]="$seq"; ARGS["$n"]=""
  done
done
echo "| sequence | valid depth | valid dark / light | holes < 16 px | textured cells | sharpness | colour noise | noise 8 / 32 px at 2-2.5 m | noise 8 / 32 px at 3-3.5 m | k (sigma = k z^2) | inliers / features | jitter / true step | ATE |"
echo "|---|---|---|---|---|---|---|---|---|---|---|---|---|"
for n in "${NAMES[@]}"; do
  tag="${n// /_}"
  "$STATS" --step 5 --max-frames "$FRAMES" "${INPUT[$n]}" > "$OUT/$tag.stats"
  # shellcheck disable=SC2086
  "$BIN/yesslam" --input "${INPUT[$n]}" ${ARGS[$n]} --max-frames "$FRAMES" --sequential --quiet --no-dense-map --out "$OUT/run_$tag" > "$OUT/run_$tag.log" 2>&1 || true
  ratio=$(awk -F, 'NR > 1 && $6 > 0 {print $9 / $6}' "$OUT/run_$tag/frames.csv" | sort -g | awk '{a[NR]=$1} END {print (NR ? a[int((NR+1)/2)] : 0)}')
  s="$OUT/$tag.stats"
  awk -v n="$n" -v v="$(field valid_depth_share "$s")" -v vd="$(field dark_valid_share "$s")" -v vl="$(field light_valid_share "$s")" \
      -v sp="$(field speckle_hole_share "$s")" -v t="$(field textured_cell_share "$s")" -v sh="$(field sharpness "$s")" -v cn="$(field colour_noise "$s")" \
      -v a="$(field noise_2.0_2.5_mm "$s")" -v a32="$(field noise32_2.0_2.5_mm "$s")" -v b="$(field noise_3.0_3.5_mm "$s")" -v b32="$(field noise32_3.0_3.5_mm "$s")" \
      -v k="$(field noise_k "$s")" -v r="$ratio" -v j="$(field jitter_median "$OUT/run_$tag.log")" -v st="$(field step_gt_median "$OUT/run_$tag.log")" \
      -v ate="$(field ate_rmse "$OUT/run_$tag.log")" \
      'BEGIN {printf "| %s | %.2f | %.2f / %.2f | %.3f | %.2f | %.0f | %.2f | %.1f / %.1f mm | %.1f / %.1f mm | %.4f | %.2f | %.1f / %.1f mm | %.1f mm |\n", n, v, vd, vl, sp, t, sh, cn, a, a32, b, b32, k, r, 1000*j, 1000*st, 1000*ate}'
done
