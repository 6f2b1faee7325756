#!/usr/bin/env python3
"""launch/multi_robot.launch with the two halves of intel_lab.bag as two robots (multi_robot.test).

Robot 1 gets the first 455 scans (/robot1/scan), robot 2 the other 455 (/robot2/scan), one half
after the other on the bag's clock, with the bag's tf (one `map` frame: the merge's transform is
the identity). /whole/mvog_mapper maps all 910. Checked: every scan inserted once, by its robot
and by the whole map; each base-station mirror's map is its robot's byte for byte; the merged map
knows every point either robot's map knows, and agrees with the whole recording's map at >= 99 %
of the points either knows (they differ where eq. (8) closed a gap: README, "merging two halves
against mapping all"); the figures are printed.
"""
import os
import subprocess
import sys
import time
import xmlrpc.client

import numpy as np
import rosbag
import rosgraph
import rospy
from geometry_msgs.msg import Point
from rosgraph_msgs.msg import Clock
from std_srvs.srv import SetBool

import mvog_data_test as data
from mvog.msg import MapBinary, MapStatistics
from mvog.srv import GetOccupancy

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "lifecycle"))
import mvog_lifecycle as life  # noqa: E402

BAG = "intel_lab.bag"
README_SCANS = 910
RATE = 50
ROBOTS = ["/robot1/mvog_mapper", "/robot2/mvog_mapper"]
SCAN_TOPICS = ["/robot1/scan", "/robot2/scan"]
MIRRORS = ["/base/robot1/mvog_mirror", "/base/robot2/mvog_mirror"]
MERGED, WHOLE = "/base/mvog_merged", "/whole/mvog_mapper"
LASER_HEIGHT = 0.3  # the data README's (synthetic) mount height
SAMPLES = 40000
MERGE_PERIOD = 2.0  # s of the clock: multi_robot.test's merge_period


def states(ns, points):
    response = rospy.ServiceProxy(ns + "/get_occupancy", GetOccupancy)(
        frame_id="", points=[Point(*map(float, p)) for p in points])
    assert response.success, response.message
    return np.frombuffer(bytes(response.state), dtype=np.uint8).copy()


def play_when_connected(command, name, topic, subscribers, timeout=60.0):
    """Runs `command` (rosbag play) as node `name`, paused until each of `subscribers` is
    connected to its `topic`: roscpp drops, uncounted, what is published before a subscriber has
    connected, and rosbag play's own waits (for one subscriber, then a fixed pause) do not wait
    for every subscriber. On a loaded machine, runs without this ended with one server or both
    short of a half's scans, none counted."""
    process = subprocess.Popen(command + ["--pause", "__name:=" + name],
                               stdin=subprocess.DEVNULL)
    try:
        master = rosgraph.Master(rospy.get_name())
        deadline = time.time() + timeout
        connected = set()
        while not all(subscriber in connected for subscriber in subscribers):
            assert process.poll() is None, "%s exited (%d)" % (name, process.returncode)
            assert time.time() < deadline, "%s: only %s connected" % (topic, sorted(connected))
            time.sleep(0.1)
            try:
                bus = xmlrpc.client.ServerProxy(master.lookupNode("/" + name)).getBusInfo(
                    rospy.get_name())[2]
            except (rosgraph.MasterError, OSError):
                continue  # not registered yet
            # roscpp's bus info: [id, the other end's node, "o" (outbound), transport, topic, ...]
            connected = {link[1] for link in bus if link[2] == "o" and link[4] == topic}
        rospy.ServiceProxy("/" + name + "/pause_playback", SetBool)(False)
        assert process.wait(timeout=120) == 0, "%s failed" % name
    finally:
        if process.poll() is None:
            process.kill()
            process.wait()


class MultiRobot(data.DataTestCase):
    @classmethod
    def setUpClass(cls):
        path = data.require_bag(BAG)
        rospy.init_node("test_multi_robot", disable_signals=True)
        with rosbag.Bag(str(path)) as bag:
            stamps = [scan.header.stamp.to_sec()
                      for _, scan, _ in data.read_messages(bag, ["/scan"])]
            start, end = bag.get_start_time(), bag.get_end_time()
        cls.halves = [len(stamps) // 2, len(stamps) - len(stamps) // 2]
        # Split midway between the two scans at the middle: no scan near the boundary.
        split = (stamps[cls.halves[0] - 1] + stamps[cls.halves[0]]) / 2.0 - start
        cls.nodes = {ns: life.Node(ns) for ns in ROBOTS + MIRRORS + [MERGED, WHOLE]}
        cls.statistics = {}
        for ns in ROBOTS + [WHOLE]:
            rospy.Subscriber(ns + "/statistics", MapStatistics, cls._on_statistics,
                             callback_args=ns)
        # What the merger merges: each mirror's ~map, published every ~binary_map_period (5 s by
        # default) when it changed, so up to a period after the mirror holds its robot's map.
        cls.published = {}
        for ns in MIRRORS:
            rospy.Subscriber(ns + "/map", MapBinary, cls._on_map, callback_args=ns)
        # Each half's topic has two subscribers: its robot and /whole.
        play = ["rosbag", "play", "--clock", "-q", "-r", str(RATE), str(path)]
        started = time.time()
        play_when_connected(play + ["-u", "%.3f" % split, "/scan:=" + SCAN_TOPICS[0]],
                            "multi_robot_first_half", SCAN_TOPICS[0], [ROBOTS[0], WHOLE])
        play_when_connected(play + ["-s", "%.3f" % split, "/scan:=" + SCAN_TOPICS[1]],
                            "multi_robot_second_half", SCAN_TOPICS[1], [ROBOTS[1], WHOLE])
        cls.play_seconds = time.time() - started

        # The clock on past the bag's end until each map holds every scan, each mirror is its
        # robot's map and has published it to the merger, and the merged map has not changed over
        # two merge periods since then. (Waiting only for the merged map to stay unchanged raced
        # with the mirrors' publications: a run merged a mirror's map of a few scans before.)
        clock = rospy.Publisher("/clock", Clock, queue_size=10)
        now, deadline = end, time.time() + 180.0
        previous, stable_since, inputs_final_since = None, None, None
        waiting_for = "every scan counted"
        while True:
            assert time.time() < deadline, "the maps did not settle, waiting for %s: %s" % (
                waiting_for, cls.describe())
            for _ in range(50):  # 0.5 s of the clock
                now += 0.01
                clock.publish(Clock(clock=rospy.Time.from_sec(now)))
                time.sleep(0.002)
            if not cls.all_inserted():
                continue
            waiting_for = "each mirror to hold its robot's map"
            snapshots = {ns: node.snapshot() for ns, node in cls.nodes.items()}
            if any(snapshots[m] != snapshots[r] for m, r in zip(MIRRORS, ROBOTS)):
                continue
            waiting_for = "each mirror to publish its map to the merger"
            if any(cls.published.get(m) != snapshots[m] for m in MIRRORS):
                inputs_final_since = None
                continue
            if inputs_final_since is None:
                inputs_final_since = now
            waiting_for = "the merged map to stay unchanged"
            if snapshots[MERGED] != previous:
                previous, stable_since = snapshots[MERGED], now
            elif now - max(stable_since, inputs_final_since) >= 2 * MERGE_PERIOD:
                break
        cls.snapshots = snapshots
        print("halves of %d and %d scans played in %.1f s; settled at %.1f s of the clock past "
              "the bag's end" % (cls.halves[0], cls.halves[1], cls.play_seconds, now - end))
        print("map bytes (saved): " + ", ".join("%s %d" % (ns, len(snapshots[ns]))
                                                for ns in sorted(snapshots)))
        print("the merged map's file is the whole recording's byte for byte: %s"
              % (snapshots[MERGED] == snapshots[WHOLE]))

    @classmethod
    def _on_statistics(cls, message, ns):
        cls.statistics[ns] = message

    @classmethod
    def _on_map(cls, message, ns):
        cls.published[ns] = bytes(message.data)

    @classmethod
    def all_inserted(cls):
        wanted = dict(zip(ROBOTS, cls.halves))
        wanted[WHOLE] = sum(cls.halves)
        for ns, count in wanted.items():
            s = cls.statistics.get(ns)
            if s is None or (s.messages_inserted + s.messages_dropped_tf +
                             s.messages_dropped_queue + s.messages_dropped_invalid) < count:
                return False
        return True

    @classmethod
    def describe(cls):
        return ", ".join("%s: %d inserted, %d dropped (tf %d, queue %d, invalid %d)" % (
            ns, s.messages_inserted, s.messages_dropped_tf + s.messages_dropped_queue +
            s.messages_dropped_invalid, s.messages_dropped_tf, s.messages_dropped_queue,
            s.messages_dropped_invalid) for ns, s in sorted(cls.statistics.items()))

    def test_every_scan_inserted_once(self):
        for ns, count in list(zip(ROBOTS, self.halves)) + [(WHOLE, README_SCANS)]:
            s = self.statistics[ns]
            self.assertEqual(s.messages_inserted, count, ns)
            self.assertEqual(s.messages_dropped_tf + s.messages_dropped_queue +
                             s.messages_dropped_invalid, 0, ns)
        self.assertEqual(sum(self.halves), README_SCANS)

    def test_each_mirror_is_its_robots_map(self):
        for mirror, robot in zip(MIRRORS, ROBOTS):
            self.assertEqual(self.snapshots[mirror], self.snapshots[robot], mirror)

    def test_the_merge_agrees_with_the_whole_recording(self):
        # Random points of the whole map's extent at the scan plane, and 0.5 m above it (unknown
        # in every map: the data is 2D).
        cells = life.read_map(self.snapshots[WHOLE])[1]
        keys = np.array(sorted(cells.keys()), dtype=np.float64)
        resolution = 0.1
        low, high = keys.min(axis=0) * resolution, (keys.max(axis=0) + 1) * resolution
        rng = np.random.default_rng(0)
        xy = rng.uniform(low, high, size=(SAMPLES, 2))
        points = np.column_stack([xy, np.full(SAMPLES, LASER_HEIGHT)])
        answers = {ns: states(ns, points) for ns in ROBOTS + [MERGED, WHOLE]}
        known = {ns: a != data.UNKNOWN for ns, a in answers.items()}
        either = known[ROBOTS[0]] | known[ROBOTS[1]]
        self.assertGreater(int(either.sum()), SAMPLES // 10, "too few known points")
        # Merging only adds: what a robot's map knows, the merge knows.
        self.assertEqual(int(np.sum(either & ~known[MERGED])), 0,
                         "points a robot's map knows and the merged map does not")
        # Where only one robot saw, the merge says what it says.
        only = [known[ROBOTS[0]] & ~known[ROBOTS[1]], known[ROBOTS[1]] & ~known[ROBOTS[0]]]
        for robot, mask in zip(ROBOTS, only):
            same = float(np.mean(answers[MERGED][mask] == answers[robot][mask]))
            print("where only %s knows (%d points): the merge agrees at %.3f %%"
                  % (robot, int(mask.sum()), 100 * same))
            self.assertGreaterEqual(same, 0.99, robot)
        both = either | known[WHOLE]
        agree = float(np.mean(answers[MERGED][both] == answers[WHOLE][both]))
        print("merged against the whole recording: %.3f %% of %d known points agree "
              "(free %d/%d, occupied %d/%d, unknown %d/%d in merged/whole)"
              % (100 * agree, int(both.sum()),
                 *[int(np.sum(answers[ns][both] == s)) for s in (data.FREE, data.OCCUPIED,
                                                                 data.UNKNOWN)
                   for ns in (MERGED, WHOLE)]))
        self.assertGreaterEqual(agree, 0.99)
        above = points + [0.0, 0.0, 0.5]
        self.assertTrue(np.all(states(MERGED, above) == data.UNKNOWN), "0.5 m above the plane")


if __name__ == "__main__":
    data.main("multi_robot", MultiRobot)
