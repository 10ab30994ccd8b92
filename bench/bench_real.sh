#!/usr/bin/env bash
# yesslam with the default configuration (shipped detector, no --config) on every real RGB-D
# sequence in ../shared, RUNS runs each (medians; mapping on its own thread, as users run it):
#   - bonn_crowd_dev: 250 Xtion frames of the Bonn RGB-D Dynamic "crowd" sequence (people walking
#     close), its marker ground truth converted with --gt-format bonn, the dataset's published
#     distortion in a camera file; also its people-free opening alone (the first 90 frames) and its
#     second half alone (frames 125-249: a run that starts among people);
#   - tum_fr1_rpy_dev: 300 Kinect v1 frames of TUM fr1/rpy (turning in place over a desk);
#   - tum_fr1_desk_9frames: 9 Kinect frames of TUM fr1/desk.
# Prints ATE RMSE (median, and the range of the runs: issue 39 item 5), RPE RMSE (translation m/s, rotation deg/s), the per-frame steps of estimate and
# ground truth and the jitter (median length of their difference), lost frames, fps, and the ATE
# and jitter of the online poses (trajectory_online.txt: what a robot had while it moved); ATE and
# jitter are of trajectory.txt (each frame carried by its keyframe's final pose, no smoothing).
# Also the frames more than 5 cm off after the alignment (yesslam-eval --errors; median over runs).
# Usage: bench/bench_real.sh [RUNS]   (outputs in bench_out/real/)
#        BIN=/other/build/rawlog_tools OUT_TAG=old bench/bench_real.sh 3   (another build, side by side)
#        CONFIG=share/mrpt_yesslam/config/paper.ini OUT_TAG=paper bench/bench_real.sh 5   (a configuration)
set -euo pipefail
ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
BIN="${BIN:-$ROOT/build/rawlog_tools}"
CFGARGS=()
if [ -n "${CONFIG:-}" ]; then
  [ -n "${OUT_TAG:-}" ] || { echo "bench: CONFIG needs OUT_TAG (its own output folder, not the default's)" >&2; exit 1; }
  CFGARGS=(--config "$CONFIG")
fi
RUNS="${1:-3}"
SHARED="$ROOT/../shared/data"
[ -x "$BIN/yesslam" ] || { echo "bench: build first (./scripts/build.sh)" >&2; exit 1; }
for d in bonn_crowd_dev tum_fr1_rpy_dev tum_fr1_desk_9frames; do
  [ -d "$SHARED/$d" ] || { echo "bench: $SHARED/$d is missing" >&2; exit 1; }
done
OUT="$ROOT/bench_out/real${OUT_TAG:+_$OUT_TAG}"; mkdir -p "$OUT/runs"
# The Bonn intrinsics with the distortion the dataset publishes (a comment in its calibration.txt).
BONN_CAM="$OUT/bonn_camera.txt"
"$ROOT/bench/bonn_camera.sh" "$SHARED/bonn_crowd_dev" "$BONN_CAM"

median() { sort -g | awk '{a[NR]=$1} END {if (NR == 0) print "nan"; else print (NR%2) ? a[(NR+1)/2] : (a[NR/2]+a[NR/2+1])/2}'; }
field() { awk -v k="$1:" '$1==k {print $2}' "$2"; }
lost() { awk '$1=="frames:" {f=$2} $1=="tracked:" {t=$2} END {print f-t}' "$1"; }

echo "machine: $(nproc) cores, $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | sed 's/^ //')"
echo
echo "| sequence | frames | ATE RMSE (range) | RPE trans | RPE rot | step est / gt | jitter | lost | fps | online ATE (range) | online jitter | Sim(3) scale, ATE | > 5 cm off |"
echo "|---|---|---|---|---|---|---|---|---|---|---|---|---|"
row() {
  local name="$1"; shift
  for i in $(seq "$RUNS"); do
    "$BIN/yesslam" "$@" "${CFGARGS[@]}" --out "$OUT/runs/$name-$i" --quiet > "$OUT/runs/$name-$i.log" 2> "$OUT/runs/$name-$i.err" || true
  done
  m() { for i in $(seq "$RUNS"); do field "$1" "$OUT/runs/$name-$i.log"; done | median; }
  # The spread of the runs (mapping on its own thread makes parallel runs differ): min-max of the ATE.
  range() { for i in $(seq "$RUNS"); do field "$1" "$OUT/runs/$name-$i.log"; done | sort -g | awk 'NR == 1 {lo = $1} {hi = $1} END {printf "%.1f-%.1f", 1000 * lo, 1000 * hi}'; }
  local frames
  frames=$(awk '$1=="frames:" {print $2}' "$OUT/runs/$name-1.log")
  local l; l=$(for i in $(seq "$RUNS"); do lost "$OUT/runs/$name-$i.log"; done | median)
  # The scale a similarity alignment finds (1 = the estimate's size is the ground truth's), and the
  # ATE after it: how much of the error is the trajectory's size (the depth sensor's scale).
  local gt; gt=$(awk '$1=="ground" && $2=="truth:" {print $3}' "$OUT/runs/$name-1.log")
  local fmt=tum; case " $* " in *" --gt-format bonn "*) fmt=bonn ;; esac
  sim3() { for i in $(seq "$RUNS"); do "$BIN/yesslam-eval" --gt "$gt" --gt-format "$fmt" --est "$OUT/runs/$name-$i/trajectory.txt" --sim3 2>/dev/null | field "$1" /dev/stdin; done | median; }
  # Frames more than 5 cm from the truth after the SE(3) alignment.
  far() { for i in $(seq "$RUNS"); do "$BIN/yesslam-eval" --gt "$gt" --gt-format "$fmt" --est "$OUT/runs/$name-$i/trajectory.txt" --errors "$OUT/runs/$name-$i/errors.csv" >/dev/null 2>&1
          awk -F, 'NR > 1 && $2 > 0.05 {n++} END {print n + 0}' "$OUT/runs/$name-$i/errors.csv"; done | median; }
  awk -v n="$name" -v f="$frames" -v a="$(m ate_rmse)" -v t="$(m rpe_trans_rmse)" -v r="$(m rpe_rot_rmse_deg)" \
      -v se="$(m step_est_median)" -v sg="$(m step_gt_median)" -v j="$(m jitter_median)" -v l="$l" -v fps="$(m fps)" \
      -v rg="$(range ate_rmse)" -v o="$(m online_ate_rmse)" -v org="$(range online_ate_rmse)" -v oj="$(m online_jitter_median)" \
      -v sc="$(sim3 scale)" -v sa="$(sim3 ate_rmse)" -v fo="$(far)" \
      'BEGIN {printf "| %s | %s | %.1f mm (%s) | %.1f mm/s | %.2f deg/s | %.1f / %.1f mm | %.1f mm | %s | %.1f | %.1f mm (%s) | %.1f mm | %.3f, %.1f mm | %s |\n",
              n, f, 1000*a, rg, 1000*t, r, 1000*se, 1000*sg, 1000*j, l, fps, 1000*o, org, 1000*oj, sc, 1000*sa, fo}'
}
B="$SHARED/bonn_crowd_dev"
row "bonn_crowd_dev" --input "$B" --gt-format bonn --camera "$BONN_CAM"
row "bonn_crowd_dev_people_free" --input "$B" --gt-format bonn --camera "$BONN_CAM" --max-frames 90
row "bonn_crowd_dev_second_half" --input "$B" --gt-format bonn --camera "$BONN_CAM" --skip-frames 125
row "tum_fr1_rpy_dev" --input "$SHARED/tum_fr1_rpy_dev"
row "tum_fr1_desk_9frames" --input "$SHARED/tum_fr1_desk_9frames"
echo
echo "RPE with delta 1 s (the 9 fr1 frames span 0.3 s: no RPE pair there). Runs in $OUT/runs."
