#!/usr/bin/env python3
"""Self-check of scripts/make_scene.py: the bag it writes and the truth file agree.

Run with Debian's interpreter: /usr/bin/python3 -m unittest discover -s test/scene
"""
import json
import subprocess
import sys
import tempfile
import unittest
from pathlib import Path

import numpy as np
import rosbag
import rospy
import tf2_ros
from tf2_msgs.msg import TFMessage

SCRIPT = Path(__file__).resolve().parents[2] / "scripts" / "make_scene.py"
CAMERA_TOPIC, CAMERA_INFO_TOPIC, SCAN_TOPIC = (
    "/camera/depth/image", "/camera/depth/camera_info", "/scan")


def make_scene(directory, *args):
    bag, truth = Path(directory) / "scene.bag", Path(directory) / "scene_truth.json"
    subprocess.run([sys.executable, str(SCRIPT), "--output", str(bag), "--truth", str(truth),
                    *args], check=True, stderr=subprocess.DEVNULL)
    return bag, truth


def rotation_matrix(q):
    x, y, z, w = q.x, q.y, q.z, q.w
    return np.array([
        [1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
        [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
        [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)]])


def distance_to_boxes(points, boxes):
    lo = np.array([b["min"] for b in boxes])
    hi = np.array([b["max"] for b in boxes])
    gap = np.maximum(np.maximum(lo[None] - points[:, None], 0.0), points[:, None] - hi[None])
    return np.linalg.norm(gap, axis=2).min(axis=1)


def inside(point, box, margin=0.0):
    return all(lo + margin <= v <= hi - margin for v, lo, hi in zip(point, box["min"], box["max"]))


class MakeSceneTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.directory = tempfile.TemporaryDirectory()
        cls.bag_path, truth_path = make_scene(cls.directory.name)
        cls.truth = json.loads(truth_path.read_text())
        cls.bag = rosbag.Bag(str(cls.bag_path))
        cls.buffer = tf2_ros.Buffer(cache_time=rospy.Duration(3600), debug=False)
        for topic, raw, _ in cls.bag.read_messages(topics=["/tf", "/tf_static"], raw=True):
            for transform in TFMessage().deserialize(raw[1]).transforms:
                if topic == "/tf_static":
                    cls.buffer.set_transform_static(transform, "bag")
                else:
                    cls.buffer.set_transform(transform, "bag")
        cls.camera_infos = {msg.header.stamp: msg for _, msg, _ in
                            cls.bag.read_messages(topics=[CAMERA_INFO_TOPIC])}

    @classmethod
    def tearDownClass(cls):
        cls.bag.close()
        cls.directory.cleanup()

    def sensor_messages(self):
        return self.bag.read_messages(topics=[CAMERA_TOPIC, SCAN_TOPIC])

    def test_topics(self):
        topics = self.bag.get_type_and_topic_info().topics
        self.assertEqual(topics["/tf_static"].message_count, 1)
        self.assertEqual(topics["/tf"].msg_type, "tf2_msgs/TFMessage")
        self.assertEqual(topics[CAMERA_TOPIC].msg_type, "sensor_msgs/Image")
        self.assertEqual(topics[CAMERA_INFO_TOPIC].msg_type, "sensor_msgs/CameraInfo")
        self.assertEqual(topics[CAMERA_INFO_TOPIC].message_count,
                         topics[CAMERA_TOPIC].message_count)
        self.assertEqual(topics[SCAN_TOPIC].msg_type, "sensor_msgs/LaserScan")
        self.assertGreater(topics[CAMERA_TOPIC].message_count, 50)
        self.assertGreater(topics[SCAN_TOPIC].message_count, 500)
        self.assertLess(self.bag_path.stat().st_size, 12_000_000)

    def test_tf_static_is_latched_and_first(self):
        first = next(self.bag.read_messages(return_connection_header=True))
        self.assertEqual(first.topic, "/tf_static")
        self.assertIn(first.connection_header["latching"], (b"1", "1"))

    def test_every_sensor_message_can_be_transformed(self):
        for _, msg, t in self.sensor_messages():
            self.assertEqual(msg.header.stamp, t)
            self.assertTrue(self.buffer.can_transform("map", msg.header.frame_id, msg.header.stamp),
                            f"{msg.header.frame_id} at {msg.header.stamp.to_sec()}")

    def test_returns_lie_on_obstacles(self):
        obstacles = self.truth["static_boxes"] + [self.truth["person"]["swept_box"]]
        for topic, msg, _ in self.sensor_messages():
            if topic == CAMERA_TOPIC:
                # Back-projected with the camera info of its stamp (REP-118: +Inf, no return).
                self.assertEqual((msg.width, msg.height, msg.encoding, msg.step),
                                 (88, 72, "32FC1", 4 * 88))
                info = self.camera_infos[msg.header.stamp]
                self.assertEqual((info.width, info.height), (msg.width, msg.height))
                depth = np.frombuffer(msg.data, "<f4").astype(float)
                self.assertFalse(np.isnan(depth).any())
                u, v = np.meshgrid(np.arange(msg.width), np.arange(msg.height))
                fx, cx, fy, cy = info.K[0], info.K[2], info.K[4], info.K[5]
                local = np.stack([(u.ravel() - cx) / fx * depth, (v.ravel() - cy) / fy * depth,
                                  depth], axis=1)
            else:
                ranges = np.array(msg.ranges)
                self.assertFalse(np.isnan(ranges).any())
                angles = msg.angle_min + msg.angle_increment * np.arange(len(ranges))
                with np.errstate(invalid="ignore"):
                    local = np.stack([ranges * np.cos(angles), ranges * np.sin(angles),
                                      np.zeros_like(ranges)], axis=1)
            local = local[np.isfinite(local).all(axis=1)]
            transform = self.buffer.lookup_transform(
                "map", msg.header.frame_id, msg.header.stamp).transform
            translation = transform.translation
            points = local @ rotation_matrix(transform.rotation).T + np.array(
                [translation.x, translation.y, translation.z])
            self.assertLess(distance_to_boxes(points, obstacles).max(), 0.06, topic)

    def test_truth_probes_are_consistent_with_the_scene(self):
        probes = self.truth["probes"]
        boxes = {box["name"]: box for box in self.truth["static_boxes"]}
        for kind in ("occupied", "free", "unknown", "person"):
            self.assertTrue(probes[kind], kind)
        for probe in probes["occupied"]:
            self.assertTrue(inside(probe["point"], boxes[probe["box"]]), probe["name"])
        free_points = np.array([probe["point"] for probe in probes["free"]])
        self.assertGreaterEqual(distance_to_boxes(free_points, list(boxes.values())).min(), 0.3)
        room = self.truth["room"]
        for probe in probes["unknown"]:
            self.assertFalse(inside(probe["point"], room, margin=0.15) and not any(
                inside(probe["point"], box) for box in boxes.values()), probe["name"])
        standing = self.truth["person"]["standing_boxes"]
        for probe in probes["person"]:
            self.assertTrue(any(inside(probe["point"], box) for box in standing), probe["name"])
            self.assertEqual(probe["occupied_interval"], self.truth["person"]["standing_interval"])

    def test_same_seed_gives_the_same_bag(self):
        with tempfile.TemporaryDirectory() as first, tempfile.TemporaryDirectory() as second:
            a, _ = make_scene(first, "--duration", "4", "--seed", "7")
            b, _ = make_scene(second, "--duration", "4", "--seed", "7")
            self.assertEqual(a.read_bytes(), b.read_bytes())


if __name__ == "__main__":
    unittest.main()
