#!/usr/bin/env bash
# Sanitizer builds and fuzzing (see RELIABILITY.md), with plain CMake (test/sanitizers), beside
# the catkin workspace in $WORKSPACE/sanitizers:
#   address  g++, AddressSanitizer + UndefinedBehaviorSanitizer (no recovery): the core gtests,
#            the ROS conversion gtests, the concurrency and SIGKILL-during-save tests, and the
#            fuzz corpora and regressions replayed through the fuzz targets' entry points;
#   thread   g++, ThreadSanitizer: the concurrency tests;
#   fuzz     clang++-14, libFuzzer + ASan + UBSan: each target for MVOG_FUZZ_SECONDS (25) seconds,
#            seeded with test/fuzz/corpus/<target> and test/fuzz/regressions/<target>. A crash is
#            written to $WORKSPACE/logs/fuzz/: copy it into test/fuzz/regressions/<target>/.
# Called by scripts/test.sh; runs alone too. The last line is
#   sanitizers: N passed, N failed, N skipped
# (one check per test program or fuzz run); exits non-zero if any failed.
source "$(dirname "${BASH_SOURCE[0]}")/common.sh"

install_missing_packages
FUZZ_SECONDS=${MVOG_FUZZ_SECONDS:-25}
BUILD_ROOT=$WORKSPACE/sanitizers
FUZZ_LOGS=$LOG_DIR/fuzz
mkdir -p "$BUILD_ROOT" "$FUZZ_LOGS"
export ASAN_OPTIONS=${ASAN_OPTIONS:-detect_leaks=1:abort_on_error=0}
export UBSAN_OPTIONS=${UBSAN_OPTIONS:-print_stacktrace=1:halt_on_error=1}
export TSAN_OPTIONS=${TSAN_OPTIONS:-halt_on_error=1:second_deadlock_stack=1}

passed=0
failed=0
failures=()

fail() {
  failed=$((failed + 1))
  failures+=("$1")
}

# build MODE COMPILER TARGET...: configures and builds $BUILD_ROOT/MODE; false on failure.
build() {
  local mode=$1 compiler=$2
  shift 2
  quietly "sanitizer-$mode-configure" env CXX="$compiler" cmake -S "$REPO/test/sanitizers" \
    -B "$BUILD_ROOT/$mode" -DMVOG_SANITIZER="$mode" -DCMAKE_BUILD_TYPE=RelWithDebInfo \
    -DCMAKE_CXX_FLAGS_RELWITHDEBINFO=-O1 &&
    quietly "sanitizer-$mode-build" cmake --build "$BUILD_ROOT/$mode" -j2 --target "$@"
}

# check NAME COMMAND...: runs one test program, its output in $LOG_DIR/NAME.log.
check() {
  local name=$1
  shift
  if "$@" >"$LOG_DIR/$name.log" 2>&1; then
    passed=$((passed + 1))
  else
    fail "$name: see $LOG_DIR/$name.log"
  fi
}

asan_checks=(asan-core-gtests asan-conversions-gtests asan-concurrency asan-save-sigkill
             asan-replay-map_file asan-replay-conversions)
if build address g++ test_mvog_core test_conversions test_concurrency test_save_sigkill \
  fuzz_replay_map_file fuzz_replay_conversions; then
  dir=$BUILD_ROOT/address
  check asan-core-gtests "$dir/mvog/test_mvog_core"
  check asan-conversions-gtests "$dir/test_conversions"
  check asan-concurrency "$dir/test_concurrency"
  check asan-save-sigkill "$dir/test_save_sigkill"
  for target in map_file conversions; do
    check "asan-replay-$target" "$dir/fuzz_replay_$target" "$REPO/test/fuzz/corpus/$target" \
      "$REPO/test/fuzz/regressions/$target"
  done
else
  for name in "${asan_checks[@]}"; do fail "$name: the address build failed"; done
fi

if build thread g++ test_concurrency; then
  check tsan-concurrency "$BUILD_ROOT/thread/test_concurrency"
else
  fail "tsan-concurrency: the thread build failed"
fi

if build fuzz clang++-14 fuzz_map_file fuzz_conversions; then
  for target in map_file conversions; do
    # New inputs go to the first directory (kept between local runs); the others only seed.
    mkdir -p "$BUILD_ROOT/fuzz/corpus/$target"
    seeds=("$REPO/test/fuzz/corpus/$target")
    [ -d "$REPO/test/fuzz/regressions/$target" ] && seeds+=("$REPO/test/fuzz/regressions/$target")
    check "fuzz-$target" "$BUILD_ROOT/fuzz/fuzz_$target" -max_total_time="$FUZZ_SECONDS" \
      -rss_limit_mb=2048 -timeout=10 -print_final_stats=1 \
      -artifact_prefix="$FUZZ_LOGS/$target-" "$BUILD_ROOT/fuzz/corpus/$target" "${seeds[@]}"
  done
else
  fail "fuzz-map_file: the fuzz build failed"
  fail "fuzz-conversions: the fuzz build failed"
fi

for failure in "${failures[@]}"; do echo "FAILED: $failure"; done
echo "sanitizers: $passed passed, $failed failed, 0 skipped"
[ "$failed" -eq 0 ]
