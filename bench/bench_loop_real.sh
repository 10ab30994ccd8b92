#!/usr/bin/env bash
# Loops on real cameras (issue 64): every loop candidate appearance gives on the two real dev slices
# of ../shared (bonn_crowd_dev, tum_fr1_rpy_dev) and on any real TUM-layout folder with a
# groundtruth.txt given as an argument, labelled by the ground truth (yesslam-eval --loops: a true
# revisit has the two keyframes' true positions within 0.5 m, their viewing directions within 30
# degrees and each view's centre 2 m ahead in the other's view), with what each stage did with the
# true and the false ones, and the ATE with loop closing and without.
# Sequential runs (deterministic); the default configuration unless CONFIG (with OUT_TAG) is set.
# Usage: bench/bench_loop_real.sh [TUM_FOLDER ...]       (outputs in bench_out/loop_real/)
set -euo pipefail
ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
BIN="${BIN:-$ROOT/build/rawlog_tools}"
SHARED="$ROOT/../shared/data"
CFGARGS=()
if [ -n "${CONFIG:-}" ]; then
  [ -n "${OUT_TAG:-}" ] || { echo "bench_loop_real: CONFIG needs OUT_TAG (its own output folder)" >&2; exit 1; }
  CFGARGS=(--config "$CONFIG")
fi
[ -x "$BIN/yesslam" ] && [ -x "$BIN/yesslam-eval" ] || { echo "bench_loop_real: build first (./scripts/build.sh)" >&2; exit 1; }
for d in bonn_crowd_dev tum_fr1_rpy_dev; do
  [ -d "$SHARED/$d" ] || { echo "bench_loop_real: $SHARED/$d is missing" >&2; exit 1; }
done
for d in "$@"; do
  [ -f "$d/groundtruth.txt" ] || { echo "bench_loop_real: $d: no groundtruth.txt (a TUM-layout folder with its ground truth)" >&2; exit 1; }
done
OUT="$ROOT/bench_out/loop_real${OUT_TAG:+_$OUT_TAG}"; mkdir -p "$OUT"
"$ROOT/bench/bonn_camera.sh" "$SHARED/bonn_crowd_dev" "$OUT/bonn_camera.txt"
field() { awk -v k="$1:" '$1==k {print $2}' "$2"; }

echo "machine: $(nproc) cores, $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | sed 's/^ //')"
echo
echo "| sequence | keyframes | candidates (true) | detected (true) | accepted (true) | detection precision / recall | verification precision / recall | ATE with / without loops | online ATE with / without |"
echo "|---|---|---|---|---|---|---|---|---|"
stages_of=()
row() {  # row NAME GT_FORMAT ARGS...
  local name="$1" fmt="$2"; shift 2
  local on="$OUT/$name" off="$OUT/$name-noloop"
  "$BIN/yesslam" "$@" "${CFGARGS[@]}" --sequential --no-dense-map --out "$on" --quiet > "$on.log" 2> "$on.err" \
    || { echo "bench_loop_real: $name failed:" >&2; tail -3 "$on.err" >&2; exit 1; }
  "$BIN/yesslam" "$@" "${CFGARGS[@]}" --sequential --no-dense-map --no-loop-closure --out "$off" --quiet > "$off.log" 2> "$off.err" \
    || { echo "bench_loop_real: $name without loops failed:" >&2; tail -3 "$off.err" >&2; exit 1; }
  local gt; gt=$(awk '$1=="ground" && $2=="truth:" {print $3}' "$on.log")
  "$BIN/yesslam-eval" --gt "$gt" --gt-format "$fmt" --loops "$on/loop_candidates.csv" --labels "$on/labelled_candidates.csv" > "$on.loops" 2> "$on.loops.err" \
    || { echo "bench_loop_real: labelling $name failed:" >&2; cat "$on.loops.err" >&2; exit 1; }
  local L="$on.loops"
  for f in "$on.log" "$off.log"; do
    [ -n "$(field ate_rmse "$f")" ] && [ -n "$(field online_ate_rmse "$f")" ] || { echo "bench_loop_real: $f has no ATE (no ground truth found?)" >&2; exit 1; }
  done
  printf "| %s | %s | %s (%s) | %s (%s) | %s (%s) | %s / %s | %s / %s | %.1f / %.1f mm | %.1f / %.1f mm |\n" "$name" \
    "$(awk '$1=="keyframes:" {print $2}' "$on.log")" \
    "$(field loop_candidates "$L")" "$(field loop_true_candidates "$L")" "$(field loop_detected "$L")" "$(field loop_detected_true "$L")" \
    "$(field loop_accepted "$L")" "$(field loop_accepted_true "$L")" \
    "$(field detection_precision "$L")" "$(field detection_recall "$L")" "$(field verification_precision "$L")" "$(field verification_recall "$L")" \
    "$(awk "BEGIN {print 1000 * $(field ate_rmse "$on.log")}")" "$(awk "BEGIN {print 1000 * $(field ate_rmse "$off.log")}")" \
    "$(awk "BEGIN {print 1000 * $(field online_ate_rmse "$on.log")}")" "$(awk "BEGIN {print 1000 * $(field online_ate_rmse "$off.log")}")"
  stages_of+=("$name")
}
row bonn_crowd_dev bonn --input "$SHARED/bonn_crowd_dev" --gt-format bonn --camera "$OUT/bonn_camera.txt"
row tum_fr1_rpy_dev tum --input "$SHARED/tum_fr1_rpy_dev"
for d in "$@"; do row "$(basename "$d")" auto --input "$d"; done

echo
echo "Where the candidates stopped (true revisits / false):"
echo
stages="covisible young below_min_score not_group_best inconsistent gone few_matches ransac pose_solve projection untried dropped accepted"
printf "| sequence |"; for s in $stages; do printf " %s |" "$s"; done; echo
printf "|---|"; for s in $stages; do printf "%s" "---|"; done; echo
for name in "${stages_of[@]}"; do
  printf "| %s |" "$name"
  for s in $stages; do
    printf " %s |" "$(awk -v k="stage_$s:" '$1==k {print $2 " / " $4; f=1} END {if (!f) print "0 / 0"}' "$OUT/$name.loops")"
  done
  echo
done
echo
echo "detected = reached verification (passed covisibility, age, score, grouping and consistency); recall of"
echo "detection over the true candidates neither covisible nor young (the map links those already), of"
echo "verification over the true ones it tried."
echo "Labelled candidates per sequence: $OUT/NAME/labelled_candidates.csv."
