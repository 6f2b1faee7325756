#!/usr/bin/env python3
"""~forget_mass on people_stationary.bag looped, with decay on (forgetting.test).

Two servers are fed the same scans on the test's clock: /mvog_forgetting (masses x 0.9 every
second, volumes lighter than ~forget_mass 1.0 removed after each step) and /mvog_keeping (the
same decay, nothing forgotten). The bag is played LOOPS times end to end (each loop's stamps
shifted by the bag's length, the static map -> laser transform holding throughout), then the
room as it was at the bag's end (its last second of scans, in which no one walks: the people
left) for QUIET seconds. Checked: every scan inserted by both; the forgetting server's bytes_held
peaks no higher in the last loop than in the first (bounded), and falls once the people left and
their mass decayed, with its positive volumes, while the keeping server's positive volumes stay;
the walls stay occupied and the space in front of the scanner free in the forgetting map.
"""
import os
import threading
import time

import numpy as np
import rosbag
import rospy
from rosgraph_msgs.msg import Clock
from sensor_msgs.msg import LaserScan
from tf2_msgs.msg import TFMessage

import mvog_data_test as data
from mvog.msg import MapStatistics

BAG = "people_stationary.bag"
FORGETTING, KEEPING = "/mvog_forgetting", "/mvog_keeping"
LOOPS = int(os.environ.get("MVOG_FORGETTING_LOOPS", 2))
QUIET = 30.0           # s of the room without people after the last loop
FINAL_SCANS = 10       # the bag's last second: no return of a person in its last 3 s
WALL_SECONDS_PER_SCAN = 0.01  # 10x the bag's rate, as people_stationary.test plays it


class Series:
    """A server's ~statistics as they come: (stamp, bytes_held, positive_volumes)."""

    def __init__(self, ns):
        self.lock = threading.Lock()
        self.latest = None
        self.points = []
        rospy.Subscriber(ns + "/statistics", MapStatistics, self._receive, queue_size=100)

    def _receive(self, message):
        with self.lock:
            self.latest = message
            self.points.append((message.header.stamp.to_sec(), message.bytes_held,
                                message.positive_volumes))

    def between(self, start, end):
        with self.lock:
            return [p for p in self.points if start <= p[0] < end]

    def at_or_after(self, stamp):
        with self.lock:
            return next((p for p in self.points if p[0] >= stamp), None)


class Forgetting(data.DataTestCase):
    @classmethod
    def setUpClass(cls):
        path = data.require_bag(BAG)
        rospy.init_node("test_forgetting", disable_signals=True)
        with rosbag.Bag(str(path)) as bag:
            scans = [scan for _, scan, _ in data.read_messages(bag, ["/scan"])]
            static = [m for _, m, _ in data.read_messages(bag, ["/tf_static"])]
            buffer = data.tf_buffer(bag)
        cls.pose = data.sensor_pose(buffer, scans[-1].header)
        cls.last_returns = data.scan_points(scans[-1], cls.pose)
        first = scans[0].header.stamp.to_sec()
        since_first = [scan.header.stamp.to_sec() - first for scan in scans]  # play() restamps
        period = since_first[-1] / (len(scans) - 1)
        length = since_first[-1] + period  # one loop, s

        cls.series = {ns: Series(ns) for ns in (FORGETTING, KEEPING)}
        clock = rospy.Publisher("/clock", Clock, queue_size=10)
        tf_static = rospy.Publisher("/tf_static", TFMessage, queue_size=1, latch=True)
        publisher = rospy.Publisher("/scan", LaserScan, queue_size=1000)
        data_deadline = time.time() + 60.0
        while publisher.get_num_connections() < 2 or clock.get_num_connections() < 2:
            assert time.time() < data_deadline, "the servers did not subscribe to /scan"
            time.sleep(0.1)
        clock.publish(Clock(clock=rospy.Time.from_sec(first - 1.0)))
        for message in static:
            tf_static.publish(message)
        time.sleep(1.0)

        def play(message, stamp):
            clock.publish(Clock(clock=rospy.Time.from_sec(stamp)))
            message.header.stamp = rospy.Time.from_sec(stamp)
            publisher.publish(message)
            time.sleep(WALL_SECONDS_PER_SCAN)

        offsets = [first + loop * length for loop in range(LOOPS)]
        cls.loops = [(offset, offset + length) for offset in offsets]
        sent = 0
        start = time.time()
        for offset in offsets:
            for scan, since in zip(scans, since_first):
                play(scan, offset + since)
                sent += 1
        cls.bag_end = offsets[-1] + length
        quiet = scans[-FINAL_SCANS:]
        for k in range(int(round(QUIET / period))):
            play(quiet[k % FINAL_SCANS], cls.bag_end + k * period)
            sent += 1
        cls.end = cls.bag_end + QUIET
        cls.sent = sent
        # The clock on, 0.01 s at a time, until both servers account for every scan (statistics
        # every second of the clock), then the last decay step and its statistics.
        now = cls.end
        deadline = time.time() + 120.0
        while time.time() < deadline:
            now += 0.01
            clock.publish(Clock(clock=rospy.Time.from_sec(now)))
            time.sleep(0.002)
            latest = [cls.series[ns].latest for ns in cls.series]
            if all(s is not None and s.header.stamp.to_sec() > cls.end + 1.5 and
                   s.messages_inserted + s.messages_dropped_tf + s.messages_dropped_queue +
                   s.messages_dropped_invalid >= sent for s in latest):
                break
        cls.now = now
        cls.statistics = {ns: cls.series[ns].latest for ns in cls.series}
        print("%d scans in %.1f s of wall time (%d loops of %.1f s, then %.0f s quiet)"
              % (sent, time.time() - start, LOOPS, length, QUIET))
        for ns, series in cls.series.items():
            for loop, (a, b) in enumerate(cls.loops):
                held = [p[1] for p in series.between(a, b)]
                print("%s loop %d: bytes_held %d..%d, last %d" % (ns, loop + 1, min(held),
                                                                   max(held), held[-1]))
            quiet_points = series.between(cls.bag_end, cls.now + 1.0)
            print("%s quiet: bytes_held %s" % (ns, [p[1] for p in quiet_points]))
            print("%s quiet: positive_volumes %s" % (ns, [p[2] for p in quiet_points]))

    def held(self, ns, start, end):
        return [p[1] for p in self.series[ns].between(start, end)]

    def test_every_scan_inserted(self):
        for ns, s in self.statistics.items():
            self.assertEqual(s.messages_inserted, self.sent, ns)
            self.assertEqual(s.messages_dropped_tf + s.messages_dropped_queue +
                             s.messages_dropped_invalid, 0, ns)

    def test_bytes_held_stay_bounded_from_loop_to_loop(self):
        first = max(self.held(FORGETTING, *self.loops[0]))
        last = max(self.held(FORGETTING, *self.loops[-1]))
        self.assertLessEqual(last, 1.05 * first,
                             "the forgetting server's peak grew from the first loop to the last")

    def test_bytes_fall_after_the_people_left(self):
        # bytes_held at the bag's end (the last statistics of the last loop) against the end of
        # the quiet time, the people's volumes decayed below ~forget_mass meanwhile.
        _, bytes_at_bag_end, positive_at_bag_end = self.series[FORGETTING].between(
            self.loops[-1][0], self.bag_end)[-1]
        final = self.statistics[FORGETTING]
        self.assertLess(final.bytes_held, 0.9 * bytes_at_bag_end,
                        "bytes_held did not fall after the people left")
        self.assertLess(final.positive_volumes, positive_at_bag_end)
        # Without forgetting, decay keeps every volume: nothing falls.
        _, _, kept_at_bag_end = self.series[KEEPING].between(self.loops[-1][0],
                                                             self.bag_end)[-1]
        self.assertGreaterEqual(self.statistics[KEEPING].positive_volumes, kept_at_bag_end)
        self.assertLess(final.bytes_held, self.statistics[KEEPING].bytes_held)

    def test_walls_stay_and_the_scanner_sees_free_space(self):
        # The last scan's returns (walls: nobody in the last seconds) at the scan plane.
        points = data.sample(self.last_returns, 400)
        old = data.MAPPER
        try:
            data.MAPPER = FORGETTING
            self.assertFraction(points, data.OCCUPIED, 0.95, "the last scan's returns")
            origin, forward = self.pose[:3, 3], self.pose[:3, 0]
            self.assertFraction(origin + np.outer([0.2, 0.3, 0.4], forward), data.FREE, 1.0,
                                "in front of the scanner")
        finally:
            data.MAPPER = old


if __name__ == "__main__":
    data.main("forgetting", Forgetting)
