#!/usr/bin/env python3
"""Mirrors follow a server's map bit for bit, and repair a dropped update (see mirror.test).

The test is the clock (simulated time) and the sensor: a laser 0.5 m up drives 12 m down a
corridor, one 360-degree scan every 0.1 s, past the server /robot/mvog_mapper, whose map decays
(x 0.8 every second), forgets what falls below 0.3, keeps 4 m around the latest scan and has a
box cleared behind it at the end: every kind of change, tiles modified and removed. Three mirrors follow it:
/robot/mvog_mirror on the server's ~map_updates, /lossy/mvog_mirror on a relay of them that drops
one update with changes in it (no later update applies without it: the mirror must detect the gap
and ask the server, ~get_map_update), and /chained/mvog_mirror, a nodelet mirroring the first
mirror. Once the clock holds still, every mirror's saved map must be the server's byte for byte,
and the mirrors answer queries and show markers as the server does.
"""
import math
import sys
import threading
import time
import unittest

import rospy
import rostest
from tf2_msgs.msg import TFMessage
from sensor_msgs.msg import LaserScan

import mvog_lifecycle as life
from mvog_lifecycle import rel
from mvog.msg import MapStatistics, MapUpdate

SERVER = "/robot/mvog_mapper"
MIRRORS = ["/robot/mvog_mirror", "/lossy/mvog_mirror", "/chained/mvog_mirror"]
SCANS = 120
STEP = 0.1            # m and s between scans
DROPPED_UPDATE = 12   # the relay drops the 12th incremental update that changes tiles
CLEARED = ((8.0, -1.6, -10.0), (9.6, 1.6, 10.0))  # m, behind the robot once it stops
KEEP_RADIUS = 4.0  # the server's
TILE = 1.6         # m, 16 cells of 0.1 m
BEAMS = 360


def scan(stamp, k):
    """A corridor 1 m either side, with a pillar every 2 m on the left: returns within 2 m."""
    ranges = []
    x = k * STEP
    for beam in range(BEAMS):
        angle = 2.0 * math.pi * beam / BEAMS
        sine = math.sin(angle)
        wall = 1.0 / abs(sine) if abs(sine) > 1e-3 else math.inf
        if sine > 1e-3 and int((x + wall * math.cos(angle)) / 2.0) % 2 == 0:
            wall *= 0.8  # the pillars
        ranges.append(wall if wall <= 2.0 else math.inf)
    return rel.scan(ranges, frame="laser", stamp=stamp, range_max=2.0)


class Relay:
    """Passes the server's updates on to /lossy/relayed_updates but one."""

    def __init__(self):
        self.lock = threading.Lock()
        self.incremental_with_changes = 0
        self.dropped = None
        self.removed_tiles = 0
        self.publisher = rospy.Publisher("/lossy/relayed_updates", MapUpdate, queue_size=100)
        self.subscriber = rospy.Subscriber(SERVER + "/map_updates", MapUpdate, self._receive,
                                           queue_size=100)

    def _receive(self, update):
        with self.lock:
            self.removed_tiles += update.tiles_removed
            if not update.full and update.tiles_changed > 0:
                self.incremental_with_changes += 1
                if self.incremental_with_changes == DROPPED_UPDATE:
                    self.dropped = update
                    return
        self.publisher.publish(update)


class Mirror(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        rospy.init_node("test_mirror", disable_signals=True)
        cls.clock = life.SimClock(100.0)
        cls.server = life.Node(SERVER)
        cls.mirrors = [life.Node(ns) for ns in MIRRORS]
        cls.statistics = None
        rospy.Subscriber(SERVER + "/statistics", MapStatistics, cls._on_statistics)
        cls.relay = Relay()
        cls.scans = rospy.Publisher("/robot/scan", LaserScan, queue_size=SCANS)
        cls.tf = rospy.Publisher("/tf", TFMessage, queue_size=100)
        rel.wait_for(lambda: cls.scans.get_num_connections() > 0 and
                     cls.tf.get_num_connections() >= 4 and
                     cls.relay.publisher.get_num_connections() > 0 and
                     cls.relay.subscriber.get_num_connections() > 0, "the nodes to connect")

    @classmethod
    def _on_statistics(cls, message):
        cls.statistics = message

    def advance_until(self, condition, what, seconds=60.0):
        """Moves the clock on, 0.05 s at a time, until `condition` holds."""
        deadline = time.monotonic() + rel.TIMEOUT
        while not condition():
            self.assertLess(time.monotonic(), deadline, "timed out waiting for " + what)
            self.clock.advance(0.05)
            time.sleep(0.01)

    def mapped(self, count):
        return lambda: (self.statistics is not None and
                        self.statistics.messages_inserted >= count)

    def test_every_mirror_is_the_server_byte_for_byte(self):
        markers = {ns: life.MarkerState(ns + "/occupied") for ns in [SERVER, MIRRORS[0]]}
        for k in range(SCANS):
            stamp = self.clock.now()
            self.tf.publish(TFMessage([rel.transform("map", "laser", x=k * STEP + 0.05, y=0.05,
                                                     z=rel.LASER_HEIGHT, stamp=stamp)]))
            self.scans.publish(scan(stamp, k))
            self.advance_until(self.mapped(k + 1), "scan %d to be inserted" % (k + 1))
        response = self.server.clear_box(*CLEARED)
        self.assertTrue(response.success, response.message)
        self.assertGreater(response.cells_changed, 0)
        self.assertEqual(self.statistics.messages_dropped_tf + self.statistics.messages_dropped_queue,
                         0)
        self.assertIsNotNone(self.relay.dropped, "no update was dropped: too few updates")
        self.assertGreater(self.relay.removed_tiles, 0, "no update removed tiles")

        # Hold the clock still (no decay step, no publication): the mirrors must come to hold
        # exactly the server's map. A decay step may fall between the last update and the
        # hold: then the next hold, 0.3 s later, brings it.
        for attempt in range(8):
            self.clock.advance(0.3)
            reference = self.server.snapshot()
            if rel.wait_for_or_not(lambda: all(m.snapshot() == reference for m in self.mirrors),
                                   10.0):
                break
        differing = [m.ns for m in self.mirrors if m.snapshot() != reference]
        self.assertEqual(differing, [], "mirrors whose map is not the server's")
        print("the server's map, %d bytes, mirrored after %d hold(s); update %d -> %d dropped"
              % (len(reference), attempt + 1, self.relay.dropped.from_revision,
                 self.relay.dropped.to_revision))

        # They answer as the server, and show what it shows: nothing in the box cleared, nothing
        # of the tiles the window dropped.
        points = [(0.1 * i + 0.05, 0.1 * j + 0.05, rel.LASER_HEIGHT)
                  for i in range(0, SCANS, 5) for j in range(-12, 13)]
        answers = self.server.states(points)
        self.assertIn(life.OCCUPIED, answers)
        for mirror in self.mirrors:
            self.assertEqual(mirror.states(points), answers, mirror.ns)
        self.clock.advance(0.3)  # markers are published on the clock
        rel.wait_for(lambda: sorted(markers[MIRRORS[0]].points()) ==
                     sorted(markers[SERVER].points()), "the mirror's markers to be the server's")
        shown = markers[MIRRORS[0]].points()
        self.assertTrue(shown)
        (x0, y0, _), (x1, y1, _) = CLEARED
        self.assertFalse([p for p in shown if x0 < p[0] < x1 and y0 < p[1] < y1],
                         "markers in the box cleared")
        window_starts = (SCANS - 1) * STEP - KEEP_RADIUS - TILE
        self.assertFalse([p for p in shown if p[0] < window_starts],
                         "markers of tiles the window dropped")

if __name__ == "__main__":
    rostest.rosrun("mvog", "test_mirror", Mirror, sys.argv)
