#!/usr/bin/env bash
# Issue 42 item 1: `cpack -G DEB` makes a .deb holding the library, its CMake package, the apps and
# the shipped files, whose dependencies are Debian packages (dpkg-shlibdeps' run-time libraries and
# the development packages the static library's users need).
# Usage: check_deb.sh BUILD_DIR
set -euo pipefail
build="$1"
work="$(mktemp -d "${TMPDIR:-/tmp}/yesslam_deb.XXXXXX")"
trap 'rm -rf "$work"' EXIT
(cd "$work" && cpack -G DEB --config "$build/CPackConfig.cmake" -B "$work/out" > "$work/cpack.log" 2>&1) \
  || { tail -30 "$work/cpack.log" >&2; exit 1; }
deb="$(ls "$work"/out/*.deb 2>/dev/null | head -1)"
[ -n "$deb" ] || { echo "check_deb: cpack made no .deb" >&2; tail -20 "$work/cpack.log" >&2; exit 1; }
depends="$(dpkg-deb -f "$deb" Depends)"
for p in libmrpt-dev libopencv-dev libceres-dev liboctomap-dev libopenni2-dev libdeflate-dev 'libc6 '; do
  grep -q "$p" <<< "$depends " || { echo "check_deb: $deb does not depend on ${p% }: Depends: $depends" >&2; exit 1; }
done
contents="$(dpkg-deb -c "$deb")"
for f in /bin/yesslam /bin/tum2rawlog /lib/cmake/mrpt_yesslam/mrpt_yesslamConfig.cmake /include/mrpt_yesslam/system/CYesSlamSystem.h \
         /share/mrpt_yesslam/config/default.ini libmrpt_yesslam.a; do
  grep -q -- "$f" <<< "$contents" || { echo "check_deb: $deb has no $f" >&2; exit 1; }
done
echo "check_deb: $(basename "$deb"): $(grep -c . <<< "$contents") entries; Depends: $depends"
