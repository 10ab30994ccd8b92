#!/usr/bin/env bash
# Installs dependencies, builds (Release, all cores) and runs the whole test suite with ctest.
#   ./scripts/test.sh             normal build in build/
#   ./scripts/test.sh --sanitize  ASan + UBSan build in build-sanitize/, same suite, halting on the first finding
# The tests read data from ../shared beside the repository and fail if it is missing.
set -euo pipefail
ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
cd "$ROOT"
mode="normal"
case "${1:-}" in
  "") ;;
  --sanitize) mode="sanitize" ;;
  -h|--help) sed -n '2,5p' "$0" | sed 's/^# \{0,1\}//'; exit 0 ;;
  *) echo "test.sh: error: unknown option '$1' (use --sanitize or nothing)" >&2; exit 2 ;;
esac
start=$(date +%s)
./scripts/install_deps.sh
if [ "$mode" = sanitize ]; then
  BUILD="$ROOT/build-sanitize"
  ./scripts/build.sh "$BUILD" -DCMAKE_BUILD_TYPE=RelWithDebInfo -DYESSLAM_SANITIZE=ON -DYESSLAM_BUILD_TESTS=ON
  # allocator_may_return_null: a corrupt file asking for terabytes must get std::bad_alloc (and our
  # clear error), as in a normal build, not an ASan abort.
  export ASAN_OPTIONS="halt_on_error=1:detect_leaks=1:abort_on_error=0:allocator_may_return_null=1"
  export UBSAN_OPTIONS="halt_on_error=1:print_stacktrace=1:suppressions=$ROOT/tests/sanitizer/ubsan.supp"
  # Leaks inside Mesa's OpenGL driver only (tests/sanitizer/lsan.supp says which and why).
  export LSAN_OPTIONS="suppressions=$ROOT/tests/sanitizer/lsan.supp"
else
  BUILD="$ROOT/build"
  ./scripts/build.sh "$BUILD" -DYESSLAM_BUILD_TESTS=ON
fi
built=$(date +%s)
cd "$BUILD"
ctest --output-on-failure -j "$(nproc)"
echo "test.sh ($mode): build $((built - start)) s, tests $(( $(date +%s) - built )) s"
