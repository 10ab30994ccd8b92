#!/usr/bin/env bash
# The main job on the embedded default data, as a new user would run it: installs dependencies,
# builds, generates a short walking sequence with yesslam-sim, runs yesslam on it (file detector),
# prints ATE/RPE against ground truth, renders the map; then shorter tours of the other tools on
# real TUM RGB-D material from ../shared. Prints where every result is.
set -euo pipefail
ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
SHARED="$(cd "$ROOT/.." && pwd)/shared"
OUT="$ROOT/out/demo"
cd "$ROOT"
[ -d "$SHARED/data" ] || { echo "demo: error: $SHARED/data not found (the demo data lives in ../shared)" >&2; exit 1; }
./scripts/install_deps.sh
echo "demo: building (Release) ..."
# Every tool, so that `cmake --install build` works after the demo (the tests, if configured, are
# left to ./scripts/test.sh).
cmake -S "$ROOT" -B "$ROOT/build" -DCMAKE_BUILD_TYPE=Release >/dev/null
cmake --build "$ROOT/build" -j "$(nproc)" --target yesslam_tools >/dev/null
BIN="$ROOT/build/rawlog_tools"
mkdir -p "$OUT"
DESK="$SHARED/data/tum_fr1_desk_9frames"
TRAJ="$SHARED/data/tum_eval_trajectories"

echo; echo "== 1. The main job: SLAM on a walking sequence (people crossing an office), against exact ground truth =="
"$BIN/yesslam-sim" --preset walking_xyz --frames 150 --out "$OUT/sim_walking_xyz" --overlays --quiet
"$BIN/yesslam" --input "$OUT/sim_walking_xyz" --config "$ROOT/share/mrpt_yesslam/config/sim.ini" --out "$OUT/slam_walking_xyz" --detector file --quiet
# The default view: the z-up map from behind its first camera, dense cloud, map points and path.
"$BIN/yesslam-render" --scene "$OUT/slam_walking_xyz/map.3Dscene" --out "$OUT/slam_walking_xyz/map.png" --elevation 45
"$BIN/yesslam-render" --scene "$OUT/slam_walking_xyz/map.3Dscene" --out "$OUT/slam_walking_xyz/octomap.png" --elevation 45 \
  --hide dense_cloud,map_points,keyframe

echo; echo "== 2. The same run without any dynamic handling (--no-dynamic-filter: people's features used, as ORB-SLAM2 would) =="
"$BIN/yesslam" --input "$OUT/sim_walking_xyz" --config "$ROOT/share/mrpt_yesslam/config/sim.ini" --out "$OUT/slam_walking_xyz_unfiltered" --detector file --no-dynamic-filter --quiet \
  | grep -E '^(ate_rmse|rpe_trans_rmse|tracked):'

echo; echo "== 3. Real Kinect frames (TUM fr1/desk): SLAM, rawlog conversion, frames at ground-truth poses -> 3D scene =="
"$BIN/yesslam" --input "$DESK" --out "$OUT/slam_fr1_desk" --detector none --quiet | grep -E '^(tracked|ate_rmse):'
"$BIN/tum2rawlog" --input "$DESK" --output "$OUT/fr1_desk_9frames.rawlog"
"$BIN/yesslam-cloud" --input "$OUT/fr1_desk_9frames.rawlog" --poses "$OUT/fr1_desk_9frames_groundtruth.txt" \
  --out "$OUT/fr1_desk_cloud.3Dscene" --stride 2
"$BIN/yesslam-render" --scene "$OUT/fr1_desk_cloud.3Dscene" --out "$OUT/fr1_desk_cloud.png" --azimuth -60 --elevation 20

echo; echo "== 4. ATE/RPE of a published RGB-D SLAM estimate (fr1/xyz), as the TUM tools compute them =="
"$BIN/yesslam-eval" --gt "$TRAJ/evo_freiburg1_xyz-groundtruth.txt" --est "$TRAJ/evo_freiburg1_xyz-rgbdslam.txt" \
  --json "$OUT/fr1_xyz_rgbdslam_eval.json" --plot "$OUT/fr1_xyz_rgbdslam_ate.png"

echo; echo "== 5. YOLO detection (Yolo-Fastest, OpenCV DNN, CPU) on a real TUM fr3/walking_xyz frame =="
M="$SHARED/models/yolo_fastest_darknet"
"$BIN/yesslam-detect" --model "$M/yolo-fastest-1.1-xl.cfg" --weights "$M/yolo-fastest-1.1-xl.weights" --names "$M/coco.names" \
  --input "$SHARED/data/tum_sample_frames/fr3_walking/fr3_walking_xyz_rgb_1341846313.553992.png" --out "$OUT/detect_fr3_walking" \
  --overlay --quiet

echo
echo "demo: results in $OUT"
echo "  SLAM (main job): $OUT/slam_walking_xyz/ (trajectory.txt, keyframes.txt, map.3Dscene, map.png, dense_cloud.ply, map.ot, map.bt, octomap.png, stats.json, eval.json, ate.png)"
echo "  without filter:  $OUT/slam_walking_xyz_unfiltered/"
echo "  simulation:      $OUT/sim_walking_xyz/ (TUM folder, groundtruth.txt, labels/, labels/overlay/, detections.txt)"
echo "  real frames:     $OUT/slam_fr1_desk/, rawlog $OUT/fr1_desk_9frames.rawlog"
echo "  3D scene:        $OUT/fr1_desk_cloud.3Dscene (view: SceneViewer3D, or yesslam-render), picture fr1_desk_cloud.png"
echo "  evaluation:      $OUT/fr1_xyz_rgbdslam_eval.json, plot $OUT/fr1_xyz_rgbdslam_ate.png"
echo "  detection:       $OUT/detect_fr3_walking/ (detections.txt, overlays/0.000000.png)"
