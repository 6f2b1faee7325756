#!/usr/bin/env bash
# The main job: installs what is missing, builds, generates the embedded default recording (a
# MAV with a depth camera and a tilted laser in an office while a person walks in and out),
# replays it through mapper.launch with `rosbag play --clock`, then saves the map, writes two
# cross-sections and the projected map as map_server PGM + YAML, a screenshot of rviz (under
# Xvfb) and a rendered PNG of the occupied space, and prints the statistics and what it wrote.
#
#   scripts/demo.sh [--bag FILE] [--scan-topic T] [--cloud-topic T] [--resolution R]
#                   [--config YAML] [--heights "Z1 Z2"] [--rate X] [--output DIR]
source "$(dirname "${BASH_SOURCE[0]}")/common.sh"

bag=""
scan_topic=/scan
cloud_topic=/camera/depth/points
resolution=0.05
config=$REPO/config/demo.yaml
heights="0.5 1.5"
rate=1.0
output=$REPO/out/demo
while [ $# -gt 0 ]; do
  case $1 in
    --bag) bag=$(realpath "$2"); shift 2 ;;
    --scan-topic) scan_topic=$2; shift 2 ;;
    --cloud-topic) cloud_topic=$2; shift 2 ;;
    --resolution) resolution=$2; shift 2 ;;
    --config) config=$(realpath "$2"); shift 2 ;;
    --heights) heights=$2; shift 2 ;;
    --rate) rate=$2; shift 2 ;;
    --output) output=$2; shift 2 ;;
    -h|--help) sed -n '2,10p' "$0"; exit 0 ;;
    *) echo "unknown option: $1 (see --help)" >&2; exit 2 ;;
  esac
done

install_missing_packages
build_workspace
source_workspace
mkdir -p "$output"
output=$(realpath "$output")
export ROS_HOME=$output/ros_home ROS_LOG_DIR=$output/ros_home/log

if [ -z "$bag" ]; then
  bag=$output/scene.bag
  if [ ! -s "$bag" ] || [ "$REPO/scripts/make_scene.py" -nt "$bag" ]; then
    quietly make-scene python3 "$REPO/scripts/make_scene.py" --output "$bag" \
      --truth "$output/scene_truth.json"
  fi
fi

start_private_master demo

heights_yaml="[$(tr -s ' ' ',' <<<"$heights")]"
roslaunch mvog mapper.launch use_sim_time:=true resolution:="$resolution" \
  scan_topic:="$scan_topic" cloud_topic:="$cloud_topic" map_directory:="$output" \
  config:="$config" >"$LOG_DIR/demo-mapper.log" 2>&1 &
BACKGROUND_PIDS+=($!)
until rosservice list 2>/dev/null | grep -q /mvog_mapper/save_map; do
  if ! kill -0 "${BACKGROUND_PIDS[-1]}" 2>/dev/null; then
    echo "the mapper did not start:" >&2
    tail -n 20 "$LOG_DIR/demo-mapper.log" >&2
    exit 1
  fi
  sleep 0.5
done
rosparam set /mvog_mapper/cross_section_heights "$heights_yaml" 2>/dev/null || true

screenshot=""
if command -v Xvfb >/dev/null && command -v rviz >/dev/null; then
  # Xvfb picks a free display itself and writes its number to the file descriptor given.
  rm -f "$LOG_DIR/demo-xvfb-display"  # the loop below must not read a previous run's number
  Xvfb -displayfd 3 -screen 0 1280x900x24 3>"$LOG_DIR/demo-xvfb-display" >"$LOG_DIR/demo-xvfb.log" 2>&1 &
  BACKGROUND_PIDS+=($!)
  for _ in $(seq 50); do [ -s "$LOG_DIR/demo-xvfb-display" ] && break; sleep 0.2; done
  display=:$(cat "$LOG_DIR/demo-xvfb-display")
  DISPLAY=$display rviz -d "$REPO/rviz/mvog.rviz" >"$LOG_DIR/demo-rviz.log" 2>&1 &
  BACKGROUND_PIDS+=($!)
fi

echo "replaying $bag ..."
rosbag play --clock -q -r "$rate" "$bag" >"$LOG_DIR/demo-rosbag.log" 2>&1
# Let the mapper drain its queue and publish once more.
previous=-1
for _ in $(seq 30); do
  inserted=$(rostopic echo -n 1 /mvog_mapper/statistics/messages_inserted 2>/dev/null | head -1 || true)
  [ "$inserted" = "$previous" ] && break
  previous=$inserted
  sleep 2
done

rosservice call /mvog_mapper/save_map "path: 'demo.mvog'" >"$LOG_DIR/demo-save.log"
grep -q 'success: True' "$LOG_DIR/demo-save.log" || { cat "$LOG_DIR/demo-save.log"; exit 1; }
map=$output/demo.mvog

if [ ${#BACKGROUND_PIDS[@]} -gt 2 ] && DISPLAY=$display xwininfo -root >/dev/null 2>&1; then
  sleep 3
  DISPLAY=$display import -window root "$output/rviz.png" 2>>"$LOG_DIR/demo-screenshot.log" &&
    screenshot=$output/rviz.png
fi

export_args=()
for z in $heights; do export_args+=(--cross-section "$z" "$output/cross_section_${z}m"); done
export_args+=(--projection 0.1 2.0 "$output/projected_map" --render "$output/occupied.png")
rosrun mvog mvog_export "$map" "${export_args[@]}" >"$LOG_DIR/demo-export.log"

echo
echo "statistics:"
rostopic echo -n 1 /mvog_mapper/statistics 2>/dev/null |
  grep -E 'cells_with_volumes|_volumes|bytes_held|table_one|readings_inserted|readings_rejected|insertion_seconds|messages_' |
  sed 's/^/  /'
if [ -f "$output/scene_truth.json" ] && [ "$bag" = "$output/scene.bag" ]; then
  python3 - "$output/scene_truth.json" <<'PY'
import json, subprocess, sys
truth = json.load(open(sys.argv[1]))
points = [probe["point"] for probe in truth["probes"]["person"]]
request = "{frame_id: '', points: [%s]}" % ", ".join(
    "{x: %f, y: %f, z: %f}" % tuple(p) for p in points)
out = subprocess.run(["rosservice", "call", "/mvog_mapper/get_occupancy", request],
                     capture_output=True, text=True).stdout
states = {"0": "unknown", "1": "free", "2": "occupied"}
line = next((l for l in out.splitlines() if l.startswith("state:")), "state: []")
found = [states.get(s.strip(), s) for s in line.split(":", 1)[1].strip(" []").split(",") if s.strip()]
print("  where the person stood, after he left: " + ", ".join(found))
PY
fi
echo
echo "wrote:"
echo "  map             $map"
for z in $heights; do echo "  cross-section   $output/cross_section_${z}m.pgm (.yaml)"; done
echo "  projected map   $output/projected_map.pgm (.yaml)"
echo "  occupied space  $output/occupied.png"
[ -n "$screenshot" ] && echo "  rviz            $screenshot"
echo "  logs            $LOG_DIR"
