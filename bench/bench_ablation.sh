#!/usr/bin/env bash
# Ablation of the default configuration against the paper's pipeline (issue 39 item 0): every way
# default.ini departs from paper.ini, switched off one at a time (set to paper.ini's value), on
#   - the real Bonn slice's two halves, each run as a sequence of its own (A = slice frames 0-124:
#     the people-free pan, people entering at the end; B = frames 125-249: people from the first
#     frame), with the dataset's published distortion;
#   - the 9 real TUM fr1/desk frames, and ../shared/data/tum_fr1_rpy_dev (300 Kinect frames turning
#     in place) when it is there (a row says so when it is not);
#   - two --real-sensor simulations: walking_xyz (seed 41) and the real fr1/xyz camera path
#     replayed in the walking room (evo_freiburg1_xyz ground truth, seed 42), FRAMES frames each.
# Runs are sequential (--sequential: deterministic, so one run per cell), without the dense map
# (it does not move the trajectory). Each cell: ATE RMSE of trajectory.txt (each frame carried by
# its keyframe) / ATE RMSE of trajectory_online.txt / the online jitter (median length of the
# difference between the estimate's and the truth's frame-to-frame steps), mm. The verdict column applies the
# rule of issue 39: a departure stays only where switching it off is worse on both real cameras
# (the Bonn halves together, the TUM Kinect frames) and not better on the sims.
# Usage: bench/bench_ablation.sh [FRAMES]   (outputs in bench_out/ablation/; a run is reused while its
# binary, configuration and sequence are unchanged; RERUN=1 runs every one again)
set -euo pipefail
ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
BIN="${BIN:-$ROOT/build/rawlog_tools}"
# shellcheck source=bench/sim_sequence.sh
source "$(dirname "${BASH_SOURCE[0]}")/sim_sequence.sh"
FRAMES="${1:-200}"
SHARED="$ROOT/../shared/data"
for t in yesslam yesslam-sim; do [ -x "$BIN/$t" ] || { echo "bench: build first (./scripts/build.sh)" >&2; exit 1; }; done
for d in bonn_crowd_dev tum_fr1_desk_9frames tum_eval_trajectories; do
  [ -d "$SHARED/$d" ] || { echo "bench: $SHARED/$d is missing" >&2; exit 1; }
done
OUT="$ROOT/bench_out/ablation"; mkdir -p "$OUT/runs" "$OUT/cfg"
BONN_CAM="$OUT/bonn_camera.txt"
"$ROOT/bench/bonn_camera.sh" "$SHARED/bonn_crowd_dev" "$BONN_CAM"
sim_sequence "$OUT/sim_walking_xyz" --preset walking_xyz --real-sensor --seed 41 --frames "$FRAMES" --det-noise yolo --no-rawlog --quiet
sim_sequence "$OUT/sim_fr1_xyz_path" --preset walking_xyz --real-sensor --seed 42 --frames "$FRAMES" --det-noise yolo --no-rawlog --quiet \
  --trajectory "$SHARED/tum_eval_trajectories/evo_freiburg1_xyz-groundtruth.txt"

# The departures: name, then the INI lines that switch it off (paper.ini's values). "default" and
# "paper" are the two ends.
DEPARTURES=(
  "default|"
  "depth residual ([Camera] depthNoise = 0)|[Camera]\ndepthNoise = 0"
  "depth error growing with z^2.5 (z^2 instead)|[Camera]\ndepthNoiseExponent = 2"
  "fill against the neighbour, depth range cap|[DynamicMask]\nfillCompare = seed\nmaxDepthRange = 0"
  "masks held for missed detections|[DynamicMask]\nholdFrames = 0"
  "geometric check (mover check and its uncertain regions)|[GeometricCheck]\nenabled = false\nmovers = false"
  "see-through culling|[Tracking]\nseeThroughFrames = 0"
  "weak solutions checked against the motion model|[Tracking]\nweakInliers = 0"
  "online pose filtered causally|[OnlinePose]\npositionSigma = 0"
  "forced keyframes when tracking thins|[KeyFrames]\nforceTrackedRatio = 0"
  "semantic choice against the reference ratio|[KeyFrames]\nsemanticRefRatio = 1"
  "keyframe motion measured from the tracker's reference|[KeyFrames]\nmotionReference = previous"
  "eta bounded as the paper's intent, not as written|[KeyFrames]\netaAsWritten = true"
  "normalised BoW score in loop detection|[LoopClosing]\nnormaliseBow = false"
  "paper.ini (all of them off)|@paper"
)
SEQS=(bonn_a bonn_b fr1_desk fr1_rpy sim_xyz sim_fr1path)
declare -A SEQARGS=(
  [bonn_a]="--input $SHARED/bonn_crowd_dev --camera $BONN_CAM --gt-format bonn --max-frames 125"
  [bonn_b]="--input $SHARED/bonn_crowd_dev --camera $BONN_CAM --gt-format bonn --skip-frames 125 --max-frames 125"
  [fr1_desk]="--input $SHARED/tum_fr1_desk_9frames"
  [fr1_rpy]="--input $SHARED/tum_fr1_rpy_dev"
  [sim_xyz]="--input $OUT/sim_walking_xyz"
  [sim_fr1path]="--input $OUT/sim_fr1_xyz_path"
)
cell() {  # cell TAG SEQ CFG: "ATE / jitter" in mm, "failed" (see the run's log) or "missing"
  local tag="$1" seq="$2" cfg="$3" dir="$OUT/runs/$1-$2"
  if [ "$seq" = fr1_rpy ] && [ ! -d "$SHARED/tum_fr1_rpy_dev" ]; then echo "missing"; return; fi
  # A run is reused only while it is what would run now: the same binary, configuration lines,
  # sequence arguments and (for the sims) sequence.
  local key; key="$(stat -c '%Y %s' "$BIN/yesslam") $(cat "$cfg") ${SEQARGS[$seq]} $(cat "${SEQARGS[$seq]##* }/.bench_key" 2>/dev/null || true)"
  if [ "${RERUN:-0}" != 0 ] || [ ! -f "$dir/eval.json" ] || [ "$(cat "$dir/.bench_key" 2>/dev/null)" != "$key" ]; then
    rm -rf "$dir"
    # shellcheck disable=SC2086  # SEQARGS are word lists
    "$BIN/yesslam" ${SEQARGS[$seq]} --config "$cfg" --sequential --no-dense-map --quiet --out "$dir" > "$dir.log" 2>&1 || true
    [ -d "$dir" ] && printf '%s' "$key" > "$dir/.bench_key"
  fi
  python3 - "$dir/eval.json" "$dir/eval_online.json" <<'PY' 2>/dev/null || echo "failed"
import json, sys
e = json.load(open(sys.argv[1])); o = json.load(open(sys.argv[2]))
print("%.1f / %.1f / %.1f" % (1000 * e["ate_rmse"], 1000 * o["ate_rmse"], 1000 * o["jitter_median"]))
PY
}
echo "machine: $(nproc) cores, $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | sed 's/^ //'); sims $FRAMES frames; cells ATE RMSE / online ATE RMSE / online jitter, mm"
echo
echo "| switched off | Bonn A | Bonn B | fr1 desk 9 | fr1 rpy | sim walking_xyz | sim fr1/xyz path | verdict |"
echo "|---|---|---|---|---|---|---|---|"
declare -A BASE
i=0
for d in "${DEPARTURES[@]}"; do
  name="${d%%|*}"; lines="${d#*|}"; tag="d$i"; i=$((i + 1))
  cfg="$OUT/cfg/$tag.ini"
  if [ "$lines" = "@paper" ]; then cfg="$ROOT/share/mrpt_yesslam/config/paper.ini"
  else printf '%b\n' "$lines" > "$cfg"; fi
  vals=()
  for s in "${SEQS[@]}"; do vals+=("$(cell "$tag" "$s" "$cfg")"); done
  verdict=""
  if [ "$tag" = d0 ]; then
    for k in "${!SEQS[@]}"; do BASE[${SEQS[$k]}]="${vals[$k]%% *}"; done
  else
    # Worse (switching off hurts) by more than the tie-choice noise (0.7 mm Bonn, 0.5 mm elsewhere).
    verdict=$(python3 - "${BASE[bonn_a]}" "${BASE[bonn_b]}" "${BASE[fr1_desk]}" "${BASE[fr1_rpy]}" "${BASE[sim_xyz]}" "${BASE[sim_fr1path]}" \
      "${vals[0]%% *}" "${vals[1]%% *}" "${vals[2]%% *}" "${vals[3]%% *}" "${vals[4]%% *}" "${vals[5]%% *}" <<'PY'
import sys
def f(x):
    try: return float(x)
    except ValueError: return None
b = [f(x) for x in sys.argv[1:7]]; v = [f(x) for x in sys.argv[7:13]]
d = [None if x is None or y is None else y - x for x, y in zip(b, v)]   # off minus on: > 0 = the departure helps
bonn = None if d[0] is None or d[1] is None else d[0] + d[1]
kinect = [x for x in (d[2], d[3]) if x is not None]
kin = sum(kinect) if kinect else None
sims = [x for x in (d[4], d[5]) if x is not None]
if bonn is None or kin is None or len(sims) < 2: print("? (a run failed: see its log)")
elif bonn > 0.7 and kin > 0.5 and min(sims) > -0.5: print("keep (helps both cameras)")
elif bonn < -0.7 and kin < -0.5: print("drop (hurts both cameras)")
else: print("mixed: Bonn %+.1f, Kinect %+.1f, sims %+.1f / %+.1f mm" % (bonn, kin, sims[0], sims[1]))
PY
)
  fi
  echo "| $name | ${vals[0]} | ${vals[1]} | ${vals[2]} | ${vals[3]} | ${vals[4]} | ${vals[5]} | $verdict |"
done
echo
echo "Cells: the run with that departure switched off (its paper.ini value), everything else default."
echo "Verdict: off-minus-on summed over the two Bonn halves and over the Kinect sequences; 'keep' when"
echo "both are worse without it (beyond the 0.7 / 0.5 mm that the choice among tied corners moves a"
echo "run) and no sim gets better without it."
[ -d "$SHARED/tum_fr1_rpy_dev" ] || echo "$SHARED/tum_fr1_rpy_dev is missing here: the Kinect camera is judged on 9 frames only."
