#!/usr/bin/env python3
"""What ~map_updates sends against what ~map would, over a bag replayed into a running server.

    map_updates_bandwidth.py BAG RATE [SERVER]   (SERVER: default /mvog_mapper)

The server runs on simulated time (mapper.launch use_sim_time:=true) with its ~binary_map_period:
every period in which the map changed it publishes both an update (what changed since the last
one) and the whole map (~map), so the two streams compare like for like. This plays the bag with
`rosbag play --clock -r RATE`, counts the bytes of both, and prints for each tenth of the bag's
time the map's size (its latest ~map) and each stream's bytes per second of bag time, as a
Markdown table. A measurement, not a test: nothing is asserted. Example (intel_lab.bag, the
figure reported with issue 13):

    rosparam load config/robot_2d_laser.yaml /mvog_mapper
    roslaunch mvog mapper.launch scan_topic:=/scan resolution:=0.05 use_sim_time:=true &
    scripts/map_updates_bandwidth.py ../shared/data/intel_lab.bag 20
"""
import subprocess
import sys
import threading
import time

import rosbag
import rospy

from mvog.msg import MapBinary, MapUpdate

PARTS = 10


def main():
    if len(sys.argv) not in (3, 4):
        sys.exit(__doc__)
    bag_path, rate = sys.argv[1], sys.argv[2]
    server = sys.argv[3] if len(sys.argv) == 4 else "/mvog_mapper"
    rospy.init_node("map_updates_bandwidth", disable_signals=True)
    lock = threading.Lock()
    updates, maps = [], []  # (stamp, bytes)

    def on_update(message):
        with lock:
            updates.append((message.header.stamp.to_sec(), len(message.data)))

    def on_map(message):
        with lock:
            maps.append((message.header.stamp.to_sec(), len(message.data)))

    rospy.Subscriber(server + "/map_updates", MapUpdate, on_update, queue_size=1000)
    rospy.Subscriber(server + "/map", MapBinary, on_map, queue_size=1000)
    time.sleep(2.0)
    with rosbag.Bag(bag_path) as bag:
        start, end = bag.get_start_time(), bag.get_end_time()
    subprocess.run(["rosbag", "play", "--clock", "-q", "--wait-for-subscribers", "-r", rate,
                    bag_path], check=True, stdin=subprocess.DEVNULL)
    time.sleep(3.0)
    with lock:
        updates, maps = list(updates), [m for m in maps if m[0] > start]
    print("%d updates, %d maps over %.0f s of bag" % (len(updates), len(maps), end - start))
    print("| part of the bag | map (bytes) | ~map_updates (B/s) | ~map (B/s) | updates / map |")
    print("|---|---:|---:|---:|---:|")
    for k in range(PARTS):
        a = start + (end - start) * k / PARTS
        b = start + (end - start) * (k + 1) / PARTS
        sent = sum(n for t, n in updates if a <= t < b)
        whole = sum(n for t, n in maps if a <= t < b)
        size = max([n for t, n in maps if t < b] or [0])
        print("| %d-%d %% | %d | %.0f | %.0f | %.3f |" % (
            100 * k // PARTS, 100 * (k + 1) // PARTS, size, sent / (b - a), whole / (b - a),
            sent / whole if whole else float("nan")))
    total_updates, total_maps = sum(n for _, n in updates), sum(n for _, n in maps)
    print("in all: ~map_updates %d bytes, ~map %d bytes (%.1f %%)"
          % (total_updates, total_maps, 100.0 * total_updates / max(total_maps, 1)))


if __name__ == "__main__":
    main()
