#!/usr/bin/env bash
# Loop closing (issue 13 item 6): ATE with and without loop closing on the loop presets (office_tour
# with two people walking, static_tour without people, office_loop whose small loop never loses
# sight of its start) and on presets without a loop to close (walking_xyz, walking_halfsphere,
# static_office: loop closing must not make them worse), each on several seeds the settings were
# never tuned on; then the place-recognition precision-recall of BoW with people, BoW on static
# keypoints and S_Loop (bench_loop_pr) on the office_tour seeds; the vocabulary's size and load
# time (median of 5); per-keyframe loop detection and per-loop correction / global BA times.
# Runs are sequential (deterministic): one run per seed is exact; the table gives the median
# over the seeds and every seed.
# Usage: bench/bench_loop.sh [SEEDS]   (default "31 32 33"; sequences are kept in bench_out/loop/)
# SIM_FLAGS="--real-sensor" bench/bench_loop.sh ...: the sequences made with those yesslam-sim
# flags too (kept apart, in bench_out/loop--real-sensor/).
set -euo pipefail
ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
BIN="$ROOT/build/rawlog_tools"
# shellcheck source=bench/sim_sequence.sh
source "$(dirname "${BASH_SOURCE[0]}")/sim_sequence.sh"
SEEDS="${1:-31 32 33}"
PR="$ROOT/build/bench/bench_loop_pr"
for t in "$BIN/yesslam-sim" "$BIN/yesslam" "$BIN/yesslam-vocab" "$PR"; do
  [ -x "$t" ] || { echo "bench: build first (./scripts/build.sh builds the tools and bench/)" >&2; exit 1; }
done
OUT="$(bench_out loop)"; mkdir -p "$OUT/runs"
[ -z "$SIM_FLAGS" ] || echo "sequences: yesslam-sim $SIM_FLAGS"
median() { sort -g | awk '{a[NR]=$1} END {if (NR == 0) print "-"; else if (NR % 2) print a[(NR+1)/2]; else printf "%.2f\n", (a[NR/2]+a[NR/2+1])/2}'; }
field() { grep -o "\"$2\": [0-9.]*" "$1" | head -1 | awk '{print $2}'; }

echo "ATE RMSE in mm (sequential runs, default configuration); loops = accepted loops"
echo
echo "| sequence | frames | ATE without loop closing | ATE with | ratio | loops | per seed (without / with) |"
echo "|---|---|---|---|---|---|---|"
for preset in office_tour static_tour office_loop walking_xyz walking_halfsphere static_office; do
  frames=""; case $preset in walking_*|static_office) frames="--frames 600" ;; esac
  offs=(); ons=(); loops=(); per=""
  for seed in $SEEDS; do
    seq="$OUT/${preset}_s$seed"
    # shellcheck disable=SC2086
    sim_sequence "$seq" --preset "$preset" --seed "$seed" $frames --no-rawlog --quiet "${SIMX[@]}"
    for lc in on off; do
      run="$OUT/runs/${preset}_s${seed}_$lc"
      extra=""; [ $lc = off ] && extra="--no-loop-closure"
      "$BIN/yesslam" --input "$seq" --out "$run" --sequential --quiet $extra > "$run.log" 2>&1
    done
    off=$(awk '/^ate_rmse:/{printf "%.1f", 1000*$2}' "$OUT/runs/${preset}_s${seed}_off.log")
    on=$(awk '/^ate_rmse:/{printf "%.1f", 1000*$2}' "$OUT/runs/${preset}_s${seed}_on.log")
    offs+=("$off"); ons+=("$on"); loops+=("$(field "$OUT/runs/${preset}_s${seed}_on/stats.json" accepted)")
    per="$per s$seed $off / $on;"
  done
  n=$(ls "$OUT/${preset}_s${SEEDS%% *}/rgb" | wc -l)
  mo=$(printf "%s\n" "${offs[@]}" | median); mn=$(printf "%s\n" "${ons[@]}" | median)
  echo "| $preset | $n | $mo | $mn | $(awk -v a="$mn" -v b="$mo" 'BEGIN{printf "%.2f", a/b}') | $(printf "%s " "${loops[@]}") | ${per% ;} |"
done

echo
echo "Place recognition on office_tour (pairs of keyframes >= minLoopAge apart; true loop: centres within 0.3 m, axes within 20 deg)"
for seed in $SEEDS; do
  echo "seed $seed:"
  "$PR" --input "$OUT/office_tour_s$seed" | sed -n '1,6p' | sed 's/^/  /'
done
echo
"$PR" --input "$OUT/office_tour_s${SEEDS%% *}" | sed -n '7,$p'

echo
VOC="$ROOT/share/mrpt_yesslam/vocabulary/orb_k10_L5.yvoc"
loads=$(for i in 1 2 3 4 5; do "$BIN/yesslam-vocab" --info "$VOC" | awk '/load ms/{print $3}'; done | median)
echo "vocabulary: $(du -h "$VOC" | cut -f1), $("$BIN/yesslam-vocab" --info "$VOC" | awk '/^words/{print $2}') words, load $loads ms (median of 5)"
echo
echo "| sequence (seed ${SEEDS%% *}) | loop detection ms per keyframe (median / p95) | correction ms per loop | global BA ms |"
echo "|---|---|---|---|"
for preset in office_tour static_tour; do
  js="$OUT/runs/${preset}_s${SEEDS%% *}_on/stats.json"
  det=$(grep -o '"loop_detect": {[^}]*}' "$js" | grep -o '"\(median\|p95\)": [0-9.]*' | awk '{print $2}' | paste -sd/)
  cor=$(grep -o '"loop_correct": {[^}]*}' "$js" | grep -o '"median": [0-9.]*' | awk '{print $2}')
  gba=$(grep -o '"global_ba": {[^}]*}' "$js" | grep -o '"median": [0-9.]*' | awk '{print $2}')
  echo "| $preset | ${det:--} | ${cor:--} | ${gba:--} |"
done
