#!/usr/bin/env bash
# Installs dependencies, builds (Release, all cores) and runs the whole test suite with ctest.
# The tests read data from ../shared beside the repository and fail if it is missing.
set -euo pipefail
ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
cd "$ROOT"
start=$(date +%s)
./scripts/install_deps.sh
./scripts/build.sh "$ROOT/build"
built=$(date +%s)
cd "$ROOT/build"
ctest --output-on-failure -j "$(nproc)"
echo "test.sh: build $((built - start)) s, tests $(( $(date +%s) - built )) s"
