#!/usr/bin/env bash
# Builds the libFuzzer targets with clang (ASan + UBSan) into build-fuzz/ and runs each for
# SECONDS (default 600), one after the other, starting from tests/fuzz/corpus/<target>/.
# New interesting inputs go to build-fuzz/corpus/<target>/; crashes to build-fuzz/crashes/<target>/.
# A crash becomes a regression test by copying its file into tests/fuzz/corpus/<target>/.
# Usage: bench/fuzz.sh [SECONDS] [TARGET ...]
set -euo pipefail
ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
SECONDS_PER="${1:-600}"; shift || true
TARGETS=("$@"); [ ${#TARGETS[@]} -gt 0 ] || TARGETS=(trajectory tum_list association camera_file config rawlog detections map png)
command -v clang++ >/dev/null || {
  SUDO=""; [ "$(id -u)" -eq 0 ] || SUDO=sudo
  $SUDO apt-get install -y -qq clang libclang-rt-14-dev >/dev/null
}
"$ROOT/scripts/install_deps.sh"
BUILD="$ROOT/build-fuzz"
cmake -S "$ROOT" -B "$BUILD" -DCMAKE_BUILD_TYPE=RelWithDebInfo -DCMAKE_CXX_COMPILER=clang++ \
  -DYESSLAM_FUZZ=ON -DYESSLAM_BUILD_TESTS=OFF -DYESSLAM_BUILD_APPS=OFF >/dev/null
cmake --build "$BUILD" -j "$(nproc)" --target $(printf 'fuzz_%s ' "${TARGETS[@]}") >/dev/null
# Huge allocations requested by corrupt files must surface as std::bad_alloc (which our readers
# turn into a clear error), as they do in normal builds, not as an ASan abort.
# A small quarantine: corrupt rawlogs make MRPT allocate (and free) very large blocks, and the
# default quarantine would count them against the RSS limit as if they were still in use.
export ASAN_OPTIONS="allocator_may_return_null=1:detect_leaks=1:quarantine_size_mb=64"
export UBSAN_OPTIONS="halt_on_error=1:print_stacktrace=1:suppressions=$ROOT/tests/sanitizer/ubsan.supp"
for t in "${TARGETS[@]}"; do
  mkdir -p "$BUILD/corpus/$t" "$BUILD/crashes/$t"
  log="$BUILD/fuzz_$t.log"
  # Rawlogs: MRPT allocates what a corrupt file asks for; run in fork mode and skip out-of-memory
  # inputs, so that the search goes on and only real crashes stop it.
  extra=(); [ "$t" = rawlog ] && extra=(-fork=1 -ignore_ooms=1)
  "$BUILD/tests/fuzz/fuzz_$t" "$BUILD/corpus/$t" "$ROOT/tests/fuzz/corpus/$t" "${extra[@]}" \
    -max_total_time="$SECONDS_PER" -rss_limit_mb=12000 -malloc_limit_mb=1024 -max_len=65536 -timeout=20 \
    -artifact_prefix="$BUILD/crashes/$t/" -print_final_stats=1 >"$log" 2>&1 || true
  execs=$(grep -m1 'stat::number_of_executed_units' "$log" | awk '{print $2}')
  crashes=$(find "$BUILD/crashes/$t" -type f | wc -l)
  echo "fuzz_$t: ${SECONDS_PER} s, ${execs:-?} executions, corpus $(ls "$BUILD/corpus/$t" | wc -l) files, findings: $crashes (log $log)"
done
