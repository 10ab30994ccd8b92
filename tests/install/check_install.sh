#!/usr/bin/env bash
# Issue 42 items 1-2: the project installs as a component other robots build on. Installs the build
# tree into a temporary prefix, builds examples/ OUT OF TREE against it with find_package (a separate
# CMake project that sees only the install), runs the example on the real TUM fr1 frames (CC BY 4.0,
# Sturm et al. 2012; ../shared/data/tum_fr1_desk_9frames/SOURCE.md) converted to a rawlog, and checks
# what it wrote: every frame has a pose near the motion-capture ground truth and the map scene is a
# real MRPT scene (rendered by the installed yesslam-render). The prefix is moved after installing,
# so nothing can be found through the paths the build knew.
# Usage: check_install.sh BUILD_DIR SOURCE_DIR SHARED_DIR
set -euo pipefail
build="$1"; src="$2"; shared="$3"
frames="$shared/data/tum_fr1_desk_9frames"
[ -d "$frames" ] || { echo "check_install: $frames: missing (../shared must be beside the repository)" >&2; exit 1; }
work="$(mktemp -d "${TMPDIR:-/tmp}/yesslam_install.XXXXXX")"
trap 'rm -rf "$work"' EXIT
cmake --install "$build" --prefix "$work/prefix" > "$work/install.log"
mv "$work/prefix" "$work/moved"
prefix="$work/moved"
for f in bin/yesslam bin/yesslam-render include/mrpt_yesslam/system/CYesSlamSystem.h \
         share/mrpt_yesslam/models share/mrpt_yesslam/config/default.ini \
         lib/cmake/mrpt_yesslam/mrpt_yesslamConfig.cmake lib/cmake/mrpt_yesslam/mrpt_yesslamConfigVersion.cmake; do
  [ -e "$prefix/$f" ] || { echo "check_install: the install has no $f" >&2; exit 1; }
done
# The SLAM library's install carries none of the tools' headers or code.
if [ -e "$prefix/include/mrpt_yesslam/sim" ] || [ -e "$prefix/include/mrpt_yesslam/eval" ] || [ -e "$prefix/include/mrpt_yesslam/render" ]; then
  echo "check_install: tool headers (sim/, eval/, render/) were installed with the SLAM library" >&2; exit 1
fi
# A version the package does not have is refused, the one it has is found.
mkdir -p "$work/probe"
cat > "$work/probe/CMakeLists.txt" <<'CM'
cmake_minimum_required(VERSION 3.16)
project(probe CXX)
find_package(mrpt_yesslam ${WANT} QUIET)
message(STATUS "FOUND=${mrpt_yesslam_FOUND}")
CM
found() { cmake -S "$work/probe" -B "$work/probe/b$1" -DWANT="$1" -DCMAKE_PREFIX_PATH="$prefix" 2>&1 | sed -n 's/.*FOUND=//p'; }
[ "$(found 0.1)" = 1 ] || { echo "check_install: find_package(mrpt_yesslam 0.1) did not find the install" >&2; exit 1; }
[ "$(found 9.0)" = 0 ] || { echo "check_install: find_package(mrpt_yesslam 9.0) accepted version $(cat "$src/CMakeLists.txt" | grep -o 'VERSION [0-9.]*' | head -1)" >&2; exit 1; }

command -v ccache >/dev/null && launcher=(-DCMAKE_CXX_COMPILER_LAUNCHER=ccache) || launcher=()
cmake -S "$src/examples" -B "$work/examples" -DCMAKE_PREFIX_PATH="$prefix" "${launcher[@]}" > "$work/configure.log" \
  || { cat "$work/configure.log" >&2; exit 1; }
cmake --build "$work/examples" -j "$(nproc)" > "$work/build.log" 2>&1 || { tail -30 "$work/build.log" >&2; exit 1; }
# The example and the tools run from the install only: nothing of the build tree on their path.
"$prefix/bin/tum2rawlog" --input "$frames" --output "$work/fr1.rawlog" --external-images --quiet
out="$(cd "$work" && "$work/examples/rawlog_slam" "$work/fr1.rawlog" "$work/run")"
echo "$out"
grep -q "9 frames, 9 tracked" <<< "$out" || { echo "check_install: the example did not track all 9 frames" >&2; exit 1; }
# The readout went with the rawlog (fr1.rawlog's camera file) and the library found it as the app does.
grep -q "readout 0.028 s, from the recording's camera file" <<< "$out" \
  || { echo "check_install: the example did not take the rawlog's rolling-shutter readout from its camera file" >&2; exit 1; }
# The shipped model and vocabulary came from the moved install (through the package's share folder).
grep -q "detector .*yolo-fastest" <<< "$out" && grep -q "vocabulary loaded" <<< "$out" \
  || { echo "check_install: the example did not find the installed model and vocabulary" >&2; exit 1; }
n=$(grep -vc '^#' "$work/run/trajectory.txt")
[ "$n" = 9 ] || { echo "check_install: trajectory.txt has $n poses, expected 9" >&2; exit 1; }
"$prefix/bin/yesslam-eval" --gt "$frames/groundtruth.txt" --est "$work/run/trajectory.txt" --json "$work/eval.json" > /dev/null
ate=$(grep -o '"ate_rmse": *[0-9.eE+-]*' "$work/eval.json" | sed 's/.*: *//')
[ -n "$ate" ] && awk -v a="$ate" 'BEGIN { exit !(a < 0.02) }' \
  || { echo "check_install: the example's trajectory is '$ate' m from the ground truth (ATE), expected < 0.02" >&2; exit 1; }
"$prefix/bin/yesslam-render" --scene "$work/run/map.3Dscene" --out "$work/map.png" > /dev/null
[ -s "$work/map.png" ] || { echo "check_install: the example's map.3Dscene did not render" >&2; exit 1; }
echo "check_install: installed, found as a package, example built out of tree: 9/9 frames, ATE $ate m, scene renders"
