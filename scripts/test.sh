#!/usr/bin/env bash
# Installs what is missing, builds (Release) and runs every test: a formatting check, the core
# built alone with plain CMake (no ROS), then the catkin package's gtests and rostests, the linters
# (catkin_lint, shellcheck, clang-tidy: scripts/lint.sh), then the sanitizer builds and fuzzing
# (scripts/sanitizers.sh). Prints one summary line and exits
# non-zero on any failure. Tests that replay ../shared/data skip without it, but not when CI=true.
# The Python module's tests (test/python, pytest) run after the catkin tests and count alike.
# shellcheck source=scripts/common.sh
source "$(dirname "${BASH_SOURCE[0]}")/common.sh"

install_missing_packages

# stage NAME: ends the stage running since the last call (or the installation), its time in
# `stage_times` (printed before the summary).
stage_times=()
stage_started=$SECONDS
stage() {
  stage_times+=("$1 $((SECONDS - stage_started)) s")
  stage_started=$SECONDS
}

passed=0
failed=0
skipped=0
failures=()

# The catkin tests and the sanitizer stage (some 5 and 11-15 minutes on a 2-core machine) run
# under `timeout` with three to five times that: a test that hangs fails its stage, saying so,
# well before CI's own limit of 90 minutes would stop the whole run.
catkin_tests_limit=1500
sanitizers_limit=2700
# timed_out STATUS: whether STATUS is that of a command `timeout --kill-after` stopped.
timed_out() { [ "$1" -eq 124 ] || [ "$1" -eq 137 ]; }

# 0. Every C++ file is formatted with the repository's .clang-format.
unformatted=()
while IFS= read -r -d '' file; do
  clang-format-14 --dry-run --Werror "$REPO/$file" >/dev/null 2>&1 || unformatted+=("$file")
done < <(cd "$REPO" && find include src test -name '*.cpp' -print0 -o -name '*.h' -print0)
if [ ${#unformatted[@]} -eq 0 ]; then passed=$((passed + 1)); else
  failed=$((failed + 1))
  failures+=("clang-format (run clang-format-14 -i on): ${unformatted[*]}")
fi

# 1. The core with plain CMake, without catkin or ROS: it builds (the library and its ROS-free
# tools), and no core source or header reaches a ROS, PCL, tf2 or Boost header. Its gtests run in
# the catkin build below (the same programs, flags and Release type) and under ASan + UBSan.
core_build=$WORKSPACE/core_build
quietly core-configure cmake -S "$REPO" -B "$core_build" -DMVOG_BUILD_ROS=OFF \
  -DCMAKE_BUILD_TYPE=Release -DBUILD_TESTING=OFF
if quietly core-build cmake --build "$core_build" -j2 &&
  quietly core-includes "$REPO/test/check_core_includes.sh" c++ "$REPO"; then
  passed=$((passed + 1))
else
  failed=$((failed + 1))
  failures+=("core (plain CMake): see $LOG_DIR/core-build.log and $LOG_DIR/core-includes.log")
fi
stage "format and core"

# 2. The catkin package: gtests and rostests.
build_workspace
source_workspace
stage "catkin build"

rm -rf "$WORKSPACE/build/test_results"
run_tests_status=0
quietly run-tests timeout --kill-after=30 "$catkin_tests_limit" \
  bash -c "cd '$WORKSPACE' && catkin_make run_tests -j2" || run_tests_status=$?
if timed_out "$run_tests_status"; then
  failed=$((failed + 1))
  failures+=("catkin tests: stopped after $catkin_tests_limit s (log: $LOG_DIR/run-tests.log)")
fi
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
stage "catkin tests"

# 2b. The Python module's tests (test/python, pytest), from the workspace sourced above, where
# `import mvog` finds the built module: counted from pytest's JUnit XML (its tests, failures,
# errors and skips). Their recording skips without ../shared/data, but not when CI=true.
pytest_xml=$LOG_DIR/pytest.xml
rm -f "$pytest_xml"
quietly pytest bash -c "cd '$WORKSPACE' && python3 -m pytest -p no:cacheprovider \
  --junitxml='$pytest_xml' '$REPO/test/python'" || true
read -r py_tests py_failed py_skipped < <(python3 - "$pytest_xml" <<'PY' || echo "0 0 0"
import sys
import xml.etree.ElementTree as ET
suites = ET.parse(sys.argv[1]).getroot()
suites = [suites] if suites.tag == "testsuite" else list(suites)
count = lambda name: sum(int(suite.get(name, 0)) for suite in suites)
print(count("tests"), count("failures") + count("errors"), count("skipped"))
PY
)
passed=$((passed + py_tests - py_failed - py_skipped))
# No test run at all (no XML: pytest missing, the module not built) fails the stage.
if [ "$py_tests" -eq 0 ]; then py_failed=1; fi
failed=$((failed + py_failed))
skipped=$((skipped + py_skipped))
if [ "$py_failed" -gt 0 ]; then
  failures+=("python tests: $(grep -E '^(FAILED|ERROR)' "$LOG_DIR/pytest.log" | head -10) (log: $LOG_DIR/pytest.log)")
fi
stage "python tests"

# count_script NAME: adds the counts of scripts/NAME.sh from its log, whose last line is
# "NAME: N passed, N failed, N skipped" (one failure if it printed none).
count_script() {
  local name=$1 log=$LOG_DIR/$1.log counts script_passed script_failed script_skipped
  counts=$(sed -nE "s/^$name: ([0-9]+) passed, ([0-9]+) failed, ([0-9]+) skipped\$/\\1 \\2 \\3/p" "$log")
  read -r script_passed script_failed script_skipped <<<"${counts:-0 1 0}"
  passed=$((passed + script_passed))
  failed=$((failed + script_failed))
  skipped=$((skipped + script_skipped))
  if [ "$script_failed" -gt 0 ]; then
    failures+=("$name: $(grep -E '^FAILED' "$log" | head -10) (log: $log)")
  fi
}

# 3. The linters (catkin_lint, shellcheck, clang-tidy: scripts/lint.sh). Not beside the catkin tests: at normal priority, the tests' replays at 50x lost
# scans; at idle priority (chrt --idle), the tests slowed by as much as the linters gained (629 s
# for both side by side with 4edce5d's test.sh, 607 s one after the other, on a 2-core machine).
bash "$REPO/scripts/lint.sh" >"$LOG_DIR/lint.log" 2>&1 || true
count_script lint
stage linters

# 4. Sanitizer builds and fuzzing: ASan + UBSan, TSan, libFuzzer.
sanitizers_status=0
timeout --kill-after=30 "$sanitizers_limit" bash "$REPO/scripts/sanitizers.sh" \
  >"$LOG_DIR/sanitizers.log" 2>&1 || sanitizers_status=$?
if timed_out "$sanitizers_status"; then  # counted by count_script: no summary line
  echo "FAILED: stopped after $sanitizers_limit s" >>"$LOG_DIR/sanitizers.log"
fi
count_script sanitizers
stage sanitizers

for failure in "${failures[@]}"; do echo "FAILED: $failure"; done
joined_times=$(printf '%s, ' "${stage_times[@]}")
echo "times: ${joined_times%, }; in all $SECONDS s"
echo "tests: $passed passed, $failed failed, $skipped skipped"
[ "$failed" -eq 0 ] && [ ${#failures[@]} -eq 0 ]
