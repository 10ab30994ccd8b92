#!/usr/bin/env bash
# Dynamic rejection without tuning (issue 14, item 4): for each walking preset, and for a sequence
# whose walkers are never detected and one with a high miss rate, runs yesslam with the default
# configuration and with sim.ini, each as {paper mask only, mask + geometric check, whole box}, and
# prints ATE RMSE, RPE RMSE (1 s), the worst 1-second burst (largest RPE over 1 s: a person dragging
# the camera shows there even when the RMSE looks fine), the share of tracking's inlier keypoints
# that lie on people and the share of static keypoints the mask keeps (both against the simulator's
# labels: bench_keypoint_use runs yesslam exactly as `yesslam --sequential --detector auto` does),
# lost frames and the tracking median.
# Runs are sequential, so each accuracy figure is exact and repeatable (a median of identical runs).
# Usage: bench/bench_dynamic.sh [FRAMES] [SEED]   (sequences are kept in bench_out/dynamic/)
# SIM_FLAGS="--real-sensor" bench/bench_dynamic.sh ...: the sequences made with those yesslam-sim
# options too (kept in bench_out/dynamic--real-sensor/, one folder per set of options).
set -euo pipefail
ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
BIN="$ROOT/build/rawlog_tools"
# shellcheck source=bench/sim_sequence.sh
source "$(dirname "${BASH_SOURCE[0]}")/sim_sequence.sh"
FRAMES="${1:-600}"; SEED="${2:-21}"
SIMCFG="$ROOT/share/mrpt_yesslam/config/sim.ini"
for t in yesslam-sim yesslam-eval; do [ -x "$BIN/$t" ] || { echo "bench: build first (./scripts/build.sh)" >&2; exit 1; }; done
USE="$ROOT/build/bench/bench_keypoint_use"
[ -x "$USE" ] || { echo "bench: build the benchmarks first (cmake --build build --target bench_keypoint_use)" >&2; exit 1; }
OUT="$(bench_out dynamic)"; mkdir -p "$OUT/runs" "$OUT/cfg"
# A config: the base (empty = defaults, or sim.ini) with some sections' keys replaced.
mkcfg() {  # mkcfg OUT BASE "Section.key=value ..."
  local out="$1" base="$2"; shift 2
  awk -v ovr="$*" '
    BEGIN { n = split(ovr, kv, " "); for (i = 1; i <= n; i++) { split(kv[i], a, "="); split(a[1], sk, "."); want[sk[1]] = want[sk[1]] sk[2] " = " a[2] "\n"; has[sk[1], sk[2]] = 1 } }
    /^\[/ { sec = substr($0, 2, length($0) - 2); print; if (sec in want) { printf "%s", want[sec]; done[sec] = 1 }; next }
    { split($0, p, "="); k = p[1]; gsub(/[ \t]/, "", k); if ((sec, k) in has) next; print }
    END { for (s in want) if (!(s in done)) { print "[" s "]"; printf "%s", want[s] } }' "${base:-/dev/null}" > "$out"
}
declare -A SEQS=(
  [walking_xyz]="--preset walking_xyz"
  [walking_static]="--preset walking_static"
  [walking_rpy]="--preset walking_rpy"
  [walking_halfsphere]="--preset walking_halfsphere"
  [undetected]="--preset walking_xyz --undetected-people 1"
  [miss_rate]="--preset walking_xyz --miss-rate 0.5")
[ -z "$SIM_FLAGS" ] || echo "sequences: yesslam-sim $SIM_FLAGS"
echo "frames $FRAMES, seed $SEED; ATE / RPE RMSE / worst 1 s RPE in mm; people among the inlier keypoints and static keypoints kept, %; lost frames; tracking median ms"
echo
echo "| sequence | config | variant | ATE | RPE | worst 1 s | people in inliers | static kept | lost | track ms |"
echo "|---|---|---|---|---|---|---|---|---|---|"
for name in walking_xyz walking_static walking_rpy walking_halfsphere undetected miss_rate; do
  seq="$OUT/${name}_${FRAMES}f_s${SEED}"
  # shellcheck disable=SC2086
  sim_sequence "$seq" ${SEQS[$name]} --seed "$SEED" --frames "$FRAMES" --no-rawlog --quiet "${SIMX[@]}"
  for cfg in default sim; do
    base=""; [ "$cfg" = sim ] && base="$SIMCFG"
    for variant in mask check box; do
      case $variant in
        mask) ovr="GeometricCheck.enabled=false" ;;
        check) ovr="GeometricCheck.enabled=true" ;;
        box) ovr="GeometricCheck.enabled=false DynamicMask.method=box" ;;
      esac
      c="$OUT/cfg/$cfg-$variant.ini"; mkcfg "$c" "$base" $ovr
      run="$OUT/runs/$name-${FRAMES}f_s${SEED}-$cfg-$variant"
      "$USE" --input "$seq" --config "$c" --out "$run" > "$run.log" 2>&1 || { echo "| $name | $cfg | $variant | failed: $(tail -1 "$run.log") |"; continue; }
      "$BIN/yesslam-eval" --gt "$seq/groundtruth.txt" --est "$run/trajectory.txt" --rpe-delta 1 --rpe-unit s > "$run.eval"
      f() { awk -v k="$1:" '$1 == k {printf "%.1f", 1000 * $2}' "$run.eval"; }
      lost=$(grep -o '"lost_frames": [0-9]*' "$run/stats.json" | awk '{print $2}')
      trk=$(grep -o '"track": {"median": [0-9.]*' "$run/stats.json" | awk '{print $3}')
      pct() { awk -v k="$1:" '$1 == k {printf "%.1f", 100 * $2}' "$run.log"; }
      echo "| $name | $cfg | $variant | $(f ate_rmse) | $(f rpe_trans_rmse) | $(f rpe_trans_max) | $(pct person_share) | $(pct static_kept) | $lost | $trk |"
    done
  done
done
