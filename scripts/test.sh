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
# Sanitizer builds: -O1 and line tables only (-g1), the sanitizers' recommended setting, which
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
  FILTER=(-R "WorkerPool|WriterFirstMutex|PngWriter|Prefetch|LiveSource|FrameBuilder|System\\.(Parallel|SequentialAndParallel|ACorrectionFromAnotherThread|AFailedLoopTask|AKeyFrameWaitingForItsMapping|CallbacksMayBeReplaced)|LoopClosing\\.(ACorrectionWhileTracking|AKeyFrameCulledBetween|AGlobalBundleWriteBackWaits|AGlobalBundleAnOutsideCorrectionMadeStaleRunsAgainInParallel)")
elif [ "$mode" = sanitize ]; then
  BUILD="$ROOT/build-sanitize"
  # The generated test sequences of the normal build are reused (byte-identical; the simulator's
  # own tests still generate theirs under ASan).
  ./scripts/build.sh "$BUILD" "${SANFLAGS[@]}" -DYESSLAM_SANITIZE=ON -DYESSLAM_BUILD_TESTS=ON -DYESSLAM_BUILD_BENCH=OFF \
    -DYESSLAM_TEST_CACHE_DIR="$ROOT/build/tests/cache"
  # allocator_may_return_null: a corrupt file asking for terabytes must get std::bad_alloc (and our
  # clear error), as in a normal build, not an ASan abort.
  export ASAN_OPTIONS="halt_on_error=1:detect_leaks=1:abort_on_error=0:allocator_may_return_null=1"
  export UBSAN_OPTIONS="halt_on_error=1:print_stacktrace=1:suppressions=$ROOT/tests/sanitizer/ubsan.supp"
  # Leaks inside Mesa's OpenGL driver and OpenNI2's drivers only (tests/sanitizer/lsan.supp says
  # which and why); print_suppressions=0: the table of suppressed leaks would add lines to the
  # one-line errors the tool tests check.
  export LSAN_OPTIONS="suppressions=$ROOT/tests/sanitizer/lsan.supp:print_suppressions=0"
  # The whole-sequence loop-closing and relocalisation runs (the revisit, the 330 frames
  # without one and the 196 with a relocalisation within a frame: 150 s and more under ASan) go through the same code as the parallel loop-closing test,
  # which stays; the whole-sequence dense-map runs (3.6 min under ASan)
  # through the same code as the dense unit tests and every system test, which stay:
  # under ASan each whole-sequence run costs minutes of the CI budget.
  # The map-reuse pass test (five whole runs, 98 s under ASan) goes through the same SLAM code; its
  # map files are read under ASan by the damaged-files test and the fuzz corpus, which stay.
  # The real-frame octree queries (two whole runs with every pixel sampled) and the 80 real Bonn
  # frames of the keyframe-marks test go through the dense and system code the other tests run.
  # The rolling-shutter and depth-moment system tests (300 s of ASan time together: they render
  # their sequences under ASan) and three more whole-sequence comparisons (keyframe policies, the
  # mover check on a static scene, the undetected walker: 180 s) run the SLAM code every other
  # system test runs; the shutter and depth-moment code itself is in feature/'s unit tests, which stay.
  # Four of the threaded tests the TSan suite runs (parallel against sequential mapping, parallel
  # accuracy, the correction from another thread: 72 s under ASan; the stale global BA run again in
  # parallel, whose sequential twin stays) go through the SLAM code other
  # tests run here; the parallel stages' lifetimes, failure reporting and the loop stage racing
  # tracking stay under ASan (System.ParallelMappingMapsEveryKeyFrame..., LoopClosing.ACorrectionWhileTracking...). So do the determinism check (two identical sequential runs) and the two
  # simulator-preset statistics (whole generated sequences measured; the simulator's code is in the
  # other simulator tests, which stay). The install tests (cmake --install, the example built against it, cpack) check
  # the packaging of the normal build, not memory. The recordings' camera files (five tool runs) go
  # through the camera-file code io/'s unit tests run (Camera.ARecordingsCameraFileReadsBack); the
  # jerked camera (a whole 60-frame run) through the SLAM code every system test runs.
  FILTER=(-E "Tools\\.ARecordingKeeps|System\\.ACameraJerked|LoopClosing\\.(ARevisit|NoLoopIsAccepted|AGlobalBundleAnOutsideCorrectionMadeStaleRunsAgainInParallel)|Relocalisation\\.(AKidnapped|ARelocalisationIsNoStep)|DenseMap\\.(PeopleLeave|NoSurface)|MapReuse\\.ASecondPass|Tools\\.EveryKeyFrame|Simulator\\.(TheCrowdPresetLooksLike|WalkingPresetIsAsDynamic)|System\\.(SequentialModeIsDeterministic|ARollingShutter|DepthTakenAtAnotherMoment|KeyFramePoliciesBothWork|AStaticSequenceIsNotMadeWorse|AnUndetectedWalker|ParallelMappingIsAsAccurate|SequentialAndParallel|ACorrectionFromAnotherThread)|Install\\.")
else
  BUILD="$ROOT/build"
  ./scripts/build.sh "$BUILD" -DYESSLAM_BUILD_TESTS=ON
fi
built=$(date +%s)
cd "$BUILD"
ctest --output-on-failure -j "$(nproc)" "${FILTER[@]}"
echo "test.sh ($mode): build $((built - start)) s, tests $(( $(date +%s) - built )) s"
