# shellcheck shell=bash
# Shared by scripts/demo.sh and scripts/test.sh: installs what is missing and builds, quietly.
# Source it; it defines REPO, WORKSPACE and the functions below.
set -euo pipefail
# Debian's python3 must come first: a pyenv python3 breaks catkin, pluginlib, rosrun and rostest.
export PATH=/usr/bin:$PATH
REPO=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
# The workspace lives outside the repository: inside it, the workspace's link back to the package
# would make a loop for tools that search the package directory (rosrun). One per clone.
WORKSPACE=${MVOG_WORKSPACE:-${XDG_CACHE_HOME:-$HOME/.cache}/mvog/ws-$(printf %s "$REPO" | md5sum | cut -c1-8)}
LOG_DIR=$WORKSPACE/logs
export MVOG_DATA_DIR=${MVOG_DATA_DIR:-$(cd "$REPO/.." && pwd)/shared/data}

# Debian 12 packages: ROS 1 (Debian's own build), PCL, OctoMap, test and headless-rviz tools,
# valgrind (scripts/benchmarks.sh's instruction counts), clang with its sanitizer and libFuzzer
# runtimes and ninja (scripts/sanitizers.sh), the linters (scripts/lint.sh).
MVOG_PACKAGES=(
  build-essential cmake ninja-build libeigen3-dev libgtest-dev libbenchmark-dev
  ros-core-python-dev ros-base-dev python3-rostest rosbash python3-rosbag python3-numpy
  python3-rospy python3-sensor-msgs python3-geometry-msgs python3-tf2-msgs python3-tf2-ros
  python3-diagnostic-msgs python3-std-srvs
  libpcl-dev libtf2-ros-dev libtf2-eigen-dev libtf2-msgs-dev libstd-srvs-dev
  libvisualization-msgs-dev libnav-msgs-dev libmap-msgs-dev libdiagnostic-updater-dev
  libimage-transport-dev
  rviz tf2-tools liboctomap-dev octomap-tools
  xvfb xauth x11-utils libgl1-mesa-dri imagemagick valgrind
  clang-14 libclang-rt-14-dev clang-format-14 clang-tidy-14 catkin-lint shellcheck
  # The Python module (src/python): pybind11 to build it, pytest for test/python, matplotlib for
  # the example scripts/python_map_views.py.
  pybind11-dev python3-dev python3-pytest python3-matplotlib
  # dynamic_reconfigure: its C++ server and macros, and the Python client (dynparam, the tests)
  libdynamic-reconfigure-config-init-mutex-dev python3-dynamic-reconfigure
  # OMPL: mvog_ompl, the server's ~plan_path and mvog_ompl_bench (built when it is found)
  libompl-dev
)

as_root() {
  if [ "$(id -u)" -eq 0 ]; then "$@"; else sudo "$@"; fi
}

# Runs a command with its output in a log file; prints the log's end only if it fails.
quietly() {
  local name=$1
  shift
  mkdir -p "$LOG_DIR"
  local status=0
  "$@" >"$LOG_DIR/$name.log" 2>&1 || status=$?
  if [ "$status" -ne 0 ]; then
    echo "FAILED: $* (log: $LOG_DIR/$name.log)" >&2
    tail -n 60 "$LOG_DIR/$name.log" >&2
  fi
  return "$status"
}

install_missing_packages() {
  local missing=()
  for package in "${MVOG_PACKAGES[@]}"; do
    dpkg-query -W -f='${Status}' "$package" 2>/dev/null | grep -q 'install ok installed' ||
      missing+=("$package")
  done
  [ ${#missing[@]} -eq 0 ] && return 0
  echo "installing ${#missing[@]} missing Debian packages: ${missing[*]}"
  quietly apt-update as_root apt-get update
  quietly apt-install as_root env DEBIAN_FRONTEND=noninteractive apt-get install -y \
    --no-install-recommends "${missing[@]}"
}

# The catkin workspace links the repository as its only package (catkin's default
# CATKIN_ENABLE_TESTING=ON declares the tests; `catkin_make run_tests` builds them). mvog_bench
# gets the peers' backends (Bonxai) only where MVOG_PEERS_DIR is set (scripts/benchmarks.sh sets
# it; the tests never do).
build_workspace() {
  mkdir -p "$WORKSPACE/src"
  ln -sfn "$REPO" "$WORKSPACE/src/mvog"
  (cd "$WORKSPACE" && quietly catkin_make catkin_make -DCMAKE_BUILD_TYPE=Release \
    "-DMVOG_PEERS_DIR=${MVOG_PEERS_DIR:-}" -j2)
}

source_workspace() {
  set +u
  # shellcheck disable=SC1091
  source "$WORKSPACE/devel/setup.bash"
  set -u
}

# A private ROS master on a free port (its log in $LOG_DIR/$1-roscore.log). Every process started
# in the background and added to BACKGROUND_PIDS is stopped on exit, whatever happens.
BACKGROUND_PIDS=()
stop_background_processes() {
  # Newest first, each given a few seconds to exit: rviz must close before the X server it draws
  # on (it aborts when the display goes), nodes before their master.
  local k pid tries
  for ((k = ${#BACKGROUND_PIDS[@]} - 1; k >= 0; k--)); do
    pid=${BACKGROUND_PIDS[k]}
    kill -INT "$pid" 2>/dev/null || continue
    for ((tries = 0; tries < 25; tries++)); do
      kill -0 "$pid" 2>/dev/null || break
      sleep 0.2
    done
    kill -KILL "$pid" 2>/dev/null || true
    { wait "$pid"; } 2>/dev/null || true
  done
}
start_private_master() {
  local port
  port=$(python3 -c 'import socket; s=socket.socket(); s.bind(("127.0.0.1", 0)); print(s.getsockname()[1])')
  export ROS_MASTER_URI=http://127.0.0.1:$port ROS_IP=127.0.0.1
  trap stop_background_processes EXIT
  mkdir -p "$LOG_DIR"
  roscore -p "$port" >"$LOG_DIR/$1-roscore.log" 2>&1 &
  BACKGROUND_PIDS+=($!)
  local waited=0
  until rosparam list >/dev/null 2>&1; do
    if ! kill -0 "${BACKGROUND_PIDS[-1]}" 2>/dev/null || [ "$waited" -ge 120 ]; then
      echo "the ROS master did not start (log: $LOG_DIR/$1-roscore.log):" >&2
      tail -n 20 "$LOG_DIR/$1-roscore.log" >&2
      exit 1
    fi
    sleep 0.5
    waited=$((waited + 1))
  done
}
