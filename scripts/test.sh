#!/usr/bin/env bash
# Installs dependencies, builds (Release, all cores) and runs the whole test suite with ctest.
#   ./scripts/test.sh             normal build in build/
#   ./scripts/test.sh --sanitize  ASan + UBSan build in build-sanitize/, same suite, halting on the first finding
#   ./scripts/test.sh --tsan      ThreadSanitizer build in build-tsan/: the tests that run threads
# The tests read data from ../shared beside the repository and fail if it is missing.
set -euo pipefail
ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
cd "$ROOT"
mode="normal"
case "${1:-}" in
  "") ;;
  --sanitize) mode="sanitize" ;;
  --tsan) mode="tsan" ;;
  -h|--help) sed -n '2,6p' "$0" | sed 's/^# \{0,1\}//'; exit 0 ;;
  *) echo "test.sh: error: unknown option '$1' (use --sanitize, --tsan or nothing)" >&2; exit 2 ;;
esac
start=$(date +%s)
./scripts/install_deps.sh
FILTER=()
AGAIN=()  # a second selection ctest runs after the first (ctest's -R and -E cannot say "all but these suites, save these tests")
# The TSan build: -O1 and line tables only (-g1), the sanitizers' recommended setting, which
# compiles much faster than -O2 -g and still gives file:line in every report.
SANFLAGS=(-DCMAKE_BUILD_TYPE=RelWithDebInfo "-DCMAKE_CXX_FLAGS_RELWITHDEBINFO=-O1 -g1")
if [ "$mode" = tsan ]; then
  # Only what runs threads of ours: the worker pool and what is built on it (prefetching reader,
  # asynchronous detector and frame builder, the system with its mapping stage). The system tests
  # run yesslam and yesslam-sim, which the build brings along.
  BUILD="$ROOT/build-tsan"
  # Set before building: gtest_discover_tests runs the test executables at build time.
  # Reports inside third-party libraries only (tests/sanitizer/tsan.supp says which and why).
  export TSAN_OPTIONS="halt_on_error=1:second_deadlock_stack=1:suppressions=$ROOT/tests/sanitizer/tsan.supp"
  YESSLAM_TARGETS="util_unittest io_unittest system_unittest loop_unittest" \
    ./scripts/build.sh "$BUILD" "${SANFLAGS[@]}" -DYESSLAM_SANITIZE=thread -DYESSLAM_BUILD_TESTS=ON -DYESSLAM_BUILD_BENCH=OFF \
      -DYESSLAM_TEST_CACHE_DIR="$ROOT/build/tests/cache"
  # The system tests that run mapping on its own thread; the single-threaded ones add only time.
  FILTER=(-R "WorkerPool|WriterFirstMutex|PngWriter|Prefetch|LiveSource|FrameBuilder|System\\.(ParallelMappingMapsEveryKeyFrame|MapCheckpointsWhileTheParallelStages|ParallelLiveInput|ACorrectionFromAnotherThread|AFailedLoopTask|AKeyFrameWaitingForItsMapping|CallbacksMayBeReplaced)|LoopClosing\\.(ACorrectionWhileTracking|AGlobalBundleWriteBackWaits|AGlobalBundleAnOutsideCorrectionMadeStaleRunsAgainInParallel)")
elif [ "$mode" = sanitize ]; then
  BUILD="$ROOT/build-sanitize"
  # The generated test sequences of the normal build are reused (byte-identical).
  # -O0: the suite is short now; cold, -O1 took 1054 s to build and 375 s to test, -O0 670 s and 513 s.
  YESSLAM_TARGETS="yesslam_tests" ./scripts/build.sh "$BUILD" -DCMAKE_BUILD_TYPE=RelWithDebInfo "-DCMAKE_CXX_FLAGS_RELWITHDEBINFO=-O0 -g1" -DYESSLAM_SANITIZE=ON -DYESSLAM_BUILD_TESTS=ON -DYESSLAM_BUILD_BENCH=OFF \
    -DYESSLAM_TEST_CACHE_DIR="$ROOT/build/tests/cache"
  # allocator_may_return_null: a corrupt file asking for terabytes must get std::bad_alloc (and our
  # clear error), as in a normal build, not an ASan abort.
  export ASAN_OPTIONS="halt_on_error=1:detect_leaks=1:abort_on_error=0:allocator_may_return_null=1"
  export UBSAN_OPTIONS="halt_on_error=1:print_stacktrace=1:suppressions=$ROOT/tests/sanitizer/ubsan.supp"
  # Leaks inside Mesa's OpenGL driver and OpenNI2's drivers only (tests/sanitizer/lsan.supp says
  # which and why); print_suppressions=0: the table of suppressed leaks would add lines to the
  # one-line errors the tool tests check.
  export LSAN_OPTIONS="suppressions=$ROOT/tests/sanitizer/lsan.supp:print_suppressions=0"
  # The stages' unit tests, the fuzz corpora, the bad-input tests of every tool, the parallel
  # stages' lifetimes and failure reporting, and a keyframe culled under the loop stage. Not the
  # whole-sequence runs (tools, system, loop closing, relocalisation, map reuse, dense map, the
  # simulator's presets, the live app, the interrupts, the soak, the 2D grid's runs): each costs minutes under ASan and runs the
  # SLAM code the tests here run; TSan runs the threaded ones; the install tests check packaging.
  FILTER=(-E "^(Tools|LiveApp|Interrupt|Soak|Simulator|MapReuse|LoopClosing|Relocalisation|DenseMap|Install|System)\\.|^Grid2D\\.(OnRealFrames|YesslamMap)")
  AGAIN=(-R "^Tools\\.[A-Za-z0-9]*BadInput|^Tools\\.SlamAppOnRealFramesAndItsErrors|^MapReuse\\.DamagedForeign|^Simulator\\.BadOptions|^System\\.(ParallelMappingMapsEveryKeyFrame|AKeyFrameWaitingForItsMapping|AFailedLoopTask|AFailedStageSettles|AMappingFailureStillCommits|TheRecentFramesImagesAreLetGo|CallbacksMayBeReplaced)|^LoopClosing\\.(AKeyFrameCulledBetween|AGlobalBundleWriteBackWaits)")
else
  BUILD="$ROOT/build"
  # What ctest runs (tests/CMakeLists.txt's yesslam_tests), not bench/: ./scripts/build.sh builds all.
  YESSLAM_TARGETS="yesslam_tests" ./scripts/build.sh "$BUILD" -DYESSLAM_BUILD_TESTS=ON
fi
built=$(date +%s)
cd "$BUILD"
ctest --output-on-failure -j "$(nproc)" "${FILTER[@]}"
if [ ${#AGAIN[@]} -gt 0 ]; then ctest --output-on-failure -j "$(nproc)" "${AGAIN[@]}"; fi
echo "test.sh ($mode): build $((built - start)) s, tests $(( $(date +%s) - built )) s"
