#!/usr/bin/env bash
# Map reuse (issue 17, item 6). One simulated room (room seed ROOM) is mapped by an office_tour pass
# (the camera turns round the room, people walking) and saved; then second passes through the same
# room with other seeds, other camera paths and people elsewhere, each started some frames in (so it
# does not begin where the map began), load the map and localise in it (--localize-only), and again
# extending it. Prints the map file's size and load/save times (median of 5, and per 1000
# keyframes), then per pass: the first frame with a pose and the time to it (relocalisation), the
# frames tracked, and the RMSE of the positions in the saved map's frame without any alignment.
# Runs are sequential, so every accuracy figure is exact and repeatable.
# Usage: bench/bench_map.sh [ROOM] [FRAMES]   (sequences and runs are kept in bench_out/map/)
set -euo pipefail
ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
ROOM="${1:-41}"; FRAMES="${2:-600}"
BIN="$ROOT/build/rawlog_tools"; BENCH="$ROOT/build/bench/bench_map"
# shellcheck source=bench/sim_sequence.sh
source "$(dirname "${BASH_SOURCE[0]}")/sim_sequence.sh"
for t in "$BIN/yesslam" "$BIN/yesslam-sim" "$BENCH"; do [ -x "$t" ] || { echo "bench: build first (./scripts/build.sh build -DYESSLAM_BUILD_BENCH=ON)" >&2; exit 1; }; done
OUT="$ROOT/bench_out/map"; mkdir -p "$OUT"
sim() {  # sim NAME PRESET SEED
  sim_sequence "$OUT/$1" --preset "$2" --room-seed "$ROOM" --seed "$3" --frames "$FRAMES" --no-rawlog --quiet
}
sim pass1 office_tour "$ROOM"
"$BIN/yesslam" --input "$OUT/pass1" --out "$OUT/run_pass1" --sequential --quiet --no-dense-map --save-map "$OUT/room.ysm" > "$OUT/run_pass1.log"
echo "machine: $(nproc) cores, $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | sed 's/^ //'); room seed $ROOM, $FRAMES frames per pass"
echo "map: office_tour pass, $(grep -E '^keyframes:' "$OUT/run_pass1.log" | sed 's/keyframes: *//'), ATE $(awk '/^ate_rmse:/ {printf "%.1f mm", 1000*$2}' "$OUT/run_pass1.log")"
"$BENCH" io "$OUT/room.ysm" 5
echo
echo "| second pass | started at frame | first pose at frame | time to first pose ms | tracked | RMSE in the map's frame, localise only | RMSE, extending the map |"
echo "|---|---|---|---|---|---|---|"
i=0
for spec in walking_halfsphere:$((ROOM + 1)):60 walking_rpy:$((ROOM + 2)):150 walking_xyz:$((ROOM + 3)):300 office_tour:$((ROOM + 4)):200; do
  IFS=: read -r preset seed skip <<< "$spec"
  name="pass_${preset}_s$seed"; sim "$name" "$preset" "$seed"
  for mode in loc ext; do
    extra=(--localize-only); [ "$mode" = ext ] && extra=()
    "$BIN/yesslam" --input "$OUT/$name" --skip-frames "$skip" --out "$OUT/run_${name}_$mode" --load-map "$OUT/room.ysm" "${extra[@]}" \
      --sequential --quiet --no-dense-map > "$OUT/run_${name}_$mode.log" 2>&1 || { echo "| $preset seed $seed | failed: $(tail -1 "$OUT/run_${name}_$mode.log") |"; continue 2; }
    "$BENCH" localisation "$OUT/pass1/groundtruth.txt" "$OUT/$name/groundtruth.txt" "$OUT/run_${name}_$mode/trajectory.txt" \
      "$OUT/run_${name}_$mode/frames.csv" > "$OUT/run_${name}_$mode.loc"
  done
  v() { awk -v k="$1:" '$1 == k {print $2}' "$OUT/run_${name}_$2.loc"; }
  echo "| $preset, seed $seed | $skip | $(v first_pose_frame loc) | $(v time_to_first_pose_ms loc) | $(awk '$1 == "tracked_frames:" {print $2 " of " $4}' "$OUT/run_${name}_loc.loc") | $(v rmse_in_map_frame_mm loc) mm | $(v rmse_in_map_frame_mm ext) mm |"
  i=$((i + 1))
done
