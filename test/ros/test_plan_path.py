#!/usr/bin/env python3
"""~plan_path on a running mapping server (see plan_path.test and README, "Planning").

One mvog_node; a depth camera 1 m up at the origin sees a wall at x = 2 (y in [-3, 3], up to
2.5 m) with a door in it (|y| < 0.6, up to 2.0 m), and through the door a wall at x = 5: the
space before the wall is known free, beyond it only the cone seen through the door. Planned:
through the door (only known free space; every edge free by ~check_segments, crossing the wall
within the door); around the wall (unknown space allowed: the straight line is blocked, no edge
meets occupied space); into unknown space when it is not allowed (refused, saying why); malformed
requests (NaN, a negative radius, no time, a start inside the wall) answered with an error and
nothing changed (the map, ~planned_path); and with the door closed by a box of occupied space,
no path, the status saying why. Nothing asserts how long planning took.
"""
import math
import os
import sys
import unittest

import rospy
import rostest
from geometry_msgs.msg import Point
from nav_msgs.msg import Path

from mvog.srv import CheckSegments, PlanPath

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "reliability"))
import mvog_reliability as rel  # noqa: E402

CAMERA = (0.0, 0.0, rel.CAMERA_HEIGHT)
WALL_X, BACK_X, DOOR_HALF_WIDTH, DOOR_HEIGHT, HEIGHT = 2.0, 5.0, 0.6, 2.0, 2.5
STEP = 0.05
RADIUS = 0.2
OCCUPIED = CheckSegments._response_class.OCCUPIED
FREE = CheckSegments._response_class.FREE
Status = PlanPath._response_class


def grid(low, high):
    return [low + STEP * k for k in range(int(round((high - low) / STEP)) + 1)]


def in_door(y, z):
    return abs(y) < DOOR_HALF_WIDTH and z < DOOR_HEIGHT


def relative(points):
    """Points of the map frame in the camera's frame (a translation)."""
    return [(x - CAMERA[0], y - CAMERA[1], z - CAMERA[2]) for x, y, z in points]


def scene_points():
    wall = [(WALL_X, y, z) for y in grid(-3.0, 3.0) for z in grid(0.0, HEIGHT) if not in_door(y, z)]
    # The back wall where the camera sees it through the door.
    back = []
    for y in grid(-3.0, 3.0):
        for z in grid(0.0, HEIGHT):
            t = (WALL_X - CAMERA[0]) / (BACK_X - CAMERA[0])
            if in_door(CAMERA[1] + t * (y - CAMERA[1]), CAMERA[2] + t * (z - CAMERA[2])):
                back.append((BACK_X, y, z))
    return relative(wall + back)


def door_points():
    return relative([(WALL_X, y, z) for y in grid(-3.0, 3.0) for z in grid(0.0, HEIGHT)
                     if in_door(y, z)])


def point(p):
    return Point(x=p[0], y=p[1], z=p[2])


class PlanPathTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.broadcaster = rel.init_test_node("test_plan_path")
        cls.server = rel.Server("mapper_plan_path").wait_ready()
        cls.server.clouds.publish(rel.cloud(scene_points()))
        cls.server.wait_counter("messages_inserted", 1)
        cls.plan_service = cls.server.service("plan_path", PlanPath)
        cls.check_service = cls.server.service("check_segments", CheckSegments)
        cls.paths = []
        cls.path_subscriber = rospy.Subscriber(cls.server.ns + "/planned_path", Path,
                                               cls.paths.append)

    @classmethod
    def tearDownClass(cls):
        cls.path_subscriber.unregister()
        assert cls.server.stop_alive(), "the server died"

    def plan(self, start, goal, allow_unknown=False, radius=RADIUS, time_limit=5.0):
        return self.plan_service(start=point(start), goal=point(goal), radius=radius,
                                 time_limit=time_limit, allow_unknown=allow_unknown)

    def edges(self, response):
        poses = [p.pose.position for p in response.path.poses]
        return list(zip(poses[:-1], poses[1:]))

    def edge_states(self, response):
        edges = self.edges(response)
        checked = self.check_service(starts=[a for a, _ in edges], ends=[b for _, b in edges],
                                     radius=RADIUS)
        self.assertTrue(checked.success, checked.message)
        return list(checked.state)

    def test_1_through_the_door(self):
        response = self.plan((1.0, 0.0, 1.0), (4.0, 0.0, 1.0))
        self.assertEqual(response.status, Status.PLANNED, response.message)
        self.assertEqual(response.path.header.frame_id, "map")
        first, last = response.path.poses[0].pose.position, response.path.poses[-1].pose.position
        self.assertEqual((first.x, first.y, first.z), (1.0, 0.0, 1.0))
        self.assertEqual((last.x, last.y, last.z), (4.0, 0.0, 1.0))
        self.assertEqual(self.edge_states(response), [FREE] * len(self.edges(response)))
        crossings = 0
        for a, b in self.edges(response):
            if (a.x - WALL_X) * (b.x - WALL_X) <= 0 and a.x != b.x:
                t = (WALL_X - a.x) / (b.x - a.x)
                crossings += 1
                self.assertTrue(in_door(a.y + t * (b.y - a.y), a.z + t * (b.z - a.z)),
                                "crossed the wall beside the door")
        self.assertEqual(crossings, 1)
        # Published for rviz.
        rel.wait_for(lambda: self.paths and self.paths[-1].poses == response.path.poses,
                     "the path on ~planned_path")

    def test_2_around_the_wall_with_unknown_space_allowed(self):
        start, goal = (1.0, -2.0, 1.0), (3.0, -2.0, 1.0)
        straight = self.check_service(starts=[point(start)], ends=[point(goal)], radius=RADIUS)
        self.assertEqual(straight.state[0], OCCUPIED)
        response = self.plan(start, goal, allow_unknown=True)
        self.assertEqual(response.status, Status.PLANNED, response.message)
        self.assertGreater(len(response.path.poses), 2)
        self.assertNotIn(OCCUPIED, self.edge_states(response))

    def test_3_unknown_space_is_refused_when_not_allowed(self):
        response = self.plan((1.0, 0.0, 1.0), (3.0, -2.0, 1.0))
        self.assertEqual(response.status, Status.GOAL_BLOCKED, response.message)
        self.assertIn("unknown space not allowed", response.message)
        self.assertEqual(response.path.poses, [])

    def test_4_malformed_requests_get_an_error_and_change_nothing(self):
        last = self.plan((1.0, 0.0, 1.0), (4.0, 0.0, 1.0))  # the path published last
        rel.wait_for(lambda: self.paths and self.paths[-1].poses == last.path.poses,
                     "the last path on ~planned_path")
        published = len(self.paths)
        snapshot = self.server.snapshot()
        cases = [
            ("start", Status.INVALID_REQUEST, dict(start=(math.nan, 0.0, 1.0))),
            ("goal", Status.INVALID_REQUEST, dict(goal=(4.0, math.inf, 1.0))),
            ("radius", Status.INVALID_REQUEST, dict(radius=-0.1)),
            ("radius", Status.INVALID_REQUEST, dict(radius=math.nan)),
            ("time_limit", Status.INVALID_REQUEST, dict(time_limit=0.0)),
            ("time_limit", Status.INVALID_REQUEST, dict(time_limit=-1.0)),
            ("start", Status.START_BLOCKED, dict(start=(WALL_X + 0.05, -2.0, 1.0),
                                                 allow_unknown=True)),
        ]
        for field, status, change in cases:
            request = dict(start=(1.0, 0.0, 1.0), goal=(4.0, 0.0, 1.0))
            request.update(change)
            response = self.plan(**request)
            self.assertEqual(response.status, status, (change, response.message))
            self.assertTrue(response.message.startswith(field + ":"), response.message)
            self.assertEqual(response.path.poses, [])
        rospy.sleep(0.5)
        self.assertEqual(len(self.paths), published, "a refused request published a path")
        self.assertEqual(self.server.snapshot(), snapshot)
        self.assertTrue(self.server.alive())

    def test_5_with_the_door_closed_there_is_no_path(self):
        for count in (2, 3):
            self.server.clouds.publish(rel.cloud(door_points()))
            self.server.wait_counter("messages_inserted", count)
        closed = self.check_service(starts=[point((1.0, 0.0, 1.0))],
                                    ends=[point((4.0, 0.0, 1.0))], radius=0.0)
        self.assertEqual(closed.state[0], OCCUPIED)
        response = self.plan((1.0, 0.0, 1.0), (4.0, 0.0, 1.0), time_limit=1.0)
        self.assertEqual(response.status, Status.NO_PATH, response.message)
        self.assertIn("no path found within 1 s", response.message)
        self.assertEqual(response.path.poses, [])


if __name__ == "__main__":
    rostest.rosrun("mvog", "test_plan_path", PlanPathTest, sys.argv)
