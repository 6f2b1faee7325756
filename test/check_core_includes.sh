#!/usr/bin/env bash
# Lists every header the core's sources and headers (include/mvog) reach, directly or through
# other headers, and fails if any comes from ROS, PCL, tf2 or Boost: the core must stay plain
# C++17 + Eigen.
# Usage: check_core_includes.sh COMPILER SOURCE_DIR
set -euo pipefail
compiler=$1
source_dir=$2
status=0
for source in "$source_dir"/src/core/*.cpp "$source_dir"/include/mvog/*.h; do
  deps=$("$compiler" -x c++ -std=c++17 -M -I"$source_dir/include" -I/usr/include/eigen3 "$source")
  forbidden=$(tr -s '\\ ' '\n' <<<"$deps" | grep -E '/(ros|pcl[^/]*|tf2[^/]*|boost|roscpp|catkin)/' || true)
  if [ -n "$forbidden" ]; then
    echo "FAIL: $source reaches non-core headers:"
    echo "$forbidden" | sort -u | head -20
    status=1
  fi
done
[ $status -eq 0 ] && echo "core headers: standard library and Eigen only"
exit $status
