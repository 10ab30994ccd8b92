#!/usr/bin/env bash
# Times every detector model in ../shared/models and the dynamic-object masker on 640x480 frames.
# Usage: bench/bench_detection.sh [RUNS]   (default 15; medians). Build first: ./scripts/build.sh
set -euo pipefail
ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
SHARED="$(cd "$ROOT/.." && pwd)/shared"
BIN="$ROOT/build/bench/bench_detection"
[ -x "$BIN" ] || { echo "bench: build first (./scripts/build.sh)" >&2; exit 1; }
echo "machine: $(nproc) cores, $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | sed 's/^ //')"
"$BIN" "$SHARED" "${1:-15}"
