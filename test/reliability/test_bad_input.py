#!/usr/bin/env python3
"""Bad input to a running mapping server (see bad_input.test and RELIABILITY.md).

Every malformed LaserScan, PointCloud2, depth image, frame, stamp, service request, path, map file and
parameter of the issue is sent to a real mvog_node. Each must be counted in ~statistics (or
answered with a message), leave the map byte for byte as it was (a save before and after), and
leave the server running and mapping; a bad parameter must stop the server at start, naming it.
The outcome of every case is printed as a table at the end (RELIABILITY.md reproduces it).
"""
import math
import os
import re
import shutil
import struct
import sys
import tempfile
import unittest

import rospy
import rostest
from geometry_msgs.msg import Point
from tf2_msgs.msg import TFMessage

from mvog.srv import CheckBoxes, CheckSegments

import mvog_reliability as rel

NAN, INF = float("nan"), float("inf")
MAX_POINTS = 500000      # ~max_points_per_message of the server under test
MAX_QUERY_POINTS = 1000  # ~max_query_points
SENSOR_QUEUE = 2         # ~sensor_queue_size
THIRTY_YEARS = rospy.Duration(30 * 365 * 86400)

OUTCOMES = []  # (input, outcome) for the table


def record(what, outcome):
    OUTCOMES.append((what, re.sub(r"\x1b\[[0-9;]*m", "", outcome)))


class BadInput(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.broadcaster = rel.init_test_node("test_bad_input")
        cls.server = rel.Server("mapper_bad_input", {
            "max_points_per_message": MAX_POINTS, "max_query_points": MAX_QUERY_POINTS,
            "sensor_queue_size": SENSOR_QUEUE, "insertion_queue_size": 50}).wait_ready()
        # Something in the map, so that "unchanged" means something.
        cls.server.scans.publish(rel.scan([2.0] * 16))
        cls.server.wait_counter("messages_inserted", 1)
        # A moving frame with a dynamic transform (for stamps far from now).
        cls.dynamic_timer = rospy.Timer(rospy.Duration(0.05), cls.publish_dynamic)
        cls.tf_publisher = rospy.Publisher("/tf", TFMessage, queue_size=10)

    @classmethod
    def publish_dynamic(cls, _event):
        cls.tf_publisher.publish(TFMessage(
            [rel.transform("map", "moving", x=0.5, z=0.7, stamp=rospy.Time.now())]))

    @classmethod
    def tearDownClass(cls):
        cls.dynamic_timer.shutdown()
        alive = cls.server.alive()
        cls.server.stop()
        print("\n| input | outcome |\n|---|---|")
        for what, outcome in OUTCOMES:
            print("| %s | %s |" % (what, outcome))
        sys.stdout.flush()
        assert alive, "the server died"

    # ---- helpers --------------------------------------------------------------------------

    def expect(self, what, publish, counter, count=1, unchanged=True, rejected_readings=None):
        """Publishes, waits until `counter` grew by `count`, checks the map and the server."""
        before = self.server.stats()
        snapshot = self.server.snapshot()
        publish()
        after = self.server.wait_counter(counter, getattr(before, counter) + count)
        if rejected_readings is not None:
            after = self.server.wait_counter("readings_rejected",
                                             before.readings_rejected + rejected_readings)
            self.assertEqual(after.readings_inserted, before.readings_inserted, what)
        if unchanged:
            self.assertEqual(self.server.snapshot(), snapshot, what + ": the map changed")
        self.assertTrue(self.server.alive(), what)
        outcome = {"messages_dropped_invalid": "refused, counted in messages_dropped_invalid",
                   "messages_dropped_tf": "dropped, counted in messages_dropped_tf",
                   "messages_dropped_camera_info":
                   "dropped, counted in messages_dropped_camera_info",
                   "messages_inserted": "taken"}[counter]
        if rejected_readings is not None:
            outcome += ("; %d readings counted in readings_rejected" % rejected_readings)
        if unchanged:
            outcome += "; map unchanged"
        record(what, outcome)
        return before, after

    def invalid_scan(self, what, message):
        self.expect("LaserScan " + what, lambda: self.server.scans.publish(message),
                    "messages_dropped_invalid")

    def invalid_cloud(self, what, message):
        self.expect("PointCloud2 " + what, lambda: self.server.clouds.publish(message),
                    "messages_dropped_invalid")

    # ---- LaserScan ------------------------------------------------------------------------

    def test_laser_scan(self):
        bad_ranges = [("NaN ranges", [NAN] * 8), ("-Inf ranges", [-INF] * 8),
                      ("negative ranges", [-1.0] * 8), ("ranges below range_min", [0.05] * 8)]
        for what, ranges in bad_ranges:
            self.expect("LaserScan " + what, lambda: self.server.scans.publish(rel.scan(ranges)),
                        "messages_inserted", rejected_readings=len(ranges))
        # A hit beyond ~max_coordinate (10 km) from a scan whose range_max allows it.
        self.expect("LaserScan range 1e20 m within a range_max of 1e30 m",
                    lambda: self.server.scans.publish(rel.scan([1e20] * 4, range_max=1e30)),
                    "messages_inserted", rejected_readings=4)
        # +Inf and huge ranges above range_max: REP-117 out-of-range, free space up to range_max.
        for what, ranges in [("+Inf ranges", [INF] * 8), ("huge ranges (1e30)", [1e30] * 8)]:
            before, after = self.expect(
                "LaserScan " + what, lambda: self.server.scans.publish(rel.scan(ranges)),
                "messages_inserted", unchanged=False)
            self.assertEqual(after.positive_volumes, before.positive_volumes, what)
            OUTCOMES[-1] = (OUTCOMES[-1][0], "free space up to range_max (REP-117), no obstacle")
        invalid = [
            ("angle_increment 0", rel.scan([1.0] * 4, angle_increment=0.0)),
            ("angle_increment NaN", rel.scan([1.0] * 4, angle_increment=NAN)),
            ("angle_increment Inf", rel.scan([1.0] * 4, angle_increment=INF)),
            ("angle_min NaN", rel.scan([1.0] * 4, angle_min=NAN)),
            ("range_min > range_max", rel.scan([1.0] * 4, range_min=5.0, range_max=2.0)),
            ("range_min NaN", rel.scan([1.0] * 4, range_min=NAN)),
            ("range_max NaN", rel.scan([1.0] * 4, range_max=NAN)),
            ("range_max Inf", rel.scan([1.0] * 4, range_max=INF)),
            ("range_min negative", rel.scan([1.0] * 4, range_min=-1.0)),
            ("0 beams", rel.scan([])),
            ("a million beams (~max_points_per_message %d)" % MAX_POINTS,
             rel.scan([1.0] * 1000000)),
        ]
        for what, message in invalid:
            self.invalid_scan(what, message)
        # Accepted: a clockwise scan, intensities of another length (they are not used).
        self.expect("LaserScan angle_increment negative (clockwise)",
                    lambda: self.server.scans.publish(
                        rel.scan([1.5] * 4, angle_min=3.0, angle_increment=-0.5)),
                    "messages_inserted", unchanged=False)
        OUTCOMES[-1] = (OUTCOMES[-1][0], "mapped (a clockwise scanner is valid)")
        self.expect("LaserScan intensities of another length",
                    lambda: self.server.scans.publish(
                        rel.scan([1.7] * 4, intensities=[1.0] * 9)),
                    "messages_inserted", unchanged=False)
        OUTCOMES[-1] = (OUTCOMES[-1][0], "mapped; intensities are not used")

    def test_a_laser_scan_warnings_are_throttled(self):
        """First: no warning of the kind was printed yet."""
        # One at a time: a burst beyond ~sensor_queue_size would lose some in roscpp's own
        # subscriber queue, uncounted (see RELIABILITY.md).
        before = self.server.stats()
        for k in range(20):
            self.server.scans.publish(rel.scan([]))
            self.server.wait_counter("messages_dropped_invalid",
                                     before.messages_dropped_invalid + k + 1)
        lines = [line for line in self.server.output().splitlines()
                 if "dropped an invalid LaserScan" in line]
        self.assertGreater(len(lines), 0)
        self.assertTrue(any("LaserScan has no beams" in line for line in lines))
        # One line per 5 s at most (ROS_WARN_THROTTLE), not one per message.
        self.assertLess(len(lines), 20)
        record("20 invalid LaserScans within a few seconds", "%d warning line(s) in all, 20 counted"
               % len(lines))

    # ---- PointCloud2 ----------------------------------------------------------------------

    def test_point_cloud(self):
        points = [(1.0, 0.5, 0.0), (2.0, -0.5, 0.2), (1.5, 0.0, -0.3)]
        good = rel.cloud(points)
        invalid = [
            ("data shorter than width*height*point_step", rel.cloud(points, data=good.data[:-1])),
            ("no x/y/z fields", rel.cloud(points, fields=[("rgb", 0, rel.FLOAT32)])),
            ("no z field", rel.cloud(points, fields=rel.XYZ32[:2])),
            ("integer x/y/z", rel.cloud(points, fields=[("x", 0, rel.INT32), ("y", 4, rel.INT32),
                                                        ("z", 8, rel.INT32)])),
            ("point_step smaller than the fields", rel.cloud(points, point_step=8,
                                                             data=good.data)),
            ("field offset beyond point_step", rel.cloud(
                points, fields=[("x", 0, rel.FLOAT32), ("y", 4, rel.FLOAT32),
                                ("z", 4000, rel.FLOAT32)], data=good.data)),
            ("width 2^32-1", rel.cloud(points, width=0xFFFFFFFF, data=good.data)),
            ("width and height 2^32-1", rel.cloud(points, width=0xFFFFFFFF, height=0xFFFFFFFF,
                                                  data=good.data)),
            ("row_step smaller than width*point_step", rel.cloud(points, row_step=4)),
        ]
        for what, message in invalid:
            self.invalid_cloud(what, message)
        for what, message in [("width 0", rel.cloud([], width=0, data=b"")),
                              ("height 0", rel.cloud([], width=5, height=0, data=b"")),
                              ("width 0 with 1000 rows", rel.cloud([], width=0, height=1000,
                                                                   data=b""))]:
            self.expect("PointCloud2 " + what, lambda: self.server.clouds.publish(message),
                        "messages_inserted")
            OUTCOMES[-1] = (OUTCOMES[-1][0], "taken, nothing to insert; map unchanged")
        bad_points = [("NaN points", [(NAN, 0.0, 0.0), (0.0, NAN, 1.0), (NAN, NAN, NAN)]),
                      ("Inf points", [(INF, 0.0, 0.0), (0.0, -INF, 1.0), (1.0, 1.0, INF)]),
                      ("points 10,000 km away", [(1e7, 0.0, 0.0), (0.0, -1e7, 0.0),
                                                 (5e6, 5e6, 5e6)])]
        for what, cloud_points in bad_points:
            before, after = self.expect(
                "PointCloud2 " + what,
                lambda: self.server.clouds.publish(rel.cloud(cloud_points)),
                "messages_inserted", rejected_readings=len(cloud_points))
            # The map did not grow towards them: no tile, no byte.
            self.assertEqual(after.bytes_held, before.bytes_held, what)
            self.assertEqual(after.minimal_grid_cells, before.minimal_grid_cells, what)
        # Big-endian data with is_bigendian set: read as such (a supported layout).
        before = self.server.stats()
        self.server.clouds.publish(rel.cloud([(2.5, 2.5, 0.0)], big_endian=True))
        self.server.wait_counter("messages_inserted", before.messages_inserted + 1)
        response = self.server.occupancy([(2.55, 2.55, 1.0)])
        self.assertEqual(response.state[0], 2, "the big-endian point was not mapped")
        record("PointCloud2 is_bigendian set (big-endian data)", "mapped, bytes swapped")

    # ---- Depth images ---------------------------------------------------------------------

    def publish_depth(self, image, info=None):
        """The camera info first (the server pairs them in either order), then the image."""
        self.server.camera_infos.publish(rel.camera_info(image) if info is None else info)
        self.server.depth_images.publish(image)

    def test_depth_image(self):
        # 8 x 6 pixels looking up from the camera frame (1 m high), 2 m away.
        good = rel.depth_image([2000] * 48, 8, encoding="16UC1")
        short = bytes(good.data[:-1])
        k_nan = rel.camera_info(good, fx=NAN)
        k_zero = rel.camera_info(good, fx=0.0, fy=0.0, cx=0.0, cy=0.0)
        invalid = [
            ("encoding rgb8", rel.depth_image([1] * 48, 8, encoding="rgb8"), None),
            ("encoding mono16", rel.depth_image([2000] * 48, 8, encoding="mono16"), None),
            ("big-endian 16-bit", rel.depth_image([2000] * 48, 8, encoding="16UC1",
                                                  big_endian=True), None),
            ("step smaller than width*bytes", rel.depth_image([2000] * 48, 8, encoding="16UC1",
                                                              step=15, data=good.data), None),
            ("data shorter than height*step", rel.depth_image([2000] * 48, 8, encoding="16UC1",
                                                              data=short), None),
            ("K zero", good, k_zero),
            ("K NaN", good, k_nan),
            ("camera info of another size", good, rel.camera_info(good, width=640, height=480)),
        ]
        for what, image, info in invalid:
            image.header.stamp = rospy.Time.now()
            if info is not None:
                info.header = image.header
            self.expect("depth image " + what, lambda: self.publish_depth(image, info),
                        "messages_dropped_invalid")
        self.assertTrue(any("encoding 'rgb8'" in line for line in self.server.output().splitlines()
                            if "dropped an invalid depth image" in line), "no warning naming it")

        def publish_without_camera_info():
            # Images wait for the camera info of their stamp; beyond ~sensor_queue_size waiting,
            # the oldest is dropped and counted.
            before = self.server.stats().messages_dropped_camera_info
            for _ in range(100):
                self.server.depth_images.publish(rel.depth_image([2000] * 48, 8, encoding="16UC1"))
                if rel.wait_for_or_not(lambda: self.server.statistics.messages_dropped_camera_info
                                       > before, 0.5):
                    return
        self.expect("depth image without camera info, several", publish_without_camera_info,
                    "messages_dropped_camera_info")
        OUTCOMES[-1] = (OUTCOMES[-1][0], "waits for its camera info; beyond ~sensor_queue_size "
                        "waiting, the oldest is dropped and counted in "
                        "messages_dropped_camera_info; map unchanged")

        # REP-118: 0, NaN and -Inf say nothing.
        for what, depths in [("0 pixels (16UC1)", [0] * 12), ("NaN pixels", [NAN] * 12),
                             ("-Inf pixels", [-INF] * 12)]:
            encoding = "16UC1" if "16UC1" in what else "32FC1"
            self.expect("depth image of " + what,
                        lambda: self.publish_depth(rel.depth_image(depths, 4, encoding=encoding)),
                        "messages_inserted", rejected_readings=len(depths))
        # +Inf: no return, free space only (from the laser frame, 0.5 m high: below the good
        # image's surface, which it must not touch).
        before = self.server.stats()
        self.publish_depth(rel.depth_image([INF] * 12, 4, frame="laser"))
        after = self.server.wait_counter("messages_inserted", before.messages_inserted + 1)
        self.assertEqual(after.out_of_range_readings - before.out_of_range_readings, 12)
        self.assertEqual(after.positive_volumes, before.positive_volumes)
        record("depth image of +Inf pixels", "free space up to ~max_range (REP-118, "
               "~out_of_range_free_length), no obstacle")
        # A good image maps: the pixel (4, 3) sees (0.25 m, 0.25 m) 2 m above the camera.
        before = self.server.stats()
        self.publish_depth(good)
        self.server.wait_counter("messages_inserted", before.messages_inserted + 1)
        response = self.server.occupancy([(0.25, 0.25, rel.CAMERA_HEIGHT + 2.0)])
        self.assertEqual(response.state[0], 2, "the depth image was not mapped")
        record("depth image 16UC1 with its camera info", "mapped")

    # ---- Frames and stamps ----------------------------------------------------------------

    def test_frames_and_stamps(self):
        self.expect("LaserScan with an empty frame_id",
                    lambda: self.server.scans.publish(rel.scan([1.0] * 4, frame="")),
                    "messages_dropped_tf")
        # A message waits for its transform; beyond ~sensor_queue_size waiting messages of a
        # topic, the oldest is dropped and counted.
        cases = [
            ("unknown frame", dict(frame="nowhere")),
            ("stamp 30 years ahead (dynamic frame)",
             dict(frame="moving", stamp=rospy.Time.now() + THIRTY_YEARS)),
            ("stamp 30 years ago (dynamic frame)",
             dict(frame="moving", stamp=rospy.Time.now() - THIRTY_YEARS)),
        ]
        for what, header in cases:
            def publish():
                # One at a time (see above) until one of these is pushed out of the waiting
                # queue: up to SENSOR_QUEUE messages of the case before may be waiting in front
                # of them, and are dropped first.
                before = self.server.stats().messages_dropped_tf
                for _ in range(100):
                    self.server.scans.publish(rel.scan([1.0] * 4, **header))
                    if rel.wait_for_or_not(lambda: self.server.statistics.messages_dropped_tf >
                                           before + SENSOR_QUEUE, 0.5):
                        return
            self.expect("LaserScan " + what + ", several", publish, "messages_dropped_tf")
            OUTCOMES[-1] = (OUTCOMES[-1][0], "waits for its transform; beyond "
                            "~sensor_queue_size waiting, the oldest is dropped and counted in "
                            "messages_dropped_tf; map unchanged")
        # Static transforms hold at every time: a stamp 30 years ahead in a static frame maps.
        self.expect("LaserScan stamp 30 years ahead (static frame)",
                    lambda: self.server.scans.publish(
                        rel.scan([3.0] * 4, stamp=rospy.Time.now() + THIRTY_YEARS)),
                    "messages_inserted", unchanged=False)
        OUTCOMES[-1] = (OUTCOMES[-1][0], "mapped (a static transform holds at any time)")
        # The waiting messages of the dynamic frame are flushed by newer ones in time, which map.
        before = self.server.stats()
        self.server.scans.publish(rel.scan([1.2] * 4, frame="moving"))
        self.server.wait_counter("messages_inserted", before.messages_inserted + 1)

    # ---- Services -------------------------------------------------------------------------

    def test_queries(self):
        response = self.server.occupancy([])
        self.assertTrue(response.success)
        self.assertEqual(len(response.probability), 0)
        record("get_occupancy with no point", "success, empty answer")
        response = self.server.occupancy([(0.0, 0.0, 0.0)] * (MAX_QUERY_POINTS + 1))
        self.assertFalse(response.success)
        self.assertIn("max_query_points", response.message)
        record("get_occupancy with ~max_query_points + 1 points",
               "refused: \"%s\"" % response.message)
        response = self.server.occupancy([(NAN, 0.0, 0.0), (0.0, INF, 0.0), (1.0, 1.0, -INF),
                                          (1e300, 1e300, 1e300)])
        self.assertTrue(response.success)
        self.assertEqual(list(response.state), [0, 0, 0, 0])
        self.assertTrue(all(math.isnan(p) for p in response.probability))
        record("get_occupancy at NaN, Inf and 1e300 points", "unknown (state 0, probability NaN)")
        response = self.server.occupancy([(1.0, 0.0, 0.5)], frame_id="nowhere")
        self.assertFalse(response.success)
        self.assertIn("nowhere", response.message)
        # One reason, not one per poll of tf while the server waited (~tf_timeout).
        self.assertLess(len(response.message), 200, response.message)
        record("get_occupancy in an unknown frame", "refused: \"%s\"" %
               response.message.split("\n")[0][:110])
        response = self.server.occupancy([(1.0, 0.0, 0.5)], frame_id="/map")
        self.assertTrue(response.success, response.message)
        record("get_occupancy in frame '/map' (tf1's leading '/')", "answered, as in 'map'")

    def test_planning_queries(self):
        """check_segments and check_boxes refuse what they cannot answer, saying why."""
        snapshot = self.server.snapshot()
        check_segments = self.server.service("check_segments", CheckSegments)
        check_boxes = self.server.service("check_boxes", CheckBoxes)

        def segments(pairs, radius=0.0, frame_id=""):
            return check_segments(frame_id=frame_id, radius=radius,
                                  starts=[Point(*a) for a, _ in pairs],
                                  ends=[Point(*b) for _, b in pairs])

        def boxes(pairs, frame_id=""):
            return check_boxes(frame_id=frame_id, min_corners=[Point(*a) for a, _ in pairs],
                               max_corners=[Point(*b) for _, b in pairs])

        response = segments([])
        self.assertTrue(response.success, response.message)
        self.assertEqual(len(response.state), 0)
        record("check_segments with no segment", "success, empty answer")
        good = ((0.0, 0.0, 0.5), (1.0, 0.0, 0.5))
        refused = [
            ("check_segments with more ends than starts",
             lambda: check_segments(starts=[Point(*good[0])], ends=[Point(*good[1])] * 2)),
            ("check_segments with ~max_query_points + 1 segments",
             lambda: segments([good] * (MAX_QUERY_POINTS + 1))),
            ("check_segments with a NaN point", lambda: segments([((NAN, 0.0, 0.5), good[1])])),
            ("check_segments with an infinite point",
             lambda: segments([(good[0], (INF, 0.0, 0.5))])),
            ("check_segments with a point beyond ~max_coordinate",
             lambda: segments([(good[0], (1e300, 0.0, 0.5))])),
            ("check_segments with a NaN radius", lambda: segments([good], radius=NAN)),
            ("check_segments with a negative radius", lambda: segments([good], radius=-0.1)),
            ("check_segments with a radius beyond ~max_coordinate",
             lambda: segments([good], radius=1e12)),
            ("check_segments over more than ~max_query_cells cells",
             lambda: segments([((-9000.0, 0.0, 0.5), (9000.0, 0.0, 0.5))], radius=100.0)),
            ("check_segments in an unknown frame", lambda: segments([good], frame_id="nowhere")),
            ("check_boxes with more max corners than min corners",
             lambda: check_boxes(min_corners=[Point(*good[0])], max_corners=[Point(*good[1])] * 2)),
            ("check_boxes with ~max_query_points + 1 boxes",
             lambda: boxes([good] * (MAX_QUERY_POINTS + 1))),
            ("check_boxes with a min corner above its max corner",
             lambda: boxes([(good[1], good[0])])),
            ("check_boxes with a NaN corner", lambda: boxes([((NAN, 0.0, 0.0), good[1])])),
            ("check_boxes over more than ~max_query_cells cells",
             lambda: boxes([((-9000.0, -9000.0, 0.0), (9000.0, 9000.0, 1.0))])),
            ("check_boxes in an unknown frame", lambda: boxes([good], frame_id="nowhere")),
        ]
        for what, request in refused:
            response = request()
            self.assertFalse(response.success, what)
            self.assertTrue(response.message, what)
            self.assertEqual(len(response.state), 0, what)
            record(what, "refused: \"%s\"" % response.message.split("\n")[0][:140])
        self.assertEqual(self.server.snapshot(), snapshot)
        self.assertTrue(self.server.alive())

    def test_paths(self):
        outside = tempfile.mkdtemp(prefix="mvog_reliability_outside_")
        try:
            outside_map = os.path.join(outside, "outside.mvog")
            with open(outside_map, "wb") as f:
                f.write(self.server.snapshot())
            directory = self.server.directory
            os.symlink(outside_map, os.path.join(directory, "link_out.mvog"))
            os.symlink(outside, os.path.join(directory, "dir_out"))
            os.symlink(os.path.join(outside, "missing.mvog"), os.path.join(directory,
                                                                             "dangling.mvog"))
            snapshot = self.server.snapshot()
            refused = [("absolute path outside", outside_map),
                       ("'..' out of the directory", "../" + os.path.basename(outside) +
                        "/outside.mvog"),
                       ("symlink to a file outside", "link_out.mvog"),
                       ("through a symlinked directory outside", "dir_out/outside.mvog"),
                       ("dangling symlink", "dangling.mvog"),
                       ("the directory itself", "."),
                       ("a hidden name (the temporaries of saves have them)",
                        ".map.mvog.saving-Ab3xZ9"),
                       ("empty path", "")]
            for what, path in refused:
                for verb in ("load", "save"):
                    response = getattr(self.server, verb)(path)
                    self.assertFalse(response.success, "%s %s" % (verb, what))
                    self.assertTrue(response.message)
                record("save_map / load_map: " + what, "refused: \"%s\"" % response.message)
            self.assertEqual(self.server.snapshot(), snapshot)
            self.assertEqual(os.listdir(outside), ["outside.mvog"], "something was written "
                             "outside the map directory")
        finally:
            shutil.rmtree(outside, ignore_errors=True)

    def test_load_refuses_bad_files(self):
        snapshot = self.server.snapshot()
        absurd = bytearray(snapshot[:64])
        struct.pack_into("<QQ", absurd, 32, 1 << 40, 1 << 50)
        absurd = bytes(absurd) + struct.pack("<Q", rel.fnv1a64(bytes(absurd)))
        flipped = bytearray(snapshot)
        flipped[len(flipped) // 2] ^= 0x10
        resolution = bytearray(snapshot)
        struct.pack_into("<d", resolution, 16, -0.1)
        resolution = bytes(resolution[:-8]) + struct.pack("<Q", rel.fnv1a64(bytes(resolution[:-8])))
        files = [("empty file", b""), ("truncated file", snapshot[:-9]),
                 ("one bit flipped", bytes(flipped)),
                 ("foreign file (PNG)", b"\x89PNG\r\n\x1a\n" + b"\0" * 100),
                 ("absurd header counts (2^40 cells), valid checksum", absurd),
                 ("negative resolution, valid checksum", resolution)]
        for what, data in files:
            with open(os.path.join(self.server.directory, "bad.mvog"), "wb") as f:
                f.write(data)
            response = self.server.load("bad.mvog")
            self.assertFalse(response.success, what)
            self.assertEqual(self.server.snapshot(), snapshot, what + ": the map changed")
            record("load_map: " + what, "refused, map untouched: \"%s\"" %
                   response.message.split(": ", 1)[-1])
        self.assertTrue(self.server.alive())

    # ---- Parameters -----------------------------------------------------------------------

    def test_bad_parameters_refuse_to_start(self):
        cases = [("resolution", {"resolution": NAN}), ("resolution", {"resolution": -0.1}),
                 ("resolution", {"resolution": 0.0}), ("resolution", {"resolution": "fine"}),
                 ("max_coordinate", {"max_coordinate": 0.0}),
                 ("min_range", {"min_range": 5.0, "max_range": 2.0}),
                 ("max_range", {"max_range": NAN}),
                 ("insertion_queue_size", {"insertion_queue_size": 0}),
                 ("tf_timeout", {"tf_timeout": NAN}),
                 ("decay_factor", {"decay_factor": 1.5}),
                 ("decay_period", {"decay_period": -1.0}),
                 ("publish_period", {"publish_period": 0.0}),
                 ("occupancy_threshold", {"occupancy_threshold": NAN}),
                 ("projection_min_z", {"projection_min_z": 2.0, "projection_max_z": 1.0}),
                 ("max_query_points", {"max_query_points": 0}),
                 ("max_query_cells", {"max_query_cells": 0}),
                 ("robot_height", {"robot_height": 0.0}),
                 ("frontier_min_z", {"frontier_min_z": 2.0, "frontier_max_z": 1.0}),
                 ("depth_stride", {"depth_stride": 0}),
                 ("autosave_period", {"autosave_period": -5.0})]
        # All started at once: each only reads its parameters and exits.
        servers = []
        try:
            for k, (_, values) in enumerate(cases):
                servers.append(rel.Server("mapper_refused_%d" % k, values))
            outcomes = [(server.wait_exit(), server.output()) for server in servers]
        finally:
            for server in servers:
                server.stop()
        for (parameter, values), (status, output) in zip(cases, outcomes):
            self.assertNotEqual(status, 0, "%s: %s" % (values, output))
            self.assertIn("~" + parameter, output, values)
            line = [l for l in output.splitlines() if "cannot start" in l]
            record("parameter %s" % ", ".join("%s = %s" % kv for kv in values.items()),
                   "refuses to start: \"%s\"" % (line[0].split("cannot start: ", 1)[-1]
                                                 if line else output.strip()[-80:]))

    def test_zz_still_mapping(self):
        """After everything else: the same server still maps a good scan."""
        before = self.server.stats()
        self.server.scans.publish(rel.scan([4.0] * 16))
        after = self.server.wait_counter("messages_inserted", before.messages_inserted + 1)
        self.assertGreater(after.readings_inserted, before.readings_inserted)
        self.assertTrue(self.server.alive())


if __name__ == "__main__":
    rostest.rosrun("mvog", "test_bad_input", BadInput, sys.argv)
