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
#                 compile commands of a unity configuration of the catkin workspace (below).
# Prints each linter's findings; the last line is
#   lint: N passed, N failed, N skipped
# and it exits non-zero if any linter found something.
# shellcheck source=scripts/common.sh
source "$(dirname "${BASH_SOURCE[0]}")/common.sh"

install_missing_packages
# The workspace's top-level CMakeLists.txt, which catkin_make writes (scripts/test.sh builds first).
[ -f "$WORKSPACE/src/CMakeLists.txt" ] || build_workspace

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

# clang-tidy reads the package as CMake's unity build groups it: a target's sources included by a
# generated file, eight to a file, so that the ROS, PCL and Boost headers are parsed once for
# eight sources rather than once for each (some 160 s for all of src/ on 2 cores, against 500 s
# source by source). Only configured, in a tree of its own ($WORKSPACE/lint): nothing is compiled
# but the message and dynamic_reconfigure headers the sources include. The sources are reached
# through the workspace's link to the repository: the header filter keeps the findings to our own
# sources and headers (not the generated message headers); the checks are those of .clang-tidy,
# linked into the tree, above the generated files. The one finding located in
# a generated file, its `#include` of a .cpp file, is the unity build's own: dropped, with its
# notes.
# Bonxai's sources, which mvog_bench compiles from MVOG_PEERS_DIR (../shared/peers), are not
# configured here.
lint_tree=$WORKSPACE/lint
configure_unity_tree() {
  mkdir -p "$lint_tree"
  ln -sfn "$REPO/.clang-tidy" "$lint_tree/.clang-tidy"
  cmake -S "$WORKSPACE/src" -B "$lint_tree/build" -DCATKIN_DEVEL_PREFIX="$lint_tree/devel" \
    -DCMAKE_BUILD_TYPE=Release -DCMAKE_EXPORT_COMPILE_COMMANDS=ON -DCMAKE_UNITY_BUILD=ON \
    -DCATKIN_ENABLE_TESTING=OFF -DMVOG_PEERS_DIR= &&
    cmake --build "$lint_tree/build" -j2 --target mvog_generate_messages_cpp mvog_gencfg
}
clang_tidy() {
  local findings unity_files
  quietly lint-unity-tree configure_unity_tree || return 1
  unity_files=$(grep -cE '"file": ".*/Unity/unity_[0-9]+_cxx\.cxx"' \
    "$lint_tree/build/compile_commands.json" || true)
  echo "clang-tidy on $unity_files unity files"
  [ "$unity_files" -gt 0 ] || return 1
  findings=$(run-clang-tidy-14 -quiet -j 2 -p "$lint_tree/build" \
    -header-filter="^$WORKSPACE/src/mvog/(include|src)/" "/Unity/unity_[0-9]+_cxx\.cxx\$" 2>&1 |
    sed -E 's/\x1b\[[0-9;]*m//g' |
    grep -vE '^(clang-tidy-14 |[0-9]+ warnings? (generated|treated as errors)|Suppressed [0-9]+ warnings|Use -header-filter|Running clang-tidy|Enabled checks)' |
    awk '/\/Unity\/unity_[0-9]+_cxx\.cxx:[0-9]+:[0-9]+: (warning|error): suspicious #include of file with .\.cpp. extension/ { skip = 3 }
         /\/Unity\/unity_[0-9]+_cxx\.cxx:[0-9]+:[0-9]+: note: did you mean to include/ { skip = 1 }
         skip > 0 { skip--; next } { print }' || true)
  echo "$findings"
  # run-clang-tidy colours its output (always, in version 14: the escapes are dropped) and its
  # status says only that some file had findings: they decide, with their names.
  ! grep -qE '(warning|error): ' <<<"$findings"
}
lint clang-tidy clang_tidy

echo "lint: $passed passed, $failed failed, 0 skipped"
[ "$failed" -eq 0 ]
