#!/usr/bin/env bash
# Configures and builds mrpt_yesslam (Release, all cores) into build/ or the folder given as $1.
# Extra arguments after the folder go to cmake; YESSLAM_TARGETS="a b" builds only those targets.
# Compiles through ccache when it is installed (a rebuild after a small change takes seconds).
set -euo pipefail
ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
BUILD="${1:-$ROOT/build}"
shift || true
LAUNCHER=()
command -v ccache >/dev/null && LAUNCHER=(-DCMAKE_CXX_COMPILER_LAUNCHER=ccache)
# ccache caches files compiled with the precompiled header only with these (its manual's PCH section).
export CCACHE_SLOPPINESS="pch_defines,time_macros,include_file_mtime,include_file_ctime"
cmake -S "$ROOT" -B "$BUILD" -DCMAKE_BUILD_TYPE=Release "${LAUNCHER[@]}" "$@" >/dev/null
TARGETS=()
for t in ${YESSLAM_TARGETS:-}; do TARGETS+=(--target "$t"); done
cmake --build "$BUILD" -j "$(nproc)" "${TARGETS[@]}"
