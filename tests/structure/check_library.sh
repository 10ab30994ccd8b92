#!/usr/bin/env bash
# The SLAM library (mrpt_yesslam) neither holds nor calls the tools' code (issue 28 item 8): the
# simulator, the renderer, the evaluator and the command-line jobs live in mrpt_yesslam_tools, which
# links it. Usage: check_library.sh LIBRARY (a static or shared mrpt_yesslam).
set -euo pipefail
lib="$1"
[ -f "$lib" ] || { echo "check_library: $lib: not found" >&2; exit 1; }
syms="$(nm -C "$lib" 2>/dev/null)"
[ -n "$syms" ] || { echo "check_library: $lib: no symbols read (nm)" >&2; exit 1; }
# One name of each tool part: defined or referenced, it must not appear.
bad="$(grep -E 'mrpt_yesslam::(CSequenceSimulator|CSimWorld|CBoxRaycaster|renderScene|loadScene|computeAte|computeRpe|evaluateTrajectories|writeTrajectoryPlot|CSensorStatistics|runSlamJob|runDetectionJob)\b' <<< "$syms" || true)"
if [ -n "$bad" ]; then
  echo "check_library: $lib holds or calls tool code:" >&2
  head -20 <<< "$bad" >&2
  exit 1
fi
echo "check_library: $lib holds the SLAM stages only ($(grep -c ' T ' <<< "$syms") functions)"
