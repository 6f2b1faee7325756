"""Shared code of the rostests of a map's lifetime (test/lifecycle/*.test, and the forgetting
replay of test/data): map files read back into volume lists, a running server or mirror seen
through its services, markers and grids as they were last published, the simulated clock.

Servers the test starts itself are mvog_reliability.Server (test/reliability); the .test files
start the others (mirrors, servers on simulated time).
"""
import math
import os
import struct
import sys
import threading
import time

import rospy
from geometry_msgs.msg import Point, Transform
from nav_msgs.msg import OccupancyGrid
from rosgraph_msgs.msg import Clock as ClockMessage
from visualization_msgs.msg import Marker, MarkerArray

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "reliability"))
import mvog_reliability as rel  # noqa: E402

from mvog.msg import MapBinary  # noqa: E402
from mvog.srv import ClearBox, GetOccupancy, MapFile, MergeMap  # noqa: E402

UNKNOWN, FREE, OCCUPIED = 0, 1, 2


# ---- Map files (include/mvog/map_io.h) -------------------------------------------------------

def read_map(data):
    """The header fields and the cells of a map file: {(x, y): (positive, negative)}, each list
    of (bottom, top, mass) as float32 values, heights in grid units."""
    header = dict(zip(("resolution", "max_coordinate", "cells", "volumes", "rules"),
                      struct.unpack_from("<ddQQI", data, 16)))
    cells, offset = {}, 64
    for _ in range(header["cells"]):
        x, y, positive, negative = struct.unpack_from("<iiII", data, offset)
        offset += 16
        volumes = [struct.unpack_from("<fff", data, offset + 12 * k)
                   for k in range(positive + negative)]
        offset += 12 * (positive + negative)
        cells[(x, y)] = (volumes[:positive], volumes[positive:])
    return header, cells


def with_checksum(body):
    """Map bytes (without their checksum) followed by a valid one: a header patched on purpose."""
    return bytes(body) + struct.pack("<Q", rel.fnv1a64(bytes(body)))


def patched_header(data, offset, fmt, value):
    """A valid map file like `data` but for one header field."""
    body = bytearray(data[:-8])
    struct.pack_into(fmt, body, offset, value)
    return with_checksum(body)


# ---- Requests ----------------------------------------------------------------------------------

def point(x, y, z):
    return Point(x=x, y=y, z=z)


def transform(x=0.0, y=0.0, z=0.0, yaw=0.0, quaternion=None):
    """A geometry_msgs/Transform: a translation and a yaw (radians), or a quaternion (x, y, z, w)
    as given."""
    t = Transform()
    t.translation.x, t.translation.y, t.translation.z = x, y, z
    q = quaternion or (0.0, 0.0, math.sin(yaw / 2.0), math.cos(yaw / 2.0))
    t.rotation.x, t.rotation.y, t.rotation.z, t.rotation.w = q
    return t


IDENTITY = transform()


class Node:
    """A running server or mirror at namespace `ns` (e.g. /robot/mvog_mirror), seen through its
    services; files in its ~map_directory."""

    def __init__(self, ns):
        self.ns = ns
        rospy.wait_for_service(ns + "/save_map", timeout=rel.TIMEOUT)
        self.directory = rospy.get_param(ns + "/map_directory")

    def call(self, service, service_class, **request):
        rospy.wait_for_service(self.ns + "/" + service, timeout=rel.TIMEOUT)
        return rospy.ServiceProxy(self.ns + "/" + service, service_class)(**request)

    def snapshot(self):
        """The bytes of a save of the map now."""
        return rel.saved_map_bytes(lambda name: self.call("save_map", MapFile, path=name),
                                   self.directory,
                                   "snapshot_%s.mvog" % self.ns.strip("/").replace("/", "_"))

    def states(self, points):
        response = self.call("get_occupancy", GetOccupancy, frame_id="",
                             points=[point(*p) for p in points])
        assert response.success, response.message
        return list(response.state)

    def clear_box(self, min_corner, max_corner, frame_id=""):
        return self.call("clear_box", ClearBox, frame_id=frame_id,
                         min_corner=point(*min_corner), max_corner=point(*max_corner))

    def merge_map(self, path="", data=b"", map_from_other=IDENTITY):
        return self.call("merge_map", MergeMap, path=path, map=MapBinary(data=data),
                         map_from_other=map_from_other)


# ---- What a server publishes -------------------------------------------------------------------

class MarkerState:
    """The markers of a MarkerArray topic as a display would hold them: by (ns, id), after every
    ADD, DELETE and DELETEALL received."""

    def __init__(self, topic):
        self.lock = threading.Lock()
        self.markers = {}
        self.messages = 0
        self.subscriber = rospy.Subscriber(topic, MarkerArray, self._receive)

    def _receive(self, array):
        with self.lock:
            for marker in array.markers:
                if marker.action == Marker.DELETEALL:
                    self.markers.clear()
                elif marker.action == Marker.DELETE:
                    self.markers.pop((marker.ns, marker.id), None)
                else:
                    self.markers[(marker.ns, marker.id)] = marker
            self.messages += 1

    def points(self):
        """Every vertex of every marker held, (x, y, z)."""
        with self.lock:
            return [(p.x, p.y, p.z) for m in self.markers.values() for p in m.points]


class LatestGrid:
    """The latest nav_msgs/OccupancyGrid of a topic."""

    def __init__(self, topic):
        self.grid = None
        self.messages = 0
        self.subscriber = rospy.Subscriber(topic, OccupancyGrid, self._receive)

    def _receive(self, grid):
        self.grid = grid
        self.messages += 1

    def value_at(self, x, y):
        """The value of the cell holding (x, y), or None outside the grid."""
        info = self.grid.info
        i = int(math.floor((x - info.origin.position.x) / info.resolution))
        j = int(math.floor((y - info.origin.position.y) / info.resolution))
        if not (0 <= i < info.width and 0 <= j < info.height):
            return None
        return self.grid.data[j * info.width + i]


# ---- Simulated time ----------------------------------------------------------------------------

class SimClock:
    """/clock, set by the test: the servers' timers (decay, publications) run when it moves."""

    def __init__(self, start):
        self.time = start
        self.publisher = rospy.Publisher("/clock", ClockMessage, queue_size=10)
        rel.wait_for(lambda: self.publisher.get_num_connections() > 0, "/clock subscribers")
        self.publish()

    def now(self):
        return rospy.Time.from_sec(self.time)

    def publish(self):
        self.publisher.publish(ClockMessage(clock=self.now()))

    def advance(self, seconds, step=0.01, wall_per_step=0.002):
        """Moves the clock on by `seconds`, `step` at a time (every timer on the way fires)."""
        for _ in range(int(round(seconds / step))):
            self.time += step
            self.publish()
            time.sleep(wall_per_step)

