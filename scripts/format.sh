#!/usr/bin/env bash
# Formats every C++ file of the project in place with .clang-format (Debian 12's clang-format 14),
# as tests/structure/check_format.sh checks it.
set -euo pipefail
cd "$(dirname "$0")/.."
find mrpt_yesslam apps rawlog_tools tests bench examples \( -name '*.cpp' -o -name '*.h' \) -print0 | xargs -0 clang-format-14 -i
