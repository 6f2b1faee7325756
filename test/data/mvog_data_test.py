"""Shared code of the rostests that replay the recordings of $MVOG_DATA_DIR through mapper.launch.

Each test node (test_*.py beside this file) reads its bag with the rosbag API to work out what
the map must say (sensor poses from a tf2 Buffer filled with the bag's /tf and /tf_static, the
readings projected into the map frame), replays the bag with `rosbag play --clock` against the
mapping server that its .test file started, waits until the server has taken every message, and
then asks ~get_occupancy and ~statistics.

Data: $MVOG_DATA_DIR (scripts/common.sh exports it), else <repo>/../shared/data. Without it the
tests skip, unless CI=true, where a missing bag is a failure. Nothing is copied into the repo.
"""
import os
import signal
import subprocess
import sys
import threading
import time
import unittest
import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np
import rosbag
import rospy
import rostest
import tf2_ros
from geometry_msgs.msg import Point
from rosgraph_msgs.msg import Clock
from sensor_msgs.msg import LaserScan, PointCloud2
from tf2_msgs.msg import TFMessage

from mvog.msg import MapStatistics
from mvog.srv import GetOccupancy, GetOccupancyRequest

UNKNOWN, FREE, OCCUPIED = (GetOccupancy._response_class.UNKNOWN,
                           GetOccupancy._response_class.FREE,
                           GetOccupancy._response_class.OCCUPIED)
STATE_NAMES = {UNKNOWN: "unknown", FREE: "free", OCCUPIED: "occupied"}
MAPPER = "/mvog_mapper"
REPO = Path(__file__).resolve().parents[2]


# ---- Data directory ------------------------------------------------------------------------

def data_dir():
    return Path(os.environ.get("MVOG_DATA_DIR") or REPO.parent / "shared" / "data")


def require_bag(name):
    """The bag's path; skips the test class without it (fails instead when CI=true)."""
    path = data_dir() / name
    if path.is_file():
        return path
    message = ("%s not found: set MVOG_DATA_DIR to the directory of the recordings "
               "(default <repo>/../shared/data)" % path)
    if os.environ.get("CI", "").lower() == "true":
        raise AssertionError("CI=true and " + message)
    global _skip_reason
    _skip_reason = message
    sys.__stderr__.write("\nSKIPPED %s: %s\n" % (name, message))
    raise unittest.SkipTest(message)


_skip_reason = None
XML_OUTPUT_FLAG = "--gtest_output=xml:"


def main(test_name, test_class):
    """rostest.rosrun, and then, if the data was missing, the result file marks every test as
    skipped: rosunit's XML runner would report them as passed (it ignores skips), while
    catkin_test_results and scripts/test.sh count the `skipped` attribute."""
    result_file = next((arg[len(XML_OUTPUT_FLAG):] for arg in sys.argv
                        if arg.startswith(XML_OUTPUT_FLAG)), None)
    rostest.rosrun("mvog", test_name, test_class)
    if _skip_reason is not None and result_file and os.path.isfile(result_file):
        names = unittest.TestLoader().getTestCaseNames(test_class)
        suite = ET.Element("testsuite", name=test_name, tests=str(len(names)), errors="0",
                           failures="0", skipped=str(len(names)), time="0")
        for name in names:
            case = ET.SubElement(suite, "testcase", classname=test_class.__name__, name=name,
                                 time="0")
            ET.SubElement(case, "skipped", message=_skip_reason)
        ET.ElementTree(suite).write(result_file, encoding="utf-8", xml_declaration=True)


# ---- Reading the bag -----------------------------------------------------------------------

def read_messages(bag, topics):
    """(topic, message, bag time) with the messages deserialised into this process's classes
    (rosbag's own generated classes upset tf2_ros' type checks)."""
    classes = {"sensor_msgs/LaserScan": LaserScan, "sensor_msgs/PointCloud2": PointCloud2,
               "tf2_msgs/TFMessage": TFMessage}
    for topic, raw, stamp in bag.read_messages(topics=topics, raw=True):
        message = classes[raw[0]]()
        message.deserialize(raw[1])
        yield topic, message, stamp


def tf_buffer(bag):
    """A Buffer holding every transform of the bag (no cache expiry)."""
    buffer = tf2_ros.Buffer(cache_time=rospy.Duration(1e6), debug=False)
    for topic, message, _ in read_messages(bag, ["/tf", "/tf_static"]):
        for transform in message.transforms:
            if topic == "/tf_static":
                buffer.set_transform_static(transform, "bag")
            else:
                buffer.set_transform(transform, "bag")
    return buffer


def to_matrix(transform):
    """4x4 homogeneous matrix of a geometry_msgs/TransformStamped."""
    q = transform.transform.rotation
    t = transform.transform.translation
    x, y, z, w = q.x, q.y, q.z, q.w
    m = np.eye(4)
    m[:3, :3] = [[1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
                 [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
                 [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)]]
    m[:3, 3] = [t.x, t.y, t.z]
    return m


def sensor_pose(buffer, header, frame="map"):
    return to_matrix(buffer.lookup_transform(frame, header.frame_id, header.stamp))


def transform_points(pose, points):
    return points @ pose[:3, :3].T + pose[:3, 3]


def scan_beams(scan):
    """Ranges, angles and the valid mask (finite, within [range_min, range_max]) of a scan."""
    ranges = np.asarray(scan.ranges, dtype=np.float64)
    angles = scan.angle_min + np.arange(len(ranges)) * scan.angle_increment
    with np.errstate(invalid="ignore"):
        valid = np.isfinite(ranges) & (ranges >= scan.range_min) & (ranges <= scan.range_max)
    return ranges, angles, valid


def scan_points(scan, pose):
    """Valid returns of a LaserScan in the map frame."""
    ranges, angles, valid = scan_beams(scan)
    ranges, angles = ranges[valid], angles[valid]
    local = np.stack([ranges * np.cos(angles), ranges * np.sin(angles),
                      np.zeros_like(ranges)], axis=1)
    return transform_points(pose, local)


def cloud_xyz(cloud):
    """(N, 3) float64 array of a PointCloud2's x, y, z (float32 fields)."""
    offsets = {f.name: f.offset for f in cloud.fields}
    data = np.frombuffer(cloud.data, dtype=np.uint8).reshape(-1, cloud.point_step)
    columns = [data[:, offsets[a]:offsets[a] + 4].copy().view("<f4")[:, 0] for a in "xyz"]
    return np.stack(columns, axis=1).astype(np.float64)


# ---- Cells ---------------------------------------------------------------------------------

def cell_keys(xy, resolution):
    """Integer cell indices (i, j) of points, as in Sec. III-A: i <= x / res < i + 1."""
    return np.floor(np.asarray(xy)[:, :2] / resolution).astype(np.int64)


def cell_centres(keys, resolution):
    return (np.asarray(keys, dtype=np.float64) + 0.5) * resolution


def sample(points, count, seed=0):
    """At most `count` of the rows, chosen reproducibly."""
    points = np.asarray(points)
    if len(points) <= count:
        return points
    return points[np.random.default_rng(seed).choice(len(points), count, replace=False)]


# ---- The server under test -----------------------------------------------------------------

class Replay:
    """Plays a bag into the running mapping server and waits until it has handled every message.

    After the bag ends the simulated clock stops, and with it the server's timers (statistics,
    decay). This class then keeps publishing /clock, continuing from the bag's end, so that the
    server publishes fresh ~statistics.
    """

    def __init__(self, bag_path, rate, sensor_messages, play_timeout=90.0):
        self.bag_path = Path(bag_path)
        self.rate = rate
        self.sensor_messages = sensor_messages
        self.play_timeout = play_timeout
        self.statistics = None
        self.statistics_count = 0
        self.wall_seconds = None
        self._lock = threading.Lock()

    def _on_statistics(self, message):
        with self._lock:
            self.statistics = message
            self.statistics_count += 1

    def run(self):
        rospy.wait_for_service(MAPPER + "/get_occupancy", timeout=60.0)
        rospy.Subscriber(MAPPER + "/statistics", MapStatistics, self._on_statistics)
        with rosbag.Bag(str(self.bag_path)) as bag:
            end = bag.get_end_time()
        command = ["rosbag", "play", "--clock", "-q", "--wait-for-subscribers",
                   "-r", str(self.rate), str(self.bag_path)]
        start = time.time()
        player = subprocess.Popen(command, stdin=subprocess.DEVNULL, stdout=subprocess.PIPE,
                                  stderr=subprocess.STDOUT, start_new_session=True)
        try:
            output, _ = player.communicate(timeout=self.play_timeout)
        except subprocess.TimeoutExpired:
            os.killpg(player.pid, signal.SIGINT)
            output, _ = player.communicate()
            raise AssertionError("rosbag play did not finish within %.0f s:\n%s"
                                 % (self.play_timeout, output.decode(errors="replace")))
        if player.returncode != 0:
            raise AssertionError("rosbag play failed (%d):\n%s"
                                 % (player.returncode, output.decode(errors="replace")))
        self.wall_seconds = time.time() - start
        self._drain(end)
        print("rosbag play -r %g took %.1f s, the server's statistics settled after %.1f s"
              % (self.rate, self.wall_seconds, time.time() - start))
        return self.statistics

    def _drain(self, bag_end, timeout=90.0, settle_messages=8, settle_seconds=5.0):
        """Advances the clock past the bag's end until the statistics account for every sensor
        message (inserted, or dropped for a reason they count). Messages lost without a count
        would keep that from happening: then it waits until the counts have not changed over
        `settle_messages` fresh statistics and `settle_seconds` of wall time (the insertion
        thread may be starved on a loaded machine), or until `timeout`, and leaves the
        discrepancy to the tests' assertions."""
        clock = rospy.Publisher("/clock", Clock, queue_size=10)
        now = bag_end
        deadline = time.time() + timeout
        last_key, last_change, unchanged = None, time.time(), 0
        seen = self.statistics_count
        while time.time() < deadline:
            now += 0.05
            clock.publish(Clock(clock=rospy.Time.from_sec(now)))
            time.sleep(0.01)
            with self._lock:
                statistics, count = self.statistics, self.statistics_count
            if statistics is None or statistics.header.stamp.to_sec() <= bag_end or count == seen:
                continue
            seen = count
            key = (statistics.messages_inserted, statistics.messages_dropped_tf,
                   statistics.messages_dropped_queue, statistics.messages_dropped_invalid,
                   statistics.readings_inserted)
            if key != last_key:
                last_key, last_change, unchanged = key, time.time(), 0
            else:
                unchanged += 1
            if sum(key[:4]) >= self.sensor_messages and unchanged >= 1:
                return
            if unchanged >= settle_messages and time.time() - last_change > settle_seconds:
                return
        if last_key is None:
            raise AssertionError("no fresh statistics from %s/statistics within %.0f s"
                                 % (MAPPER, timeout))


def query(points, frame_id=""):
    """States and probabilities of the map at points (N, 3)."""
    points = np.asarray(points, dtype=np.float64).reshape(-1, 3)
    request = GetOccupancyRequest(frame_id=frame_id,
                                  points=[Point(*map(float, p)) for p in points])
    response = rospy.ServiceProxy(MAPPER + "/get_occupancy", GetOccupancy)(request)
    if not response.success:
        raise AssertionError("get_occupancy failed: " + response.message)
    return np.frombuffer(bytes(response.state), dtype=np.uint8).copy(), np.asarray(
        response.probability, dtype=np.float64)


def describe(points, states, wanted, limit=5):
    """A few of the points whose state is not `wanted`, for assertion messages."""
    wrong = np.flatnonzero(states != wanted)[:limit]
    return ", ".join("(%.2f, %.2f, %.2f): %s" % (*points[k], STATE_NAMES[states[k]])
                     for k in wrong)


class DataTestCase(unittest.TestCase):
    """Helpers for assertions on the replay's statistics and on fractions of sampled points."""

    def assertEveryMessageInserted(self, statistics, messages, what, rate):
        """Each of the bag's `messages` sensor messages (`what`: "scans", "clouds") replayed at
        `rate` was inserted: none dropped, and none lost without being counted."""
        s = statistics
        self.assertEqual(s.messages_inserted + s.messages_dropped_tf + s.messages_dropped_queue
                         + s.messages_dropped_invalid, messages,
                         "%s lost without being counted" % what)
        self.assertEqual(s.messages_dropped_tf, 0,
                         "%s dropped for want of a transform (at -r %g the server's 10 s tf cache "
                         "lasts %.2f s)" % (what, rate, 10.0 / rate))
        self.assertEqual(s.messages_dropped_invalid, 0, "%s refused as malformed" % what)
        self.assertEqual(s.messages_dropped_queue, 0,
                         "the insertion queue dropped %s at -r %g: the replay outpaced the mapper"
                         % (what, rate))
        self.assertEqual(s.messages_inserted, messages)

    def assertFraction(self, points, wanted, minimum, what):
        points = np.asarray(points, dtype=np.float64).reshape(-1, 3)
        self.assertGreater(len(points), 0, "no points to check for " + what)
        states, _ = query(points)
        fraction = float(np.mean(states == wanted))
        counts = {STATE_NAMES[s]: int(np.sum(states == s)) for s in STATE_NAMES}
        print("%s: %.1f %% %s of %d points %s" % (what, 100 * fraction, STATE_NAMES[wanted],
                                                   len(points), counts))
        self.assertGreaterEqual(
            fraction, minimum,
            "%s: only %.1f %% of %d points are %s (want >= %.0f %%); counts %s; e.g. %s"
            % (what, 100 * fraction, len(points), STATE_NAMES[wanted], 100 * minimum, counts,
               describe(points, states, wanted)))
        return states


class CloudReplayTest(DataTestCase):
    """A bag of PointCloud2 messages (depth camera, 3D laser) replayed into the server.

    Subclasses set BAG, TOPIC, RATE, README_MESSAGES, README_POINTS, README_FRAME (the clouds'
    frame_id), README_FLOOR (the floor's
    height in the map frame, from the data README), NEAR_RANGE (returns closer than this are
    left out of the occupancy checks: robot self-hits) and the fractions the checks demand
    (explained there).
    """
    BAG = TOPIC = None
    RATE = 1.0
    README_MESSAGES = README_POINTS = 0
    README_FRAME = None
    README_FLOOR = 0.0
    NEAR_RANGE = 0.0
    RETURNS_OCCUPIED = RETURNS_NEAR_OCCUPIED = FLOOR_OCCUPIED = FLOOR_NEAR_OCCUPIED = 1.0
    BEHIND_UNKNOWN = 1.0

    @classmethod
    def setUpClass(cls):
        path = require_bag(cls.BAG)
        rospy.init_node("test_" + Path(cls.BAG).stem, disable_signals=True)
        parameter = lambda name: rospy.get_param(MAPPER + "/" + name)
        cls.resolution = parameter("resolution")
        cls.min_range, cls.max_range = parameter("min_range"), parameter("max_range")
        cls.insert_out_of_range = parameter("insert_out_of_range")
        cls.voxel_filter_size = rospy.get_param(MAPPER + "/voxel_filter_size", 0.0)
        cls.poses, cls.points, cls.ranges, cls.frames = [], [], [], set()
        with rosbag.Bag(str(path)) as bag:
            buffer = tf_buffer(bag)
            for _, cloud, _ in read_messages(bag, [cls.TOPIC]):
                pose = sensor_pose(buffer, cloud.header)
                local = cloud_xyz(cloud)
                cls.poses.append(pose)
                cls.points.append(transform_points(pose, local))
                cls.ranges.append(np.linalg.norm(local, axis=1))
                cls.frames.add(cloud.header.frame_id)
        all_ranges = np.concatenate(cls.ranges)
        # What the server inserts: returns from min_range to max_range as obstacles, further
        # ones as free space up to max_range (~insert_out_of_range), nearer ones not at all.
        with np.errstate(invalid="ignore"):
            cls.expected_inserted = int(np.sum((all_ranges >= cls.min_range)
                                               & (all_ranges <= cls.max_range)))
            if cls.insert_out_of_range:
                cls.expected_inserted += int(np.sum(all_ranges > cls.max_range))
        # The floor: the 5th percentile of the returns' heights.
        cls.floor = float(np.percentile(np.concatenate(cls.points)[:, 2], 5))

        cls.statistics = Replay(path, cls.RATE, len(cls.poses)).run()
        print("floor at z = %.3f m; statistics after the replay:\n%s" % (cls.floor, cls.statistics))

    def returns(self, count, seed=0, select=None):
        """A sample of `count` returns the server inserted as obstacles (within max_range), not
        closer than NEAR_RANGE, optionally only where select(points, ranges) holds."""
        chosen = []
        for points, ranges in zip(self.points, self.ranges):
            keep = (ranges >= max(self.min_range, self.NEAR_RANGE)) & (
                ranges <= self.max_range - self.resolution)
            if select is not None:
                keep &= select(points, ranges)
            chosen.append(points[keep])
        return sample(np.concatenate(chosen), count, seed)

    def along_rays(self, count, distance, min_range, seed=0):
        """Points `distance` along a sample of rays whose return is at least min_range away."""
        chosen = []
        for pose, points, ranges in zip(self.poses, self.points, self.ranges):
            keep = ranges >= min_range
            origin = pose[:3, 3]
            rays = sample(points[keep], count // len(self.poses), seed)
            direction = (rays - origin) / np.linalg.norm(rays - origin, axis=1)[:, None]
            chosen.append(origin + distance * direction)
        return np.concatenate(chosen)

    def neighbourhood_fraction(self, points):
        """Fraction of the points with an occupied cell within one cell in x, y and z."""
        offsets = np.array([(dx, dy, dz) for dx in (-1, 0, 1) for dy in (-1, 0, 1)
                            for dz in (-1, 0, 1)], dtype=np.float64)
        states = query((points[:, None, :] + self.resolution * offsets).reshape(-1, 3))[0]
        return float(np.mean(np.any(states.reshape(len(points), -1) == OCCUPIED, axis=1)))

    def test_bag_matches_readme(self):
        self.assertEqual(len(self.poses), self.README_MESSAGES)
        self.assertEqual(sum(len(p) for p in self.points), self.README_POINTS)
        self.assertEqual(self.frames, {self.README_FRAME})
        self.assertAlmostEqual(self.floor, self.README_FLOOR, delta=0.05)

    def test_statistics_count_every_message_and_reading(self):
        s = self.statistics
        # README: every cloud transformable to map.
        self.assertEveryMessageInserted(s, self.README_MESSAGES, "clouds", self.RATE)
        if self.voxel_filter_size == 0.0:
            self.assertEqual(s.readings_inserted, self.expected_inserted)
            self.assertEqual(s.readings_inserted + s.readings_rejected, self.README_POINTS)
        else:  # the voxel filter thins the clouds before insertion
            self.assertGreater(s.readings_inserted, 0)

    def floor_returns(self, count):
        """Returns within 5 cm of the floor's height."""
        return self.returns(count, select=lambda p, r: np.abs(p[:, 2] - self.floor) < 0.05)

    def test_returns_are_occupied(self):
        # 3000 returns within max_range, queried where they fell: in their own cell, and with an
        # occupied cell within one cell in x, y and z (see the subclass for the fractions).
        points = self.returns(3000)
        self.assertFraction(points, OCCUPIED, self.RETURNS_OCCUPIED, "returns within max_range")
        near = self.neighbourhood_fraction(points)
        print("returns within max_range: %.1f %% within one cell of an occupied cell"
              % (100 * near))
        self.assertGreaterEqual(near, self.RETURNS_NEAR_OCCUPIED,
                                "returns with no occupied cell within one cell")

    def test_floor_is_occupied_at_its_height(self):
        points = self.floor_returns(2000)
        self.assertFraction(points, OCCUPIED, self.FLOOR_OCCUPIED, "floor returns")
        near = self.neighbourhood_fraction(points)
        print("floor returns: %.1f %% within one cell of an occupied cell" % (100 * near))
        self.assertGreaterEqual(near, self.FLOOR_NEAR_OCCUPIED,
                                "floor returns with no occupied cell within one cell")

    def test_below_the_floor_is_unknown(self):
        # No ray goes below the floor: 1 m under floor returns nothing is known.
        points = self.floor_returns(2000)
        points[:, 2] = self.floor - 1.0
        self.assertFraction(points, UNKNOWN, 0.99, "1 m below the floor")

    def test_along_the_rays_is_free(self):
        # 0.6 m from the sensor along rays whose return is at least 1.5 m away: space the sensor
        # saw through in every frame, around its whole path (clear of the robot: the rays pass
        # there). Rasterisation (Sec. V.B) could at most touch a few cells.
        points = self.along_rays(3000, 0.6, 1.5)
        self.assertFraction(points, FREE, 0.98, "0.6 m along the rays")

    def test_behind_surfaces_is_unknown(self):
        # 1 m behind returns above the floor (and 1 m inside max_range), along their ray: hidden
        # from that view. Other views see behind some of them (objects in the room, not walls),
        # so the subclass demands a fraction.
        chosen = []
        for pose, points, ranges in zip(self.poses, self.points, self.ranges):
            keep = (ranges < self.max_range - 1.0) & (ranges >= self.NEAR_RANGE) & (
                points[:, 2] > self.floor + 0.3)
            ends = sample(points[keep], 3000 // len(self.poses), len(chosen))
            origin = pose[:3, 3]
            chosen.append(ends + (ends - origin) / np.linalg.norm(ends - origin, axis=1)[:, None])
        self.assertFraction(np.concatenate(chosen), UNKNOWN, self.BEHIND_UNKNOWN,
                            "1 m behind surfaces")

    def test_far_away_is_unknown(self):
        origins = np.array([pose[:3, 3] for pose in self.poses])
        for offset in ([200.0, 0.0, 0.0], [0.0, -200.0, 0.0], [0.0, 0.0, 100.0]):
            self.assertFraction(origins + offset, UNKNOWN, 1.0, "far away %s" % offset)
