#!/usr/bin/env bash
# The linters of the ROS and C++ ecosystems, each one check (Debian's packages, installed by
# common.sh like the rest):
#   catkin_lint   the package (package.xml, CMakeLists.txt, test/tests.cmake) at its default level,
#                 --strict: a warning fails like an error. Each suppression is a
#                 `#catkin_lint: ignore` pragma beside the code, with its reason.
#   ShellCheck    every shell script (scripts/, .ci/, test/), following what they source.
#   changelog     CHANGELOG.rst parses as catkin's release tools read it and its newest entry is
#                 package.xml's version (a version bump without its entry fails).
#   clang-tidy    clang-tidy-14 on every source of src/ with the checks of .clang-tidy, through the
#                 compile commands of the catkin workspace (scripts/test.sh builds it first; run
#                 alone, this builds it too).
# Prints each linter's findings; the last line is
#   lint: N passed, N failed, N skipped
# and it exits non-zero if any linter found something.
# shellcheck source=scripts/common.sh
source "$(dirname "${BASH_SOURCE[0]}")/common.sh"

install_missing_packages
[ -f "$WORKSPACE/build/compile_commands.json" ] || build_workspace

passed=0
failed=0
# lint NAME COMMAND...: one linter; its output in $LOG_DIR/lint-NAME.log, printed when it fails.
lint() {
  local name=$1
  shift
  mkdir -p "$LOG_DIR"
  if "$@" >"$LOG_DIR/lint-$name.log" 2>&1; then
    passed=$((passed + 1))
  else
    failed=$((failed + 1))
    echo "FAILED: $name ($LOG_DIR/lint-$name.log):"
    cat "$LOG_DIR/lint-$name.log"
  fi
}

# Without a rosdep database (none offline) it cannot tell system packages apart and says so on
# stderr; the package's own checks do not need one.
lint catkin_lint catkin_lint --strict --offline "$REPO"

# From the repository's root, where the scripts' `# shellcheck source=scripts/common.sh` points.
shellcheck_scripts() (
  cd "$REPO" && find scripts .ci test -type f \( -name '*.sh' -o -path .ci/run \) -print0 |
    sort -z | xargs -0 shellcheck -x
)
lint shellcheck shellcheck_scripts

changelog_matches_version() {
  python3 - "$REPO" <<'PY'
import os
import sys
from catkin_pkg.changelog import get_changelog_from_path
from catkin_pkg.package import parse_package

repo = sys.argv[1]
version = parse_package(repo).version
entries = [str(v) for v, _, _ in get_changelog_from_path(
    os.path.join(repo, "CHANGELOG.rst")).foreach_version()]
if not entries or entries[0] != version:
    sys.exit(f"CHANGELOG.rst's newest entry is {entries[0] if entries else 'missing'}, "
             f"package.xml says {version}: add its entry")
PY
}
lint changelog changelog_matches_version

# The sources are compiled through the workspace's link to the repository: the header filter
# keeps the findings to our own headers (not the generated message headers in devel/); the
# .clang-tidy found beside the sources through that link sets the checks. The file regex keeps
# to our sources: Bonxai's, which mvog_bench compiles from MVOG_PEERS_DIR (../shared/peers), have
# compile commands too, outside the repository, and are not linted.
clang_tidy() {
  local findings
  findings=$(run-clang-tidy-14 -quiet -j 2 -p "$WORKSPACE/build" \
    -header-filter="^$WORKSPACE/src/mvog/(include|src)/" "^$WORKSPACE/src/mvog/src/" 2>&1 |
    sed -E 's/\x1b\[[0-9;]*m//g' |
    grep -vE '^(clang-tidy-14 |[0-9]+ warnings? (generated|treated as errors)|Suppressed [0-9]+ warnings|Use -header-filter|Running clang-tidy|Enabled checks)' ||
    true)
  echo "$findings"
  # run-clang-tidy colours its output (always, in version 14: the escapes are dropped) and its
  # status says only that some file had findings: they decide, with their names.
  ! grep -qE '(warning|error): ' <<<"$findings"
}
lint clang-tidy clang_tidy

echo "lint: $passed passed, $failed failed, 0 skipped"
[ "$failed" -eq 0 ]
