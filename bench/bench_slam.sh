#!/usr/bin/env bash
# Accuracy of yesslam on yesslam-sim sequences (issue 5's table): for each preset, a sequence of
# FRAMES frames (seed 1, yolo detection noise; walking_xyz replays the real TUM fr3_walking_xyz
# ground truth), then RUNS runs with dynamic filtering and RUNS without (--no-dynamic-filter), and
# one run with each keyframe policy. Prints a markdown table of medians.
# Usage: bench/bench_slam.sh [FRAMES] [RUNS] [PRESETS...]   (sequences are kept in bench_out/slam/)
# SIM_FLAGS="--real-sensor" bench/bench_slam.sh ...: the sequences made with those yesslam-sim
# options too (kept in bench_out/slam--real-sensor/, one folder per set of options).
set -euo pipefail
ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
BIN="$ROOT/build/rawlog_tools"
# shellcheck source=bench/sim_sequence.sh
source "$(dirname "${BASH_SOURCE[0]}")/sim_sequence.sh"
FRAMES="${1:-600}"; RUNS="${2:-3}"; shift 2 || true
PRESETS=("$@"); [ ${#PRESETS[@]} -gt 0 ] || PRESETS=(static_office walking_xyz walking_static walking_rpy walking_halfsphere)
SHARED="$ROOT/../shared"
CFG="$ROOT/share/mrpt_yesslam/config/sim.ini"  # the shipped configuration for yesslam-sim sequences
for t in yesslam yesslam-sim; do [ -x "$BIN/$t" ] || { echo "bench: build first (./scripts/build.sh)" >&2; exit 1; }; done
OUT="$(bench_out slam)"; mkdir -p "$OUT/runs"
# Peak memory through GNU time (Debian package "time") when it is there.
TIMECMD=(); [ -x /usr/bin/time ] && TIMECMD=(/usr/bin/time -f "maxrss_kb: %M")
median() { sort -g | awk '{a[NR]=$1} END {print (NR%2) ? a[(NR+1)/2] : (a[NR/2]+a[NR/2+1])/2}'; }
field() { awk -v k="$1:" '$1==k {print $2}' "$2"; }
kf() { awk -F'[:,]' '/"keyframes"/ {gsub(/ /,"",$2); print $2; exit}' "$1"; }  # the first: stats.json has other "keyframes" keys
rate() { awk -F'[:,]' '/"tracking_rate"/ {gsub(/ /,"",$2); print $2}' "$1"; }
[ -z "$SIM_FLAGS" ] || echo "sequences: yesslam-sim $SIM_FLAGS"
echo "machine: $(nproc) cores, $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | sed 's/^ //')"
echo
echo "| preset | frames | ATE RMSE filtered (m) | ATE RMSE unfiltered (m) | ratio | tracking rate | keyframes semantic | keyframes orbslam | fps | max RSS (MB) |"
echo "|---|---|---|---|---|---|---|---|---|---|"
for p in "${PRESETS[@]}"; do
  seq="$OUT/$p"
  extra=()
  [ "$p" = walking_xyz ] && extra=(--trajectory "$SHARED/data/tum_eval_trajectories/fr3_walking_xyz_groundtruth.txt")
  sim_sequence "$seq" --preset "$p" --seed 1 --frames "$FRAMES" --det-noise yolo --no-rawlog --quiet "${extra[@]}" "${SIMX[@]}"
  for mode in filtered unfiltered; do
    flag=(); [ $mode = unfiltered ] && flag=(--no-dynamic-filter)
    for i in $(seq "$RUNS"); do
      "${TIMECMD[@]}" "$BIN/yesslam" --input "$seq" --config "$CFG" --out "$OUT/runs/$p-$mode-$i" --quiet "${flag[@]}" \
        > "$OUT/runs/$p-$mode-$i.log" 2>&1 || true
    done
  done
  "$BIN/yesslam" --input "$seq" --config "$CFG" --out "$OUT/runs/$p-orbslam" --quiet --policy orbslam > "$OUT/runs/$p-orbslam.log" 2>&1 || true
  f=$(for i in $(seq "$RUNS"); do field ate_rmse "$OUT/runs/$p-filtered-$i.log"; done | median)
  u=$(for i in $(seq "$RUNS"); do field ate_rmse "$OUT/runs/$p-unfiltered-$i.log"; done | median)
  r=$(for i in $(seq "$RUNS"); do rate "$OUT/runs/$p-filtered-$i/stats.json"; done | median)
  ks=$(kf "$OUT/runs/$p-filtered-1/stats.json"); ko=$(kf "$OUT/runs/$p-orbslam/stats.json")
  fps=$(for i in $(seq "$RUNS"); do awk '/^fps:/ {print $2}' "$OUT/runs/$p-filtered-$i.log"; done | median)
  rss=$(for i in $(seq "$RUNS"); do awk '/^maxrss_kb:/ {print int($2/1024)}' "$OUT/runs/$p-filtered-$i.log"; done | median)
  ratio=$(awk -v a="$u" -v b="$f" 'BEGIN {printf "%.1f", (b > 0) ? a / b : 0}')
  printf "| %s | %s | %.4f | %.4f | %s | %.1f%% | %s | %s | %s | %s |\n" "$p" "$FRAMES" "$f" "$u" "$ratio" "$(awk -v x="$r" 'BEGIN{print 100*x}')" "$ks" "$ko" "$fps" "$rss"
done
