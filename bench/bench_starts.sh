#!/usr/bin/env bash
# The start of a run, measured from many starts (issue 39 item 3): yesslam on windows of LEN frames
# of the real Bonn dev slice beginning every STEP frames (sequential, no dense map), each window a
# run of its own that makes its first keyframe there. Per window: ATE RMSE, the mean error of its
# first two frames, the median error of all its frames, and the start's excess (the first two less
# the median: what the start costs beyond the run's typical error). Then the median window ATE and
# the mean excess over all windows and over those whose first 30 frames lie in the slice's
# people-free opening (its first 90 frames, so starts 0-60 with STEP 10: the camera pans over walls
# 2-5 m away, as the held-out sequence's opening does). A median of an even count is the mean of
# the middle two.
# One window says little (a start is one draw of the sensor's noise); sixteen say where the start
# is worse than the rest, and whether a change helps the start or only one window.
# Usage: bench/bench_starts.sh [LEN] [STEP]   (outputs in bench_out/starts/)
#        CONFIG=share/mrpt_yesslam/config/paper.ini OUT_TAG=paper bench/bench_starts.sh   (a configuration)
#        BIN=/other/build/rawlog_tools OUT_TAG=old bench/bench_starts.sh   (another build)
set -euo pipefail
ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
BIN="${BIN:-$ROOT/build/rawlog_tools}"
LEN="${1:-100}"; STEP="${2:-10}"
CFGARGS=()
if [ -n "${CONFIG:-}" ]; then
  [ -n "${OUT_TAG:-}" ] || { echo "bench: CONFIG needs OUT_TAG (its own output folder, not the default's)" >&2; exit 1; }
  CFGARGS=(--config "$CONFIG")
fi
SLICE="$ROOT/../shared/data/bonn_crowd_dev"
[ -x "$BIN/yesslam" ] || { echo "bench: build first (./scripts/build.sh)" >&2; exit 1; }
[ -d "$SLICE" ] || { echo "bench: $SLICE is missing" >&2; exit 1; }
FRAMES=$(grep -cv '^#' "$SLICE/rgb.txt")
if ! [[ "$LEN" =~ ^[0-9]+$ && "$STEP" =~ ^[0-9]+$ ]] || [ "$LEN" -lt 10 ] || [ "$LEN" -gt "$FRAMES" ] || [ "$STEP" -lt 1 ]; then
  echo "bench: LEN must be 10-$FRAMES and STEP at least 1" >&2; exit 1
fi
OUT="$ROOT/bench_out/starts${OUT_TAG:+_$OUT_TAG}"; mkdir -p "$OUT"
OPENING=90; MARGIN=30  # the slice's people-free frames; a window is the opening's when its first MARGIN frames are
export LC_ALL=C        # decimal points, for sort as awk writes them
trap 'rm -f "$OUT/windows.tmp"' EXIT
CAM="$OUT/bonn_camera.txt"; "$ROOT/bench/bonn_camera.sh" "$SLICE" "$CAM" > /dev/null
rm -f "$OUT/windows.tmp"
echo "| window start | ATE (mm) | first two frames (mm) | median frame (mm) | start's excess (mm) |"
echo "|---|---|---|---|---|"
for s in $(seq 0 "$STEP" $((FRAMES - LEN))); do
  run="$OUT/w$s"
  "$BIN/yesslam" --input "$SLICE" --gt-format bonn --camera "$CAM" --skip-frames "$s" --max-frames "$LEN" \
    --sequential --no-dense-map --quiet ${CFGARGS[@]+"${CFGARGS[@]}"} --out "$run" > "$run.log" 2>&1 ||
    { echo "bench: the run at $s failed, see $run.log" >&2; exit 1; }
  "$BIN/yesslam-eval" --gt "$SLICE/groundtruth.txt" --gt-format bonn --est "$run/trajectory.txt" --errors "$run/errors.csv" > "$run.eval" 2>&1 ||
    { echo "bench: evaluating the run at $s failed, see $run.eval" >&2; exit 1; }
  ate=$(awk '$1 == "ate_rmse:" {print 1000 * $2}' "$run.eval")
  [ -n "$ate" ] || { echo "bench: no ATE in $run.eval" >&2; exit 1; }
  [ -s "$run/errors.csv" ] || { echo "bench: the evaluation wrote no $run/errors.csv" >&2; exit 1; }
  # errors.csv is in stamp order: the first two rows are the window's first two frames.
  stats=$(awk -F, 'NR > 1 {e[++n] = 1000 * $2} END {
      if (n < 2) exit 1
      for (i = 1; i <= n; i++) s[i] = e[i]
      for (i = 2; i <= n; i++) {v = s[i]; j = i - 1; while (j > 0 && s[j] > v) {s[j + 1] = s[j]; j--} s[j + 1] = v}
      print (e[1] + e[2]) / 2, (s[int((n + 1) / 2)] + s[int(n / 2) + 1]) / 2}' "$run/errors.csv") ||
    { echo "bench: $run/errors.csv has fewer than two frames" >&2; exit 1; }
  read -r first med <<< "$stats"
  printf "%s %s %s %s\n" "$s" "$ate" "$first" "$med" >> "$OUT/windows.tmp"
  awk -v s="$s" -v a="$ate" -v f="$first" -v m="$med" 'BEGIN {printf "| %d | %.2f | %.1f | %.1f | %.1f |\n", s, a, f, m, f - m}'
done
sort -n -k2 "$OUT/windows.tmp" | awk '{a[NR] = $2} END {printf "median window ATE: %.2f mm over %d windows\n", (a[int((NR + 1) / 2)] + a[int(NR / 2) + 1]) / 2, NR}'
awk -v opening="$OPENING" -v margin="$MARGIN" '{x = $3 - $4; all += x; n++; if ($1 + margin <= opening) {open += x; k++}}
     END {printf "start excess, mean: %.1f mm over all windows", all / n; if (k) printf ", %.1f mm over the %d whose first %d frames are people-free", open / k, k, margin; print ""}' "$OUT/windows.tmp"
