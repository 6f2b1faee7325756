#!/usr/bin/env bash
# The load benchmark of RELIABILITY.md: installs what is missing, builds, starts a private ROS
# master and runs scripts/load_test.py (300k-point clouds at 30 Hz with tf for 60 s while a client
# queries 10k points at 10 Hz). Arguments go to load_test.py (see its --help).
#
#   scripts/load.sh [--points N | --lidar BEAMSxCOLUMNS |
#                    --depth WxH [--depth-encoding 16UC1|32FC1] [--depth-stride K]]
#                   [--rate HZ] [--duration S] [--query-points N] [--json FILE]
# shellcheck source=scripts/common.sh
source "$(dirname "${BASH_SOURCE[0]}")/common.sh"

install_missing_packages
build_workspace
source_workspace
export ROS_HOME=${ROS_HOME:-$WORKSPACE/ros_home}
start_private_master load
python3 "$REPO/scripts/load_test.py" "$@"
