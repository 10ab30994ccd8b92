#!/usr/bin/env bash
# Trains the ORB vocabulary shipped in share/mrpt_yesslam/vocabulary/orb_k10_L5.yvoc (the recipe of
# the shipped file; rerun it, or add your own images, to retrain for your environment):
#   - yesslam-sim renders of every preset with several seeds (procedural and photo textures),
#   - real photographs: the sample images of Debian's opencv-doc package (installed with apt if
#     missing) and the real TUM frames in ../shared/data/tum_sample_frames (fr2 desk, fr3 walking),
#   - EXTRA_INPUTS="dir1 dir2 ...": your own image folders, TUM folders or rawlogs.
# The fr1 desk frames in ../shared are held out: the tests use them as an unseen place.
# Usage: scripts/train_vocabulary.sh [OUT.yvoc]   (builds yesslam-sim and yesslam-vocab if needed)
set -euo pipefail
ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
BUILD="${BUILD_DIR:-$ROOT/build}"
OUT="${1:-$ROOT/share/mrpt_yesslam/vocabulary/orb_k10_L5.yvoc}"
WORK="${WORK_DIR:-$ROOT/vocab_work}"
SHARED="${YESSLAM_SHARED_DIR:-$ROOT/../shared}"
SEEDS="${SEEDS:-101 102 103 104 105 106 107 108}"
PHOTOS=/usr/share/doc/opencv-doc/examples/data

if [ ! -d "$PHOTOS" ]; then
  SUDO=""; [ "$(id -u)" = 0 ] || SUDO=sudo
  echo "train_vocabulary: installing opencv-doc for its sample photographs" >&2
  $SUDO apt-get install -y -qq --no-install-recommends opencv-doc >/dev/null
fi
[ -x "$BUILD/rawlog_tools/yesslam-vocab" ] || YESSLAM_TARGETS="yesslam-sim yesslam-vocab" "$ROOT/scripts/build.sh" "$BUILD"

mkdir -p "$WORK"
INPUTS=()
for preset in walking_xyz walking_rpy walking_halfsphere sitting_xyz sitting_halfsphere static_office office_loop; do
  for seed in $SEEDS; do
    dir="$WORK/sim_${preset}_$seed"
    [ -f "$dir/associations.txt" ] || "$BUILD/rawlog_tools/yesslam-sim" --preset "$preset" --seed "$seed" --frames 150 \
      --no-rawlog --quiet --out "$dir" >/dev/null
    INPUTS+=(--input "$dir")
  done
done
# The same rooms dressed in real photographs, so words for natural texture are not only learnt
# from a hundred photos.
for seed in $SEEDS; do
  dir="$WORK/sim_photo_walking_halfsphere_$seed"
  [ -f "$dir/associations.txt" ] || "$BUILD/rawlog_tools/yesslam-sim" --preset walking_halfsphere --seed "$seed" --frames 150 \
    --textures "$PHOTOS" --no-rawlog --quiet --out "$dir" >/dev/null
  INPUTS+=(--input "$dir")
done
INPUTS+=(--input "$PHOTOS" --input "$SHARED/data/tum_sample_frames" --input "$SHARED/data/detector_test_images")
for extra in ${EXTRA_INPUTS:-}; do INPUTS+=(--input "$extra"); done

mkdir -p "$(dirname "$OUT")"
"$BUILD/rawlog_tools/yesslam-vocab" "${INPUTS[@]}" --step 5 --k 10 --levels 5 --seed 1 --out "$OUT"
"$BUILD/rawlog_tools/yesslam-vocab" --info "$OUT"
