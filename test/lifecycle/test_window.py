#!/usr/bin/env python3
"""~keep_radius on a long straight trajectory (see window.test and README).

A laser 0.5 m up drives 30 m along a corridor (walls at y = +-1 m; returns within 2 m, free space
of the readings without a return 2 m long too) past two servers fed the same scans: "window"
keeps 3 m around ~robot_frame ("mover") and merges the tiles it drops into
~keep_radius_save_file, "whole" keeps everything. Checked: the window's bytes_held stays bounded
while the whole map grows; the file holds exactly what left the window (the two together are the
whole map, list for list); a third server that merges the file and the window's map holds the
whole map byte for byte. Without decay, so that masses are exact.
"""
import math
import os
import shutil
import sys
import tempfile
import time
import unittest

import rospy
import rostest
from tf2_msgs.msg import TFMessage

import mvog_lifecycle as life
from mvog_lifecycle import rel

KEEP_RADIUS = 3.0
SAVE_FILE = "window_dropped.mvog"
LENGTH = float(os.environ.get("MVOG_WINDOW_METRES", 30.0))  # m driven
STEP = 0.1        # m between scans
CHUNK = 50        # scans between two looks at bytes_held
CORRIDOR = 1.0    # m from the axis to each wall
RANGE_MAX = 2.0
BEAMS = 360
RESOLUTION = 0.1  # mvog_reliability.Server's


def corridor_scan(stamp):
    """A 360-degree scan of the corridor's walls from its axis: returns within RANGE_MAX."""
    ranges = []
    for k in range(BEAMS):
        sine = abs(math.sin(2.0 * math.pi * k / BEAMS))
        distance = CORRIDOR / sine if sine > 1e-9 else math.inf
        ranges.append(distance if distance <= RANGE_MAX else math.inf)
    return rel.scan(ranges, frame="mover", stamp=stamp, range_max=RANGE_MAX)


class Window(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.broadcaster = rel.init_test_node("test_window")
        cls.directory = tempfile.mkdtemp(prefix="mvog_window_")
        cls.window = rel.Server("mapper_window", {
            "keep_radius": KEEP_RADIUS, "robot_frame": "mover", "keep_radius_save_file": SAVE_FILE,
            "publish_period": 0.2, "insertion_queue_size": 100}, directory=cls.directory)
        cls.whole = rel.Server("mapper_whole", {"insertion_queue_size": 100},
                               directory=cls.directory)
        cls.rejoined = rel.Server("mapper_rejoined", directory=cls.directory)
        for server in (cls.window, cls.whole, cls.rejoined):
            server.wait_ready()
        cls.tf = rospy.Publisher("/tf", TFMessage, queue_size=100)
        rel.wait_for(lambda: cls.tf.get_num_connections() >= 3, "the servers to listen to /tf")

    @classmethod
    def tearDownClass(cls):
        alive = all(s.alive() for s in (cls.window, cls.whole, cls.rejoined))
        for server in (cls.window, cls.whole, cls.rejoined):
            server.stop()
        shutil.rmtree(cls.directory, ignore_errors=True)
        assert alive, "a server died"

    def drive(self):
        """Drives the whole corridor; returns bytes_held of (window, whole) every CHUNK scans."""
        figures = []
        scans = int(round(LENGTH / STEP))
        for k in range(scans):
            stamp = rospy.Time.now()
            self.tf.publish(TFMessage([rel.transform("map", "mover", x=k * STEP + 0.05, y=0.05,
                                                     z=rel.LASER_HEIGHT, stamp=stamp)]))
            scan = corridor_scan(stamp)
            self.window.scans.publish(scan)
            self.whole.scans.publish(scan)
            if (k + 1) % CHUNK == 0:
                window = self.window.wait_counter("messages_inserted", k + 1)
                whole = self.whole.wait_counter("messages_inserted", k + 1)
                time.sleep(0.5)  # the window's next look (every ~publish_period)
                figures.append((k + 1, self.window.stats().bytes_held, whole.bytes_held))
            else:
                time.sleep(0.01)
        return figures

    def test_the_window_stays_bounded_and_the_file_holds_what_left_it(self):
        figures = self.drive()
        print("\n| metres driven | bytes_held, window of %.0f m | bytes_held, whole map |\n"
              "|---:|---:|---:|" % KEEP_RADIUS)
        for scans, window, whole in figures:
            print("| %.0f | %d | %d |" % (scans * STEP, window, whole))
        window_bytes = [window for _, window, _ in figures]
        # Once the window has filled (after 10 m), it holds about as much wherever it is (give or
        # take the tile index's buckets and the record of removed tiles), while the whole map
        # grows with the corridor.
        self.assertLess(max(window_bytes[2:]), 1.5 * window_bytes[1], figures)
        self.assertLess(window_bytes[-1], 0.3 * figures[-1][2], figures)
        self.assertGreater(figures[-1][2], 2 * figures[1][2], figures)

        # The robot stands still now: nothing more leaves the window once it has looked again.
        time.sleep(1.0)
        window_data = life.Node(self.window.ns).snapshot()
        _, kept = life.read_map(window_data)
        with open(os.path.join(self.directory, SAVE_FILE), "rb") as f:
            _, dropped = life.read_map(f.read())
        _, whole = life.read_map(life.Node(self.whole.ns).snapshot())
        self.assertGreater(len(dropped), len(kept))
        self.assertFalse(set(kept) & set(dropped), "a cell both in the window and in the file")
        self.assertEqual(kept, {c: whole[c] for c in kept})
        self.assertEqual(dropped, {c: v for c, v in whole.items() if c not in kept})
        # Every cell dropped lies wholly beyond the window's radius from where the robot is.
        end = (LENGTH - STEP + 0.05, 0.05)

        def distance(cell):
            gaps = [max(low - at, 0.0, at - (low + RESOLUTION))
                    for low, at in zip((cell[0] * RESOLUTION, cell[1] * RESOLUTION), end)]
            return math.hypot(*gaps)

        self.assertGreater(min(distance(cell) for cell in dropped), KEEP_RADIUS)

        # Loaded back and merged: the map of the whole trajectory, byte for byte.
        rejoined = life.Node(self.rejoined.ns)
        response = rejoined.merge_map(path=SAVE_FILE)
        self.assertTrue(response.success, response.message)
        response = rejoined.merge_map(data=window_data)
        self.assertTrue(response.success, response.message)
        self.assertEqual(rejoined.snapshot(), life.Node(self.whole.ns).snapshot())


if __name__ == "__main__":
    rostest.rosrun("mvog", "test_window", Window, sys.argv)
