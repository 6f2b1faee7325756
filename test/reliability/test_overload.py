#!/usr/bin/env python3
"""A sensor that outpaces the mapper, with queries running meanwhile (see overload.test).

Clouds of 60,000 points are published at 30 Hz, far faster than a mapper at 5 cm inserts them,
while a client asks ~get_occupancy for 2,000 points ten times a second. Checked: the server stays
up, answers every query, counts whole messages dropped from its insertion queue
(messages_dropped_queue), never counts a message twice, keeps the newest (the last cloud, seen
from elsewhere, is in the map), and says so on /diagnostics: its status is a warning while it
drops messages, and OK again once it no longer does. Printed: how many messages were
inserted, dropped and counted, and lost without being counted (roscpp's own subscriber queue,
~sensor_queue_size long, drops silently), query latencies and the server's RSS. Nothing is
asserted about time.
"""
import sys
import threading
import time
import unittest

import numpy as np
import rospy
import rostest
from diagnostic_msgs.msg import DiagnosticArray, DiagnosticStatus

import mvog_reliability as rel

CLOUDS = 30
POINTS = 60000
RATE = 30.0
QUERY_POINTS = 2000
OCCUPIED = 2


def wall_cloud(seed, behind=False):
    """A bumpy wall 3 m in front of the camera, or a flat one 3 m behind it (float32 x, y, z)."""
    random = np.random.default_rng(seed)
    y = random.uniform(-2.0, 2.0, POINTS)
    z = random.uniform(-1.0, 1.0, POINTS)
    x = np.full(POINTS, -3.0) if behind else 3.0 + 0.2 * np.sin(3.0 * y + seed)
    return rel.cloud([], width=POINTS, data=np.stack([x, y, z], axis=1).astype("<f4").tobytes())


class Overload(unittest.TestCase):
    def test_a_faster_sensor_loses_whole_counted_messages_and_keeps_the_newest(self):
        broadcaster = rel.init_test_node("test_overload")
        server = rel.Server("mapper_overload", {"resolution": 0.05, "insertion_queue_size": 2,
                                                "max_range": 6.0}).wait_ready()
        clouds = [wall_cloud(k) for k in range(4)]
        newest = wall_cloud(99, behind=True)  # behind the camera: only this one maps there
        latencies, failures, rss = [], [], []
        done = threading.Event()
        levels = []  # of the server's status on /diagnostics, in order

        def on_diagnostics(array):
            levels.extend(status.level for status in array.status
                          if status.name == "mapper_overload: mapping")

        rospy.Subscriber("/diagnostics", DiagnosticArray, on_diagnostics)

        def query():
            random = np.random.default_rng(1)
            points = [tuple(p) for p in random.uniform(-4.0, 4.0, (QUERY_POINTS, 3))]
            while not done.is_set():
                start = time.monotonic()
                try:
                    response = server.occupancy(points)
                    if not response.success:
                        failures.append(response.message)
                except (rospy.ServiceException, rospy.ROSException) as e:
                    failures.append(str(e))
                latencies.append(time.monotonic() - start)
                rss.append(rel.rss_kb(server.process.pid))
                time.sleep(0.1)

        querier = threading.Thread(target=query, daemon=True)
        querier.start()
        try:
            for k in range(CLOUDS):
                message = clouds[k % len(clouds)]
                message.header.stamp = rospy.Time.now()
                server.clouds.publish(message)
                time.sleep(1.0 / RATE)
            newest.header.stamp = rospy.Time.now()
            server.clouds.publish(newest)
            published = CLOUDS + 1
            # The newest cloud is mapped eventually: behind the camera, 3 m away.
            behind = [(-3.0, 0.0, 1.0), (-3.0, 1.0, 1.5)]
            rel.wait_for(lambda: list(server.occupancy(behind).state) == [OCCUPIED, OCCUPIED],
                         "the newest cloud in the map", timeout=120.0)
            # Nothing dropped since: the status is OK again.
            seen = len(levels)
            rel.wait_for(lambda: len(levels) > seen and levels[-1] == DiagnosticStatus.OK,
                         "an OK status on /diagnostics once nothing is dropped", timeout=30.0)
        finally:
            done.set()
            querier.join()
        statistics = server.stats()
        counted = (statistics.messages_inserted + statistics.messages_dropped_queue +
                   statistics.messages_dropped_tf + statistics.messages_dropped_invalid)
        alive = server.alive()
        server.stop()
        latencies.sort()
        print("\n%d clouds of %d points at %.0f Hz: %d inserted, %d dropped from the insertion "
              "queue (counted), %d lost uncounted before the mapper saw them; %d queries of %d "
              "points, latency p50 %.3f s, p99 %.3f s, max %.3f s; server RSS max %.0f MB"
              % (published, POINTS, RATE, statistics.messages_inserted,
                 statistics.messages_dropped_queue, published - counted, len(latencies),
                 QUERY_POINTS, latencies[len(latencies) // 2],
                 latencies[min(len(latencies) - 1, int(0.99 * len(latencies)))], latencies[-1],
                 max(rss) / 1024.0))
        self.assertTrue(alive, "the server died")
        self.assertEqual(failures, [])
        self.assertEqual(statistics.messages_dropped_tf, 0)
        self.assertEqual(statistics.messages_dropped_invalid, 0)
        self.assertLessEqual(counted, published, "a message was counted twice")
        self.assertGreater(statistics.messages_inserted, 0)
        if statistics.messages_dropped_queue > 0:
            self.assertIn(DiagnosticStatus.WARN, levels,
                          "messages were dropped, and /diagnostics never warned")


if __name__ == "__main__":
    rostest.rosrun("mvog", "test_overload", Overload, sys.argv)
