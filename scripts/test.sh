#!/usr/bin/env bash
# Installs what is missing, builds (Release) and runs every test: a formatting check, the core
# alone with plain CMake (no ROS), then the catkin package's gtests and rostests, the linters
# (catkin_lint, shellcheck, clang-tidy: scripts/lint.sh), then the sanitizer builds and fuzzing
# (scripts/sanitizers.sh). Prints one summary line and exits
# non-zero on any failure. Tests that replay ../shared/data skip without it, but not when CI=true.
# shellcheck source=scripts/common.sh
source "$(dirname "${BASH_SOURCE[0]}")/common.sh"

install_missing_packages

passed=0
failed=0
skipped=0
failures=()

# 0. Every C++ file is formatted with the repository's .clang-format.
unformatted=()
while IFS= read -r -d '' file; do
  clang-format-14 --dry-run --Werror "$REPO/$file" >/dev/null 2>&1 || unformatted+=("$file")
done < <(cd "$REPO" && find include src test -name '*.cpp' -print0 -o -name '*.h' -print0)
if [ ${#unformatted[@]} -eq 0 ]; then passed=$((passed + 1)); else
  failed=$((failed + 1))
  failures+=("clang-format (run clang-format-14 -i on): ${unformatted[*]}")
fi

# 1. The core with plain CMake: proves it builds and passes without catkin.
core_build=$WORKSPACE/core_build
quietly core-configure cmake -S "$REPO" -B "$core_build" -DMVOG_BUILD_ROS=OFF \
  -DCMAKE_BUILD_TYPE=Release
quietly core-build cmake --build "$core_build" -j2
if (cd "$core_build" && ctest --output-on-failure >"$LOG_DIR/core-ctest.log" 2>&1); then :; else
  failures+=("core (plain CMake): see $LOG_DIR/core-ctest.log")
fi
core_counts=$(grep -E 'tests passed, [0-9]+ tests failed' "$LOG_DIR/core-ctest.log" || true)
core_total=$(sed -E 's/.* out of ([0-9]+).*/\1/' <<<"$core_counts")
core_failed=$(sed -E 's/.*passed, ([0-9]+) tests failed.*/\1/' <<<"$core_counts")
passed=$((passed + ${core_total:-0} - ${core_failed:-0}))
failed=$((failed + ${core_failed:-1}))

# 2. The catkin package: gtests and rostests.
build_workspace
source_workspace
rm -rf "$WORKSPACE/build/test_results"
quietly run-tests bash -c "cd '$WORKSPACE' && catkin_make run_tests -j2" || true
results=$(catkin_test_results --all "$WORKSPACE/build/test_results" 2>&1 || true)
echo "$results" >"$LOG_DIR/catkin-test-results.log"
summary=$(grep -E '^Summary:' <<<"$results" || echo "Summary: 0 tests, 1 errors, 0 failures, 0 skipped")
read -r tests errors test_failures test_skipped < <(sed -E \
  's/Summary: ([0-9]+) tests, ([0-9]+) errors, ([0-9]+) failures, ([0-9]+) skipped.*/\1 \2 \3 \4/' \
  <<<"$summary")
passed=$((passed + tests - errors - test_failures - test_skipped))
failed=$((failed + errors + test_failures))
skipped=$((skipped + test_skipped))
if [ $((errors + test_failures)) -gt 0 ] || [ "$tests" -eq 0 ]; then
  failures+=("catkin tests: $(grep -vE '^Summary:' <<<"$results" | grep -E 'errors|failures|Error' | head -20)")
fi

# run_counted NAME: runs scripts/NAME.sh, whose last line is "NAME: N passed, N failed, N skipped",
# and adds its counts (one failure if it printed none).
run_counted() {
  local name=$1 log=$LOG_DIR/$1.log counts script_passed script_failed script_skipped
  bash "$REPO/scripts/$name.sh" >"$log" 2>&1 || true
  counts=$(sed -nE "s/^$name: ([0-9]+) passed, ([0-9]+) failed, ([0-9]+) skipped\$/\\1 \\2 \\3/p" "$log")
  read -r script_passed script_failed script_skipped <<<"${counts:-0 1 0}"
  passed=$((passed + script_passed))
  failed=$((failed + script_failed))
  skipped=$((skipped + script_skipped))
  if [ "$script_failed" -gt 0 ]; then
    failures+=("$name: $(grep -E '^FAILED' "$log" | head -10) (log: $log)")
  fi
}

# 3. The linters, on the compile commands of the build above: catkin_lint, shellcheck, clang-tidy.
run_counted lint

# 4. Sanitizer builds and fuzzing: ASan + UBSan, TSan, libFuzzer.
run_counted sanitizers

for failure in "${failures[@]}"; do echo "FAILED: $failure"; done
echo "tests: $passed passed, $failed failed, $skipped skipped"
[ "$failed" -eq 0 ] && [ ${#failures[@]} -eq 0 ]
