#!/usr/bin/env bash
# Sanitizer builds and fuzzing (see RELIABILITY.md) in $WORKSPACE/sanitizers: an instrumented
# catkin workspace and plain CMake builds (test/sanitizers), of the programs of test/tests.cmake:
#   catkin   g++ -O1, AddressSanitizer + UndefinedBehaviorSanitizer (float-cast-overflow too, no
#            recovery, leaks checked): the core gtests, the ROS conversion and ROS gtests, the
#            concurrency and SIGKILL-during-save tests, the fuzz corpora and regressions replayed
#            through the fuzz targets' entry points, and the rostests of mvog_node (bad input,
#            time jumps, SIGKILL during saves, overload, the whole ROS interface);
#   thread   g++, ThreadSanitizer: the concurrency tests;
#   fuzz     clang++-14, libFuzzer + ASan + UBSan: each target (map_file, map_update,
#            conversions) for MVOG_FUZZ_SECONDS (25) seconds,
#            seeded with test/fuzz/corpus/<target> and test/fuzz/regressions/<target>. A crash is
#            written to $WORKSPACE/logs/fuzz/: copy it into test/fuzz/regressions/<target>/.
# Called by scripts/test.sh; runs alone too. The last line is
#   sanitizers: N passed, N failed, N skipped
# (one check per test program or fuzz run); exits non-zero if any failed.
# shellcheck source=scripts/common.sh
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

# Every build here is CMake's unity build, each target's sources compiled as one file: the ROS and
# gtest headers parsed once a target instead of once a source (and the rule of CMakeLists.txt
# checked, that no two sources of a target define one name in an anonymous namespace).
unity_build_flags=(-DCMAKE_UNITY_BUILD=ON -DCMAKE_UNITY_BUILD_BATCH_SIZE=0)
# Every build here uses Ninja: given several targets, CMake's Makefiles build them one after the
# other (their top-level Makefile is .NOTPARALLEL), a single-file program on one core of two;
# Ninja builds them side by side.
# ninja_tree DIR: DIR ready for a Ninja build: a tree another generator configured (an older
# run's) is removed, as CMake refuses to change a tree's generator.
ninja_tree() {
  if [ -f "$1/CMakeCache.txt" ] && ! grep -q '^CMAKE_GENERATOR:INTERNAL=Ninja$' "$1/CMakeCache.txt"
  then
    rm -rf "$1"
  fi
}

# build MODE COMPILER TARGET...: configures and builds $BUILD_ROOT/MODE; false on failure.
build() {
  local mode=$1 compiler=$2
  shift 2
  ninja_tree "$BUILD_ROOT/$mode"
  quietly "sanitizer-$mode-configure" env CXX="$compiler" cmake -G Ninja \
    -S "$REPO/test/sanitizers" -B "$BUILD_ROOT/$mode" -DMVOG_SANITIZER="$mode" \
    -DCMAKE_BUILD_TYPE=RelWithDebInfo -DCMAKE_CXX_FLAGS_RELWITHDEBINFO=-O1 \
    "${unity_build_flags[@]}" &&
    quietly "sanitizer-$mode-build" cmake --build "$BUILD_ROOT/$mode" -j2 --target "$@"
}

# check NAME COMMAND...: runs one test program in the background, its output in
# $LOG_DIR/NAME.log: two at a time, as most of them (and each fuzzer) use one core and the machine
# has two. finish_checks waits for them and counts them (after a check: it ran alone).
pending_checks=()
check() {
  local name=$1
  shift
  while [ "$(jobs -rp | wc -l)" -ge 2 ]; do wait -n || true; done
  rm -f "$LOG_DIR/$name.passed"
  ("$@" >"$LOG_DIR/$name.log" 2>&1 && touch "$LOG_DIR/$name.passed") &
  pending_checks+=("$name")
}
finish_checks() {
  wait
  local name
  for name in "${pending_checks[@]}"; do
    if [ -f "$LOG_DIR/$name.passed" ]; then
      passed=$((passed + 1))
    else
      fail "$name: see $LOG_DIR/$name.log"
    fi
  done
  pending_checks=()
}

fuzz_targets=(map_file map_update conversions)

# One instrumented catkin workspace for every ASan + UBSan check (each program is built once):
# the core's and the ROS layer's gtests, the fuzz replays, and the rostests of mvog_node (not
# those of the nodelet: an instrumented plugin cannot be loaded into Debian's uninstrumented
# nodelet manager; not the replays of ../shared/data: minutes each). -O1 as ASan's authors
# advise: less compile time than -O2 for the same checks; -g1: the line tables a report's stack
# trace needs (file:line), without -g's variable descriptions (less to compile and link); a unity
# build, as every build of this script (unity_build_flags). A sanitizer report by any process
# fails the check and is appended to its log.
asan_workspace=$BUILD_ROOT/catkin
sanitize="-fsanitize=address,undefined,float-cast-overflow -fno-sanitize-recover=all"
# in_asan_workspace NAME COMMAND...: runs COMMAND with the instrumented workspace sourced, its
# sanitizer reports in $LOG_DIR/asan-reports/NAME.
in_asan_workspace() {
  local reports=$LOG_DIR/asan-reports/$1
  shift
  rm -rf "$reports"
  mkdir -p "$reports"
  if (
    set +u
    # shellcheck disable=SC1091
    source "$asan_workspace/devel/setup.bash"
    set -u
    export ASAN_OPTIONS=detect_leaks=1:log_path=$reports/asan
    export UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1:log_path=$reports/ubsan
    export ROS_TEST_RESULTS_DIR=$asan_workspace/test_results
    "$@"
  ) && [ -z "$(ls -A "$reports")" ]; then
    return 0
  fi
  cat "$reports"/* 2>/dev/null || true
  return 1
}
asan_programs=(test_mvog_core test_mvog_ros_conversions test_concurrency test_save_sigkill
               test_mvog_ros)
asan_ros_tests=(mapper_node decay bad_input time_jump kill_during_save overload planning)
mkdir -p "$asan_workspace/src"
# shellcheck disable=SC2031 # in_asan_workspace's subshell sources setup.bash, unseen: not REPO
ln -sfn "$REPO" "$asan_workspace/src/mvog"
# The three builds first, each with both cores; then every check that times nothing (the
# gtests, the corpus replays, TSan, the fuzzers) two at a time, test_mvog_core (the longest)
# first, so that no core waits for the last of a batch; then the ASan rostests, alone.
asan_built=false
ninja_tree "$asan_workspace/build"
if (cd "$asan_workspace" && quietly sanitizer-catkin-build catkin_make --use-ninja \
  -DCMAKE_BUILD_TYPE=RelWithDebInfo -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O1 -g1" \
  -DCMAKE_CXX_FLAGS="$sanitize -fno-omit-frame-pointer" -DCMAKE_EXE_LINKER_FLAGS="$sanitize" \
  -DCMAKE_SHARED_LINKER_FLAGS="$sanitize" -DCATKIN_ENABLE_TESTING=ON -DMVOG_FUZZ_TARGETS=replay \
  "${unity_build_flags[@]}" \
  -j2 mvog_node test_mapper_node test_planning_node mvog_generate_messages "${asan_programs[@]}" \
  "${fuzz_targets[@]/#/fuzz_replay_}"); then
  asan_built=true
else
  for name in "${asan_programs[@]#test_}" "${fuzz_targets[@]/#/replay-}" \
    "${asan_ros_tests[@]/#/rostest-}"; do
    fail "asan-$name: the instrumented catkin build failed"
  done
fi
thread_built=false
if build thread g++ test_concurrency; then
  thread_built=true
else
  fail "tsan-concurrency: the thread build failed"
fi
fuzz_built=false
if build fuzz clang++-14 "${fuzz_targets[@]/#/fuzz_}"; then
  fuzz_built=true
else
  for target in "${fuzz_targets[@]}"; do fail "fuzz-$target: the fuzz build failed"; done
fi

if $asan_built; then
  dir=$asan_workspace/devel/lib/mvog
  for program in "${asan_programs[@]}"; do
    check "asan-${program#test_}" in_asan_workspace "${program#test_}" "$dir/$program"
  done
  for target in "${fuzz_targets[@]}"; do
    # shellcheck disable=SC2031 # as above
    check "asan-replay-$target" in_asan_workspace "replay-$target" "$dir/fuzz_replay_$target" \
      "$REPO/test/fuzz/corpus/$target" "$REPO/test/fuzz/regressions/$target"
  done
fi
if $thread_built; then
  check tsan-concurrency "$BUILD_ROOT/thread/mvog/test_concurrency"
fi
# shellcheck disable=SC2031 # as above
if $fuzz_built; then
  for target in "${fuzz_targets[@]}"; do
    # New inputs go to the first directory (kept between local runs); the others only seed.
    mkdir -p "$BUILD_ROOT/fuzz/corpus/$target"
    seeds=("$REPO/test/fuzz/corpus/$target")
    [ -d "$REPO/test/fuzz/regressions/$target" ] && seeds+=("$REPO/test/fuzz/regressions/$target")
    check "fuzz-$target" "$BUILD_ROOT/fuzz/mvog/fuzz_$target" -max_total_time="$FUZZ_SECONDS" \
      -rss_limit_mb=2048 -timeout=10 -print_final_stats=1 \
      -artifact_prefix="$FUZZ_LOGS/$target-" "$BUILD_ROOT/fuzz/corpus/$target" "${seeds[@]}"
  done
fi
finish_checks

# The rostests one at a time: their servers answer within deadlines, and under ASan beside
# another test the planning test's tf lookups missed them.
if $asan_built; then
  for test in "${asan_ros_tests[@]}"; do
    check "asan-rostest-$test" in_asan_workspace "rostest-$test" rostest mvog "$test.test"
    finish_checks
  done
fi

for failure in "${failures[@]}"; do echo "FAILED: $failure"; done
echo "sanitizers: $passed passed, $failed failed, 0 skipped"
[ "$failed" -eq 0 ]
