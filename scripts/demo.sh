#!/usr/bin/env bash
# The main job: installs what is missing, builds, generates the embedded default recording (a
# MAV with a depth camera and a tilted laser in an office while a person walks in and out),
# replays it through mapper.launch with `rosbag play --clock` once the mapper has subscribed,
# then saves the map, writes the cross-sections and the projected map as map_server PGM + YAML, a
# rendered PNG of the occupied space and a screenshot of rviz (under Xvfb) framed on the map, and
# prints what the mapper did with the bag's sensor messages and the line to source to use it.
#
#   scripts/demo.sh [--bag FILE] [--scan-topic T] [--cloud-topic T] [--depth-topic T]
#                   [--resolution R] [--config YAML] [--heights "Z1 Z2"] [--rate X] [--output DIR]
# (--depth-topic: a depth image topic, its camera info on the sibling camera_info topic.)
# shellcheck source=scripts/common.sh
source "$(dirname "${BASH_SOURCE[0]}")/common.sh"

bag=""
scan_topic=/scan
cloud_topic=/camera/depth/points
depth_topic=/camera/depth/image
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
    --depth-topic) depth_topic=$2; shift 2 ;;
    --resolution) resolution=$2; shift 2 ;;
    --config) config=$(realpath "$2"); shift 2 ;;
    --heights) heights=$2; shift 2 ;;
    --rate) rate=$2; shift 2 ;;
    --output) output=$2; shift 2 ;;
    -h|--help) sed -n '2,11p' "$0"; exit 0 ;;
    *) echo "unknown option: $1 (see --help)" >&2; exit 2 ;;
  esac
done
# Topics as a bag names them.
[[ $scan_topic == /* ]] || scan_topic=/$scan_topic
[[ $cloud_topic == /* ]] || cloud_topic=/$cloud_topic
[[ $depth_topic == /* ]] || depth_topic=/$depth_topic
depth_info_topic=${depth_topic%/*}/camera_info  # image_transport's sibling
read -r -a height_list <<<"$heights"

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

# The bag's sensor messages on the three topics, and how long it plays.
read -r bag_scans bag_clouds bag_images bag_seconds < <(python3 - "$bag" "$scan_topic" \
  "$cloud_topic" "$depth_topic" <<'PY'
import sys
import rosbag
with rosbag.Bag(sys.argv[1]) as bag:
    topics = bag.get_type_and_topic_info().topics
    counts = [topics[t].message_count if t in topics else 0 for t in sys.argv[2:5]]
    print(*counts, bag.get_end_time() - bag.get_start_time())
PY
)
bag_messages=$((bag_scans + bag_clouds + bag_images))
if [ "$bag_messages" -eq 0 ]; then
  echo "$bag holds no message on $scan_topic, $cloud_topic or $depth_topic" \
    "(see --scan-topic, --cloud-topic, --depth-topic)" >&2
  exit 1
fi

start_private_master demo

heights_yaml="[$(IFS=,; echo "${height_list[*]}")]"
roslaunch mvog mapper.launch use_sim_time:=true resolution:="$resolution" \
  scan_topic:="$scan_topic" cloud_topic:="$cloud_topic" depth_topic:="$depth_topic" \
  map_directory:="$output" \
  config:="$config" cross_section_heights:="$heights_yaml" >"$LOG_DIR/demo-mapper.log" 2>&1 &
BACKGROUND_PIDS+=($!)
until rosservice list 2>/dev/null | grep -q /mvog_mapper/save_map; do
  if ! kill -0 "${BACKGROUND_PIDS[-1]}" 2>/dev/null; then
    echo "the mapper did not start:" >&2
    tail -n 20 "$LOG_DIR/demo-mapper.log" >&2
    exit 1
  fi
  sleep 0.5
done

echo "replaying $bag ..."
# Only the sensor topics and tf, each played once the mapper has subscribed to it: no first
# message is lost. --keep-alive keeps the clock going past the bag's end, so that the mapper's
# timers (statistics, publication, decay) run on while it inserts what it still holds.
rosbag play --clock --keep-alive --wait-for-subscribers -q -r "$rate" "$bag" \
  --topics "$scan_topic" "$cloud_topic" "$depth_topic" "$depth_info_topic" /tf /tf_static \
  >"$LOG_DIR/demo-rosbag.log" 2>&1 &
player=$!
BACKGROUND_PIDS+=("$player")
# Until the statistics account for every sensor message of the bag (inserted or dropped for a
# reason they count); messages lost uncounted would keep them short, so also until they have
# stood still for 10 s once the bag has played.
python3 - "$bag_messages" "$bag_seconds" "$rate" <<'PY'
import sys
import time
import rospy
from mvog.msg import MapStatistics
expected, play_seconds = int(sys.argv[1]), float(sys.argv[2]) / float(sys.argv[3])
rospy.init_node("demo_replay_wait", anonymous=True, disable_signals=True)
latest = []
rospy.Subscriber("/mvog_mapper/statistics", MapStatistics, latest.append)
start = time.monotonic()
counts, changed = None, start
while time.monotonic() - start < play_seconds + 600:
    time.sleep(0.5)
    if not latest:
        continue
    s = latest[-1]
    now = (s.messages_inserted, s.messages_dropped_tf, s.messages_dropped_queue,
           s.messages_dropped_invalid, s.messages_dropped_camera_info)
    if now != counts:
        counts, changed = now, time.monotonic()
    if sum(counts) >= expected:
        break
    if time.monotonic() - start > play_seconds + 10 and time.monotonic() - changed > 10:
        break
PY
kill -INT "$player" 2>/dev/null || true
wait "$player" 2>/dev/null || true

rosservice call /mvog_mapper/save_map "path: 'demo.mvog'" >"$LOG_DIR/demo-save.log"
grep -q 'success: True' "$LOG_DIR/demo-save.log" || { cat "$LOG_DIR/demo-save.log"; exit 1; }
map=$output/demo.mvog

# A path through the door (~plan_path, when the server is built with OMPL), from the room into
# the corridor of the embedded recording: on ~planned_path (latched) for rviz's screenshot.
plan_status=""
if [ "$bag" = "$output/scene.bag" ] && rosservice list 2>/dev/null | grep -q /mvog_mapper/plan_path; then
  rosservice call /mvog_mapper/plan_path "{frame_id: '', start: {x: 4.0, y: 1.5, z: 1.2},
    goal: {x: 6.5, y: -1.0, z: 1.0}, radius: 0.25, time_limit: 1.0, allow_unknown: false}" \
    >"$LOG_DIR/demo-plan.log"
  plan_status="status $(sed -n 's/^status: //p' "$LOG_DIR/demo-plan.log") (0: planned)"
  plan_status+=", $(grep -c 'position:' "$LOG_DIR/demo-plan.log" || true) waypoints,"
  plan_status+=" $(sed -n 's/^planning_time: //p' "$LOG_DIR/demo-plan.log") s"
  plan_status+=" $(sed -n "s/^message: //p" "$LOG_DIR/demo-plan.log" | grep -v "^''$" || true)"
fi

export_args=()
for z in "${height_list[@]}"; do export_args+=(--cross-section "$z" "$output/cross_section_${z}m"); done
export_args+=(--projection 0.1 2.0 "$output/projected_map" --render "$output/occupied.png")
rosrun mvog mvog_export "$map" "${export_args[@]}" >"$LOG_DIR/demo-export.log"

# rviz's view framed on the map (its extent from the projected map), for the screenshot and for
# `rviz -d $output/mvog.rviz`.
python3 - "$REPO/rviz/mvog.rviz" "$output/projected_map" "$scan_topic" "$depth_topic" \
  >"$output/mvog.rviz" <<'PY'
import re
import sys
template, projection, scan_topic, depth_topic = sys.argv[1:5]
resolution = origin = None
for line in open(projection + ".yaml"):
    if line.startswith("resolution:"):
        resolution = float(line.split(":", 1)[1])
    elif line.startswith("origin:"):
        origin = [float(v) for v in line.split(":", 1)[1].strip(" []\n").split(",")]
with open(projection + ".pgm", "rb") as pgm:
    width, height = (int(v) for v in pgm.read(64).split()[1:3])
extent = max(width, height) * resolution
view = "Distance: %.2f\n      Focal Point:\n        X: %.2f\n        Y: %.2f\n" % (
    max(4.0, 1.75 * extent), origin[0] + 0.5 * width * resolution,
    origin[1] + 0.5 * height * resolution)
text = open(template).read()
text = re.sub(r"Distance: [-0-9.]+\n      Focal Point:\n        X: [-0-9.]+\n        Y: [-0-9.]+\n",
              view, text)
text = text.replace("Topic: /scan\n", "Topic: %s\n" % scan_topic)
text = text.replace("Depth Map Topic: /camera/depth/image\n", "Depth Map Topic: %s\n" % depth_topic)
sys.stdout.write(text)
PY

screenshot=""
if command -v Xvfb >/dev/null && command -v rviz >/dev/null; then
  # Xvfb picks a free display itself and writes its number to the file descriptor given.
  rm -f "$LOG_DIR/demo-xvfb-display"  # the loop below must not read a previous run's number
  # The screen is the size of rviz's window (its view's Window Geometry): the screenshot is the
  # window alone.
  window_width=$(sed -n '/^Window Geometry:/,$ s/^  Width: //p' "$output/mvog.rviz")
  window_height=$(sed -n '/^Window Geometry:/,$ s/^  Height: //p' "$output/mvog.rviz")
  Xvfb -displayfd 3 -screen 0 "${window_width}x${window_height}x24" 3>"$LOG_DIR/demo-xvfb-display" >"$LOG_DIR/demo-xvfb.log" 2>&1 &
  BACKGROUND_PIDS+=($!)
  for _ in $(seq 50); do [ -s "$LOG_DIR/demo-xvfb-display" ] && break; sleep 0.2; done
  display=:$(cat "$LOG_DIR/demo-xvfb-display")
  # The replay is over and nothing publishes tf: the bag's last transform of every frame, held
  # on /tf_static while rviz draws, so that its fixed frame exists and its TF display shows where
  # the sensors ended.
  python3 - "$bag" >"$LOG_DIR/demo-last-tf.log" 2>&1 <<'PY' &
import sys
import rosbag
import rospy
from tf2_msgs.msg import TFMessage
last = {}
with rosbag.Bag(sys.argv[1]) as bag:
    for _, message, _ in bag.read_messages(topics=["/tf", "/tf_static"]):
        for transform in message.transforms:
            last[(transform.header.frame_id, transform.child_frame_id)] = transform
rospy.init_node("demo_last_tf", anonymous=True)
publisher = rospy.Publisher("/tf_static", TFMessage, queue_size=1, latch=True)
publisher.publish(TFMessage(transforms=list(last.values())))
rospy.spin()
PY
  BACKGROUND_PIDS+=($!)
  DISPLAY=$display rviz -d "$output/mvog.rviz" >"$LOG_DIR/demo-rviz.log" 2>&1 &
  BACKGROUND_PIDS+=($!)
  # Once rviz has subscribed to the markers (sent whole to a new subscriber), time to draw them.
  for _ in $(seq 120); do
    rostopic info /mvog_mapper/occupied 2>/dev/null | sed -n '/Subscribers:/,$p' | grep -q rviz &&
      break
    sleep 0.5
  done
  sleep 5
  DISPLAY=$display import -window root "$output/rviz.png" 2>>"$LOG_DIR/demo-screenshot.log" &&
    screenshot=$output/rviz.png
fi

echo
rostopic echo -n 1 /mvog_mapper/statistics >"$LOG_DIR/demo-statistics.log" 2>/dev/null
statistic() { sed -n "s/^$1: //p" "$LOG_DIR/demo-statistics.log"; }
echo "sensor messages in the bag: $bag_messages ($bag_scans LaserScan on $scan_topic," \
  "$bag_clouds PointCloud2 on $cloud_topic, $bag_images depth images on $depth_topic);" \
  "inserted $(statistic messages_inserted), dropped $(statistic messages_dropped_tf) without" \
  "transform, $(statistic messages_dropped_queue) for a full queue," \
  "$(statistic messages_dropped_invalid) invalid, $(statistic messages_dropped_camera_info)" \
  "without camera info"
echo "statistics:"
grep -E 'cells_with_volumes|_volumes|bytes_held|table_one|readings_inserted|readings_rejected|insertion_seconds' \
  "$LOG_DIR/demo-statistics.log" | sed 's/^/  /'
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
[ -n "$plan_status" ] &&
  echo "path through the door, (4.0, 1.5, 1.2) to (6.5, -1.0, 1.0), radius 0.25 m: $plan_status"
echo
echo "wrote:"
echo "  map             $map"
for z in "${height_list[@]}"; do echo "  cross-section   $output/cross_section_${z}m.pgm (.yaml)"; done
echo "  projected map   $output/projected_map.pgm (.yaml)"
echo "  occupied space  $output/occupied.png"
echo "  rviz view       $output/mvog.rviz"
[ -n "$screenshot" ] && echo "  rviz            $screenshot"
echo "  logs            $LOG_DIR"
echo
echo "to use this build (roslaunch mvog mapper.launch, rosrun mvog mvog_export, rviz -d ...):"
echo "  source $WORKSPACE/devel/setup.bash"
