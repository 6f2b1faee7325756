"""Shared code of the reliability rostests (test/reliability/*.test).

Each test node starts the mapping servers it needs itself (mvog_node as rosrun finds it, under its
own name, with its own topics, parameters and temporary map directory), feeds them through rospy and
reads their ~statistics and services. Every wait is for a condition, with a generous timeout;
nothing asserts how long anything took.
"""
import functools
import math
import os
import shutil
import signal
import struct
import subprocess
import tempfile
import time

import roslib.packages
import rospy
import tf2_ros
from geometry_msgs.msg import TransformStamped
from sensor_msgs.msg import CameraInfo, Image, LaserScan, PointCloud2, PointField

from mvog.msg import MapStatistics
from mvog.srv import GetOccupancy, MapFile

TIMEOUT = 60.0  # s, for any awaited condition (a loaded CI machine)
FLOAT32, FLOAT64, INT32 = PointField.FLOAT32, PointField.FLOAT64, PointField.INT32
XYZ32 = [("x", 0, FLOAT32), ("y", 4, FLOAT32), ("z", 8, FLOAT32)]
LASER_HEIGHT = 0.5
CAMERA_HEIGHT = 1.0


@functools.lru_cache(maxsize=None)
def mvog_node_path():
    """mvog_node's path in the sourced workspace, found once: through rosrun, every start would
    pay its package lookup again (about half a second)."""
    paths = roslib.packages.find_node("mvog", "mvog_node")
    if not paths:
        raise RuntimeError("mvog_node not found: is the workspace sourced?")
    return paths[0]


def wait_for(condition, what, timeout=TIMEOUT):
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        if condition():
            return
        time.sleep(0.02)
    raise AssertionError("timed out after %.0f s waiting for %s" % (timeout, what))


def wait_for_or_not(condition, timeout):
    """Whether `condition` became true within `timeout` s (no failure: the caller retries)."""
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        if condition():
            return True
        time.sleep(0.02)
    return condition()


def transform(parent, child, x=0.0, y=0.0, z=0.0, yaw=0.0, stamp=None):
    t = TransformStamped()
    t.header.frame_id = parent
    t.header.stamp = stamp if stamp is not None else rospy.Time(0)
    t.child_frame_id = child
    t.transform.translation.x, t.transform.translation.y, t.transform.translation.z = x, y, z
    t.transform.rotation.z = math.sin(yaw / 2.0)
    t.transform.rotation.w = math.cos(yaw / 2.0)
    return t


def init_test_node(name):
    """The test's ROS node, publishing map -> laser (0.5 m up) and map -> camera (1 m up) as
    static transforms; returns the broadcaster, to be kept for as long as they are needed."""
    rospy.init_node(name, disable_signals=True)
    broadcaster = tf2_ros.StaticTransformBroadcaster()
    broadcaster.sendTransform([transform("map", "laser", z=LASER_HEIGHT),
                               transform("map", "camera", z=CAMERA_HEIGHT)])
    return broadcaster


def scan(ranges, frame="laser", stamp=None, angle_min=0.0, angle_increment=None,
         range_min=0.1, range_max=10.0, intensities=()):
    message = LaserScan()
    message.header.frame_id = frame
    message.header.stamp = stamp if stamp is not None else rospy.Time.now()
    message.angle_min = angle_min
    if angle_increment is None:
        angle_increment = 2.0 * math.pi / max(len(ranges), 1)
    message.angle_increment = angle_increment
    message.angle_max = angle_min + angle_increment * max(len(ranges) - 1, 0)
    message.range_min = range_min
    message.range_max = range_max
    message.ranges = list(ranges)
    message.intensities = list(intensities)
    return message


def cloud(points, fields=XYZ32, point_step=12, width=None, height=1, big_endian=False, data=None,
          frame="camera", stamp=None, row_step=None):
    """A PointCloud2 of `points` laid out as `fields` (name, offset, datatype); `data` overrides."""
    message = PointCloud2()
    message.header.frame_id = frame
    message.header.stamp = stamp if stamp is not None else rospy.Time.now()
    message.height = height
    message.width = len(points) // max(height, 1) if width is None else width
    message.point_step = point_step
    if row_step is None:
        row_step = (point_step * message.width) & 0xFFFFFFFF
    message.row_step = row_step
    message.is_bigendian = big_endian
    message.is_dense = False
    message.fields = [PointField(name=n, offset=o, datatype=d, count=1) for n, o, d in fields]
    if data is None:
        order = ">" if big_endian else "<"
        body = bytearray(b"\0" * (point_step * len(points)))
        for k, point in enumerate(points):
            for name, offset, datatype in fields:
                if name in ("x", "y", "z"):
                    code = "d" if datatype == FLOAT64 else "f"
                    struct.pack_into(order + code, body, k * point_step + offset,
                                     point["xyz".index(name)])
        data = bytes(body)
    message.data = data
    return message


def depth_image(depths, width, encoding="32FC1", big_endian=False, step=None, data=None,
                frame="camera", stamp=None):
    """A depth image of `depths` (row after row; millimetres for 16UC1, else metres), its rows
    `step` bytes apart (default: packed); `data` overrides the pixels."""
    message = Image()
    message.header.frame_id = frame
    message.header.stamp = stamp if stamp is not None else rospy.Time.now()
    message.width = width
    message.height = len(depths) // width if width else 0
    message.encoding = encoding
    message.is_bigendian = big_endian
    pixel = 2 if encoding in ("16UC1", "mono16") else 4
    message.step = width * pixel if step is None else step
    if data is None:
        body = bytearray(b"\0" * (message.step * message.height))
        code = (">" if big_endian else "<") + ("H" if pixel == 2 else "f")
        for k, depth in enumerate(depths):
            struct.pack_into(code, body, (k // width) * message.step + (k % width) * pixel, depth)
        data = bytes(body)
    message.data = data
    return message


def camera_info(image, fx=4.0, fy=4.0, cx=None, cy=None, width=None, height=None):
    """The camera info of `image` (same header): K of the focal lengths and principal point
    given (default: the image's centre), for an image of `width` x `height` (default: its own)."""
    message = CameraInfo()
    message.header = image.header
    message.width = image.width if width is None else width
    message.height = image.height if height is None else height
    cx = (image.width - 1) / 2.0 if cx is None else cx
    cy = (image.height - 1) / 2.0 if cy is None else cy
    message.K = [fx, 0.0, cx, 0.0, fy, cy, 0.0, 0.0, 1.0]
    return message


def fnv1a64(data):
    h = 0xcbf29ce484222325
    for b in data:
        h = ((h ^ b) * 0x100000001b3) & 0xFFFFFFFFFFFFFFFF
    return h


def saved_map_bytes(save, directory, name):
    """The bytes of the map saved by save(name) into `directory` (the file is removed)."""
    response = save(name)
    assert response.success, response.message
    path = os.path.join(directory, name)
    with open(path, "rb") as f:
        data = f.read()
    os.unlink(path)
    return data


class Server:
    """One mvog_node started by the test: /NAME, reading /NAME/scan_in, /NAME/cloud_in and the
    depth images of /NAME/depth/image with /NAME/depth/camera_info."""

    DEFAULTS = {"resolution": 0.1, "statistics_period": 0.1, "publish_period": 0.5,
                "binary_map_period": 0.0}

    def __init__(self, name, params=None, directory=None):
        self.name = name
        self.ns = "/" + name
        self.own_directory = directory is None
        self.directory = directory or tempfile.mkdtemp(prefix="mvog_reliability_")
        self.params = dict(self.DEFAULTS, map_directory=self.directory,
                           depth_topics=[self.ns + "/depth/image"], **(params or {}))
        log_fd, self.log_path = tempfile.mkstemp(prefix="mvog_reliability_%s_" % name,
                                                 suffix=".log")
        self.log = os.fdopen(log_fd, "w")
        if rospy.has_param(self.ns):
            rospy.delete_param(self.ns)
        for key, value in self.params.items():
            rospy.set_param(self.ns + "/" + key, value)
        self.statistics = None
        self.statistics_subscriber = rospy.Subscriber(self.ns + "/statistics", MapStatistics,
                                                      self._on_statistics)
        self.scans = rospy.Publisher(self.ns + "/scan_in", LaserScan, queue_size=1000)
        self.clouds = rospy.Publisher(self.ns + "/cloud_in", PointCloud2, queue_size=1000)
        self.depth_images = rospy.Publisher(self.ns + "/depth/image", Image, queue_size=1000)
        self.camera_infos = rospy.Publisher(self.ns + "/depth/camera_info", CameraInfo,
                                            queue_size=1000)
        self.process = subprocess.Popen(
            [mvog_node_path(), "__name:=" + name, "scan:=" + self.ns + "/scan_in",
             "cloud_in:=" + self.ns + "/cloud_in"],
            stdout=self.log, stderr=subprocess.STDOUT)
        self.snapshots = 0

    def _on_statistics(self, message):
        self.statistics = message

    def wait_ready(self):
        """Services up, statistics flowing, and every sensor topic connected."""
        wait_for(lambda: self.process.poll() is None and self.statistics is not None,
                 "%s to publish statistics (log: %s)" % (self.name, self.log_path))
        rospy.wait_for_service(self.ns + "/save_map", timeout=TIMEOUT)
        wait_for(lambda: all(publisher.get_num_connections() > 0 for publisher in
                             (self.scans, self.clouds, self.depth_images, self.camera_infos)),
                 "%s to subscribe" % self.name)
        return self

    def wait_exit(self):
        """The exit status of a server expected to stop by itself."""
        wait_for(lambda: self.process.poll() is not None, "%s to exit" % self.name)
        return self.process.returncode

    def output(self):
        self.log.flush()
        with open(self.log_path) as f:
            return f.read()

    def alive(self):
        return self.process.poll() is None

    def stats(self):
        """Statistics published after this call (every counter moved so far is in them)."""
        stamp = rospy.Time.now()
        wait_for(lambda: self.statistics is not None and self.statistics.header.stamp > stamp,
                 "fresh statistics of %s" % self.name)
        return self.statistics

    def wait_counter(self, field, at_least):
        wait_for(lambda: self.statistics is not None and
                 getattr(self.statistics, field) >= at_least,
                 "%s.%s >= %d (now %s)" % (self.name, field, at_least,
                                          getattr(self.statistics, field, None)))
        return self.stats()

    def service(self, name, service_class):
        return rospy.ServiceProxy(self.ns + "/" + name, service_class)

    def save(self, path):
        return self.service("save_map", MapFile)(path=path)

    def load(self, path):
        return self.service("load_map", MapFile)(path=path)

    def snapshot(self):
        """The current map, as the bytes of a save."""
        self.snapshots += 1
        return saved_map_bytes(self.save, self.directory, "snapshot_%d.mvog" % self.snapshots)

    def occupancy(self, points, frame_id=""):
        from geometry_msgs.msg import Point
        return self.service("get_occupancy", GetOccupancy)(
            frame_id=frame_id, points=[Point(x=p[0], y=p[1], z=p[2]) for p in points])

    def stop(self):
        self.statistics_subscriber.unregister()
        for publisher in (self.scans, self.clouds, self.depth_images, self.camera_infos):
            publisher.unregister()
        if self.process.poll() is None:
            self.process.send_signal(signal.SIGINT)
            try:
                self.process.wait(timeout=20)
            except subprocess.TimeoutExpired:
                self.process.kill()
                self.process.wait()
        self.log.close()
        if self.own_directory:
            shutil.rmtree(self.directory, ignore_errors=True)

    def stop_alive(self):
        """Stops the server; returns whether it was still running until then."""
        alive = self.alive()
        self.stop()
        return alive

    def kill(self):
        """SIGKILL: no shutdown, no cleanup."""
        self.process.kill()
        self.process.wait()


def rss_kb(pid):
    with open("/proc/%d/status" % pid) as f:
        for line in f:
            if line.startswith("VmRSS:"):
                return int(line.split()[1])
    return 0


__all__ = ["Server", "wait_for", "wait_for_or_not", "transform", "init_test_node", "scan", "cloud",
           "depth_image", "camera_info", "fnv1a64", "rss_kb", "FLOAT32", "FLOAT64", "INT32", "XYZ32", "TIMEOUT"]
