#!/usr/bin/env python3
"""Generate mvog's demo recording: a MAV mapping an office room (ray-cast simulation).

The scene mirrors the experiments of the MVOG paper (Dryanovski, Morris, Xiao,
IROS 2010): an office with two desks, clutter and a person, mapped by a small
depth camera (Swissranger SR4000-like) and a tilted 2D laser carried by a MAV,
while a person walks in and out of view to show the removal of dynamic obstacles.
Every range is computed by casting the sensor's rays against the scene's boxes;
the only randomness is Gaussian range noise drawn from --seed, so equal
arguments give the same bag.

Scene (frame "map", REP-103: x east, y north, z up; metres)
  Room interior x 0..8, y 0..6, z 0..3 (floor, ceiling and four 0.2 m walls).
  A 1.0 x 2.1 m door in the south wall (x 6..7) opens on a corridor closed by a
  wall at y = -1.8. Furniture, all axis-aligned boxes: a solid desk against the
  north wall with a box on it, a desk (top on four legs) in the middle with a
  monitor, a cabinet on the east wall, a bookshelf on the west wall, a pillar
  and two boxes on the floor.
  A person (0.5 x 0.4 x 1.55 m body plus a head, 1.8 m tall) appears in the
  corridor in front of the door at 25 % of the recording, walks in to
  (6.5, 1.0), stands there from 32 % to 46 %, walks back out and vanishes at
  53 %; the rest of the recording shows the room without him.

Vehicle and sensors
  base_link flies, level, two counter-clockwise laps of an ellipse around the
  middle desk (centre (4, 3), semi-axes 2.4 x 1.5 m; 20 s a lap by default)
  at 1.05-1.75 m, facing the middle of the room with a +-25 deg yaw sweep. The
  laps are phased so that it looks at the person from across the room, from
  its highest point, while he stands there, and again from the same pose
  after he has left.
  camera_depth_optical_frame (x right, y down, z forward): 0.12 m ahead of and
  0.05 m below base_link, pitched 10 deg down. 176 x 144 pixels over
  43.6 x 34.6 deg (by default --pixel-step 2 keeps every other pixel:
  88 x 72), 0.3-8 m, 1 cm range noise, --camera-rate Hz (default 2, which
  keeps the default bag near 4 MB).
  laser: 0.08 m ahead of and 0.06 m above base_link, pitched 30 deg down so the
  scan plane sweeps the room in 3D; 270 deg in 0.5 deg steps, 0.1-10 m,
  1 cm range noise, 20 Hz.

Topics (stamps from 1700000000 s; the bag's time of each message is its stamp)
  /tf_static            tf2_msgs/TFMessage       base_link -> camera_depth_optical_frame,
                                                 base_link -> laser; one message at the
                                                 start, on a latched connection
                                                 (connection header latching=1)
  /tf                   tf2_msgs/TFMessage       map -> base_link at 50 Hz, from the
                                                 start to the end: every sensor stamp has
                                                 samples before and after it
  /camera/depth/image   sensor_msgs/Image        32FC1 depth (m along the optical axis) in
                                                 the camera frame, +Inf where there is no
                                                 return (REP-118)
  /camera/depth/camera_info  sensor_msgs/CameraInfo  its pinhole camera (K, P; no distortion),
                                                 same stamp
  /scan                 sensor_msgs/LaserScan    +Inf where there is no return (REP-117)

Truth file (--truth FILE, JSON)
  The scene (room bounds, static boxes, person timeline and boxes), the sensor
  set-up, and probe points for tests of a mapper at 0.1 m resolution, each one
  checked against the simulated beams: "occupied" points 3 cm inside surfaces
  that were hit from at least 5 sensor readings (at least 0.15 m from any other
  obstacle); "free" points at least 0.3 m from any obstacle and from the
  person's path, seen through by at least 10 readings; "unknown" points that
  no beam reached, nor any point 0.15 m around them; "person" points inside
  the standing person, hit while he stood there and seen through again after
  he left by at least as many readings. Every probe records how many sensor
  readings ("views") support it. Times in the file are absolute stamps in seconds.
"""
import argparse
import json
import math
import sys
from dataclasses import dataclass

import numpy as np
import rosbag
import rospy
from geometry_msgs.msg import TransformStamped
from sensor_msgs.msg import CameraInfo, Image, LaserScan
from tf2_msgs.msg import TFMessage

START_SEC = 1_700_000_000
FIXED_FRAME = "map"
BASE_FRAME = "base_link"
TF_TOPIC = "/tf"
TF_STATIC_TOPIC = "/tf_static"
TF_RATE_HZ = 50.0
SENSOR_MARGIN_S = 0.1  # first / last sensor stamp this long after / before the tf stream
MIN_CLEARANCE_M = 0.5  # base_link's distance to any obstacle along the trajectory
CALLER_ID = "/make_scene"

ROOM_MIN = (0.0, 0.0, 0.0)
ROOM_MAX = (8.0, 6.0, 3.0)

# Probe selection (see the module docstring).
PROBE_INSET_M = 0.03
PROBE_EDGE_MARGIN_M = 0.15
PROBE_FACE_SPACING_M = 0.5
PROBES_PER_BOX = 3
FREE_CLEARANCE_M = 0.3
UNKNOWN_NEIGHBOURHOOD_M = 0.15
MIN_OCCUPIED_VIEWS = 5
MIN_FREE_VIEWS = 10
MIN_PERSON_HIT_VIEWS = 3
MIN_PERSON_FREE_VIEWS = 5
HIT_BEFORE_M = 0.15  # a beam through a point hits "at" it if its return is this much before
HIT_AFTER_M = 0.05   # ... or this much after it
FREE_AFTER_M = 0.3   # a beam sees through a point if its return is this much beyond it
REACH_BEFORE_M = 0.2  # a beam reaches a point unless it returns this much before it


@dataclass(frozen=True)
class Box:
    """Axis-aligned box in the map frame."""

    name: str
    lo: tuple
    hi: tuple

    def to_json(self):
        return {"name": self.name, "min": [round(v, 4) for v in self.lo],
                "max": [round(v, 4) for v in self.hi]}


def box_arrays(boxes):
    """Corner arrays (M, 3), (M, 3) of a list of boxes."""
    return (np.array([b.lo for b in boxes], dtype=float).reshape(-1, 3),
            np.array([b.hi for b in boxes], dtype=float).reshape(-1, 3))


def distance_to_boxes(points, boxes):
    """Euclidean distance (P, M) from each point to each box (0 inside)."""
    lo, hi = box_arrays(boxes)
    gap = np.maximum(np.maximum(lo[None] - points[:, None], 0.0), points[:, None] - hi[None])
    return np.linalg.norm(gap, axis=2)


def static_boxes():
    """The office: shell (floor, ceiling, walls, corridor) and furniture."""
    x0, y0, z0 = ROOM_MIN
    x1, y1, z1 = ROOM_MAX
    wall = 0.2
    corridor_y = -1.8
    door_x, door_top = (6.0, 7.0), 2.1
    boxes = [
        Box("floor", (x0 - wall, corridor_y - wall, z0 - wall), (x1 + wall, y1 + wall, z0)),
        Box("ceiling", (x0 - wall, corridor_y - wall, z1), (x1 + wall, y1 + wall, z1 + wall)),
        Box("wall_west", (x0 - wall, y0 - wall, z0), (x0, y1 + wall, z1)),
        Box("wall_east", (x1, y0 - wall, z0), (x1 + wall, y1 + wall, z1)),
        Box("wall_north", (x0 - wall, y1, z0), (x1 + wall, y1 + wall, z1)),
        Box("wall_south_west", (x0 - wall, y0 - wall, z0), (door_x[0], y0, z1)),
        Box("wall_south_east", (door_x[1], y0 - wall, z0), (x1 + wall, y0, z1)),
        Box("door_lintel", (door_x[0], y0 - wall, door_top), (door_x[1], y0, z1)),
        Box("corridor_wall", (x0 - wall, corridor_y - wall, z0), (x1 + wall, corridor_y, z1)),
        Box("desk_solid", (0.8, 5.2, 0.0), (2.4, 6.0, 0.75)),
        Box("box_on_desk_solid", (1.3, 5.45, 0.75), (1.6, 5.75, 1.05)),
        Box("desk_top", (3.2, 2.6, 0.71), (4.8, 3.4, 0.75)),
        Box("monitor", (3.8, 3.15, 0.75), (4.3, 3.22, 1.15)),
        Box("cabinet", (7.5, 3.4, 0.0), (8.0, 4.6, 1.9)),
        Box("bookshelf", (0.0, 1.0, 0.0), (0.4, 2.4, 2.0)),
        Box("pillar", (1.7, 0.8, 0.0), (2.1, 1.2, z1)),
        Box("floor_box_west", (1.0, 3.0, 0.0), (1.4, 3.4, 0.4)),
        Box("floor_box_north_east", (6.8, 5.2, 0.0), (7.3, 5.6, 0.5)),
    ]
    leg = 0.05
    for ix, x in enumerate((3.25, 4.7)):
        for iy, y in enumerate((2.65, 3.3)):
            boxes.append(Box(f"desk_leg_{ix}{iy}", (x, y, 0.0), (x + leg, y + leg, 0.71)))
    return boxes


class Person:
    """A person walking in through the door, standing, and walking out again."""

    BODY_SIZE = (0.5, 0.4, 1.55)
    HEAD_SIZE = (0.2, 0.2, 0.25)
    PATH_START = np.array([6.5, -1.2])  # in the corridor, in front of the door
    STAND_POINT = np.array([6.5, 1.0])
    # Fractions of the recording: appears, arrives, starts leaving, vanishes.
    TIMELINE = (0.25, 0.32, 0.46, 0.53)

    def __init__(self, duration):
        self.t_enter, self.t_arrive, self.t_leave, self.t_exit = (
            f * duration for f in self.TIMELINE)

    def position(self, t):
        """(x, y) of the person at time t (s from the start), None when absent."""
        if t < self.t_enter or t > self.t_exit:
            return None
        if t < self.t_arrive:
            s = (t - self.t_enter) / (self.t_arrive - self.t_enter)
        elif t <= self.t_leave:
            s = 1.0
        else:
            s = (self.t_exit - t) / (self.t_exit - self.t_leave)
        return self.PATH_START + s * (self.STAND_POINT - self.PATH_START)

    def boxes_at_point(self, xy):
        body_x, body_y, body_z = self.BODY_SIZE
        head_x, head_y, head_z = self.HEAD_SIZE
        x, y = xy
        return [
            Box("person_body", (x - body_x / 2, y - body_y / 2, 0.0),
                (x + body_x / 2, y + body_y / 2, body_z)),
            Box("person_head", (x - head_x / 2, y - head_y / 2, body_z),
                (x + head_x / 2, y + head_y / 2, body_z + head_z)),
        ]

    def boxes_at(self, t):
        xy = self.position(t)
        return [] if xy is None else self.boxes_at_point(xy)

    def swept_box(self):
        """Bounding box of every place the person occupies."""
        lo, hi = box_arrays(self.boxes_at_point(self.PATH_START)
                            + self.boxes_at_point(self.STAND_POINT))
        return Box("person_path", tuple(lo.min(axis=0)), tuple(hi.max(axis=0)))


class LoopTrajectory:
    """base_link pose: level elliptic laps around the middle of the room, facing its middle.

    The laps are phased so that at watch_time the vehicle is across the room from
    watch_point, at its highest, looking straight at it; later laps repeat that
    view. A yaw sweep of one cycle per lap, zero at watch_time, turns the camera
    over the walls.
    """

    CENTER = np.array([4.0, 3.0])
    SEMI_AXES = np.array([2.4, 1.5])
    LAPS = 2
    HEIGHT_M, HEIGHT_AMPLITUDE_M, HEIGHT_CYCLES_PER_LAP = 1.4, 0.35, 3
    YAW_SWEEP = math.radians(25.0)

    def __init__(self, duration, watch_time, watch_point):
        self.lap_s = duration / self.LAPS
        self.watch_time = watch_time
        away = (self.CENTER - watch_point) / self.SEMI_AXES
        self.watch_angle = math.atan2(away[1], away[0])

    def pose(self, t):
        """Position (3,) and yaw (rad) at time t (s from the start)."""
        lap_phase = 2.0 * math.pi * (t - self.watch_time) / self.lap_s
        angle = self.watch_angle + lap_phase
        xy = self.CENTER + self.SEMI_AXES * np.array([math.cos(angle), math.sin(angle)])
        z = self.HEIGHT_M + self.HEIGHT_AMPLITUDE_M * math.cos(
            self.HEIGHT_CYCLES_PER_LAP * lap_phase)
        to_center = self.CENTER - xy
        yaw = math.atan2(to_center[1], to_center[0]) + self.YAW_SWEEP * math.sin(lap_phase)
        return np.array([xy[0], xy[1], z]), yaw


def rot_y(angle):
    c, s = math.cos(angle), math.sin(angle)
    return np.array([[c, 0.0, s], [0.0, 1.0, 0.0], [-s, 0.0, c]])


def rot_z(angle):
    c, s = math.cos(angle), math.sin(angle)
    return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])


def quaternion_from_matrix(rotation):
    """(x, y, z, w) of a rotation matrix."""
    m = rotation
    trace = m[0, 0] + m[1, 1] + m[2, 2]
    if trace > 0.0:
        s = 2.0 * math.sqrt(trace + 1.0)
        q = (
            (m[2, 1] - m[1, 2]) / s, (m[0, 2] - m[2, 0]) / s, (m[1, 0] - m[0, 1]) / s, s / 4.0)
    elif m[0, 0] > m[1, 1] and m[0, 0] > m[2, 2]:
        s = 2.0 * math.sqrt(1.0 + m[0, 0] - m[1, 1] - m[2, 2])
        q = (s / 4.0, (m[0, 1] + m[1, 0]) / s, (m[0, 2] + m[2, 0]) / s, (m[2, 1] - m[1, 2]) / s)
    elif m[1, 1] > m[2, 2]:
        s = 2.0 * math.sqrt(1.0 + m[1, 1] - m[0, 0] - m[2, 2])
        q = ((m[0, 1] + m[1, 0]) / s, s / 4.0, (m[1, 2] + m[2, 1]) / s, (m[0, 2] - m[2, 0]) / s)
    else:
        s = 2.0 * math.sqrt(1.0 + m[2, 2] - m[0, 0] - m[1, 1])
        q = ((m[0, 2] + m[2, 0]) / s, (m[1, 2] + m[2, 1]) / s, s / 4.0, (m[1, 0] - m[0, 1]) / s)
    return q


# Camera axes (x right, y down, z forward) expressed in a forward-left-up body frame.
OPTICAL_AXES = np.array([[0.0, 0.0, 1.0], [-1.0, 0.0, 0.0], [0.0, -1.0, 0.0]])


@dataclass(frozen=True)
class Mount:
    """Pose of a sensor frame in base_link."""

    translation: np.ndarray
    rotation: np.ndarray


class DepthCamera:
    """Swissranger SR4000-like time-of-flight camera publishing depth images (REP-118)."""

    TOPIC = "/camera/depth/image"
    INFO_TOPIC = "/camera/depth/camera_info"
    FRAME = "camera_depth_optical_frame"
    NATIVE_WIDTH, NATIVE_HEIGHT = 176, 144
    HFOV, VFOV = math.radians(43.6), math.radians(34.6)
    RANGE_MIN, RANGE_MAX = 0.3, 8.0
    NOISE_STD = 0.01
    MOUNT = Mount(np.array([0.12, 0.0, -0.05]), rot_y(math.radians(10.0)) @ OPTICAL_AXES)

    def __init__(self, pixel_step, rate_hz):
        self.rate_hz = rate_hz
        self.width = self.NATIVE_WIDTH // pixel_step
        self.height = self.NATIVE_HEIGHT // pixel_step
        self.fx = (self.width / 2.0) / math.tan(self.HFOV / 2.0)
        self.fy = (self.height / 2.0) / math.tan(self.VFOV / 2.0)
        u, v = np.meshgrid(np.arange(self.width) + 0.5, np.arange(self.height) + 0.5)
        rays = np.stack([(u - self.width / 2.0) / self.fx, (v - self.height / 2.0) / self.fy,
                         np.ones_like(u)], axis=-1).reshape(-1, 3)
        self.directions = rays / np.linalg.norm(rays, axis=1, keepdims=True)

    def beam_index(self, local):
        """Pixel index (row-major) of points (..., 3) in the camera frame, and whether in view."""
        z = local[..., 2]
        with np.errstate(divide="ignore", invalid="ignore"):
            u = np.floor(self.fx * local[..., 0] / z + self.width / 2.0)
            v = np.floor(self.fy * local[..., 1] / z + self.height / 2.0)
        in_view = (z > 0.0) & (u >= 0) & (u < self.width) & (v >= 0) & (v < self.height)
        index = np.where(in_view, v * self.width + u, 0).astype(int)
        return index, in_view

    @staticmethod
    def beam_range(local):
        return np.linalg.norm(local, axis=-1)

    def messages(self, stamp, ranges):
        """The depth image of the ranges (depth = range x the ray's optical-axis component; +Inf
        where there is no return) and its camera info."""
        image = Image()
        image.header.stamp = stamp
        image.header.frame_id = self.FRAME
        image.height, image.width = self.height, self.width
        image.encoding = "32FC1"
        image.is_bigendian = False
        image.step = 4 * self.width
        image.data = (ranges * self.directions[:, 2]).astype("<f4").tobytes()
        info = CameraInfo()
        info.header = image.header
        info.height, info.width = self.height, self.width
        info.distortion_model = "plumb_bob"
        info.D = [0.0] * 5
        # Pixel (u, v)'s centre is the image coordinate (u, v) (REP-104): the rays above leave
        # through u + 0.5 from the image's edge.
        cx, cy = self.width / 2.0 - 0.5, self.height / 2.0 - 0.5
        info.K = [self.fx, 0.0, cx, 0.0, self.fy, cy, 0.0, 0.0, 1.0]
        info.R = [1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0]
        info.P = [self.fx, 0.0, cx, 0.0, 0.0, self.fy, cy, 0.0, 0.0, 0.0, 1.0, 0.0]
        return [(self.TOPIC, image), (self.INFO_TOPIC, info)]

    def to_json(self):
        return {"topic": self.TOPIC, "camera_info_topic": self.INFO_TOPIC, "frame_id": self.FRAME,
                "type": "sensor_msgs/Image", "encoding": "32FC1",
                "rate_hz": self.rate_hz, "width": self.width, "height": self.height,
                "hfov_deg": round(math.degrees(self.HFOV), 3),
                "vfov_deg": round(math.degrees(self.VFOV), 3),
                "range_min": self.RANGE_MIN, "range_max": self.RANGE_MAX,
                "noise_std": self.NOISE_STD, "no_return": "+Inf"}


class TiltedLaser:
    """Hokuyo-like 2D laser scanner pitched down so its plane sweeps the room."""

    TOPIC = "/scan"
    FRAME = "laser"
    RATE_HZ = 20.0
    ANGLE_MIN, ANGLE_INCREMENT, BEAMS = math.radians(-135.0), math.radians(0.5), 541
    RANGE_MIN, RANGE_MAX = 0.1, 10.0
    NOISE_STD = 0.01
    PLANE_TOLERANCE_M = 0.05  # points this close to the scan plane count as on it
    MOUNT = Mount(np.array([0.08, 0.0, 0.06]), rot_y(math.radians(30.0)))

    def __init__(self):
        self.rate_hz = self.RATE_HZ
        angles = self.ANGLE_MIN + self.ANGLE_INCREMENT * np.arange(self.BEAMS)
        self.directions = np.stack([np.cos(angles), np.sin(angles), np.zeros_like(angles)],
                                   axis=1)

    def beam_index(self, local):
        """Beam index of points (..., 3) in the laser frame, and whether in the scan plane."""
        index = np.rint((np.arctan2(local[..., 1], local[..., 0]) - self.ANGLE_MIN)
                        / self.ANGLE_INCREMENT).astype(int)
        in_view = (np.abs(local[..., 2]) < self.PLANE_TOLERANCE_M) & (index >= 0) & (
            index < self.BEAMS)
        return np.where(in_view, index, 0), in_view

    @staticmethod
    def beam_range(local):
        return np.hypot(local[..., 0], local[..., 1])

    def messages(self, stamp, ranges):
        scan = LaserScan()
        scan.header.stamp = stamp
        scan.header.frame_id = self.FRAME
        scan.angle_min = self.ANGLE_MIN
        scan.angle_max = self.ANGLE_MIN + self.ANGLE_INCREMENT * (self.BEAMS - 1)
        scan.angle_increment = self.ANGLE_INCREMENT
        scan.time_increment = 0.0
        scan.scan_time = 1.0 / self.RATE_HZ
        scan.range_min, scan.range_max = self.RANGE_MIN, self.RANGE_MAX
        scan.ranges = ranges.astype(np.float32).tolist()
        return [(self.TOPIC, scan)]

    def to_json(self):
        return {"topic": self.TOPIC, "frame_id": self.FRAME, "type": "sensor_msgs/LaserScan",
                "rate_hz": self.rate_hz, "beams": self.BEAMS,
                "angle_min_deg": math.degrees(self.ANGLE_MIN),
                "angle_increment_deg": math.degrees(self.ANGLE_INCREMENT),
                "range_min": self.RANGE_MIN, "range_max": self.RANGE_MAX,
                "noise_std": self.NOISE_STD, "no_return": "+Inf"}


def cast_rays(origin, directions, boxes):
    """Distance along each unit direction (N, 3) from origin to the nearest box, inf if none."""
    lo, hi = box_arrays(boxes)
    inverse = 1.0 / np.where(np.abs(directions) < 1e-12, 1e-12, directions)
    t_near = np.full((len(directions), len(boxes)), -np.inf)
    t_far = np.full((len(directions), len(boxes)), np.inf)
    for axis in range(3):  # slab method: intersect the rays' entry / exit parameters per axis
        t_lo = (lo[:, axis] - origin[axis]) * inverse[:, axis, None]
        t_hi = (hi[:, axis] - origin[axis]) * inverse[:, axis, None]
        np.maximum(t_near, np.minimum(t_lo, t_hi), out=t_near)
        np.minimum(t_far, np.maximum(t_lo, t_hi), out=t_far)
    hit = (t_near <= t_far) & (t_near > 0.0)
    return np.where(hit, t_near, np.inf).min(axis=1)


class Scene:
    """Static boxes, the person and the vehicle's trajectory."""

    def __init__(self, duration):
        self.duration = duration
        self.static = static_boxes()
        self.person = Person(duration)
        self.trajectory = LoopTrajectory(
            duration, (self.person.t_arrive + self.person.t_leave) / 2.0, Person.STAND_POINT)

    def boxes_at(self, t):
        return self.static + self.person.boxes_at(t)

    def sensor_pose(self, mount, t):
        """World rotation (3, 3) and origin (3,) of a sensor mounted on base_link at time t."""
        position, yaw = self.trajectory.pose(t)
        base_rotation = rot_z(yaw)
        return base_rotation @ mount.rotation, position + base_rotation @ mount.translation

    def check_clearance(self, times):
        """Fail if base_link passes closer than MIN_CLEARANCE_M to any obstacle."""
        for t in times:
            position, _ = self.trajectory.pose(t)
            distance = distance_to_boxes(position[None], self.boxes_at(t)).min()
            if distance < MIN_CLEARANCE_M:
                raise RuntimeError(
                    f"trajectory passes {distance:.2f} m from an obstacle at t={t:.2f} s")


class SensorRecording:
    """The simulated readings of one sensor: stamps, sensor poses and measured ranges."""

    def __init__(self, sensor, scene, times, rng):
        self.sensor = sensor
        self.times = np.asarray(times)
        count = len(self.times)
        self.rotations = np.empty((count, 3, 3))
        self.origins = np.empty((count, 3))
        self.ranges = np.empty((count, len(sensor.directions)))
        for k, t in enumerate(self.times):
            rotation, origin = scene.sensor_pose(sensor.MOUNT, t)
            true_ranges = cast_rays(origin, sensor.directions @ rotation.T, scene.boxes_at(t))
            measured = true_ranges + rng.normal(0.0, sensor.NOISE_STD, true_ranges.shape)
            valid = np.isfinite(true_ranges) & (measured >= sensor.RANGE_MIN) & (
                measured <= sensor.RANGE_MAX)
            self.rotations[k], self.origins[k] = rotation, origin
            self.ranges[k] = np.where(valid, measured, np.inf)

    def observe(self, points):
        """For each reading and point (P, 3): the point's range along its beam and the
        beam's measured range (inf: no return, NaN: point outside the sensor's view)."""
        local = np.einsum("fji,fpj->fpi", self.rotations, points[None] - self.origins[:, None])
        index, in_view = self.sensor.beam_index(local)
        measured = np.take_along_axis(self.ranges, index, axis=1)
        return self.sensor.beam_range(local), np.where(in_view, measured, np.nan)


class Evidence:
    """What all readings of all sensors say about a set of points (rows: readings)."""

    def __init__(self, recordings, points):
        observations = [recording.observe(points) for recording in recordings]
        self.times = np.concatenate([recording.times for recording in recordings])
        self.point_ranges = np.concatenate([o[0] for o in observations])
        self.measured = np.concatenate([o[1] for o in observations])

    def hits(self):
        with np.errstate(invalid="ignore"):
            return ((self.measured >= self.point_ranges - HIT_BEFORE_M)
                    & (self.measured <= self.point_ranges + HIT_AFTER_M))

    def see_through(self):
        return np.isfinite(self.measured) & (self.measured >= self.point_ranges + FREE_AFTER_M)

    def reached(self):
        with np.errstate(invalid="ignore"):
            return self.measured >= self.point_ranges - REACH_BEFORE_M


def face_candidates(box):
    """Points PROBE_INSET_M inside each face of a box, PROBE_EDGE_MARGIN_M from its edges,
    with the face's outward normal."""
    lo, hi = np.array(box.lo), np.array(box.hi)
    points, normals = [], []
    for axis in range(3):
        others = [a for a in range(3) if a != axis]
        spans = [np.arange(lo[a] + PROBE_EDGE_MARGIN_M, hi[a] - PROBE_EDGE_MARGIN_M + 1e-9,
                           PROBE_FACE_SPACING_M) for a in others]
        if any(len(span) == 0 for span in spans):
            continue
        inset = min(PROBE_INSET_M, (hi[axis] - lo[axis]) / 2.0)
        for side, face in ((-1.0, lo[axis] + inset), (1.0, hi[axis] - inset)):
            for b, c in np.array(np.meshgrid(*spans)).reshape(2, -1).T:
                point = np.empty(3)
                point[axis], point[others[0]], point[others[1]] = face, b, c
                normal = np.zeros(3)
                normal[axis] = side
                points.append(point)
                normals.append(normal)
    return np.array(points).reshape(-1, 3), np.array(normals).reshape(-1, 3)


def rounded(point):
    return [round(float(v), 3) for v in point]


def occupied_probes(scene, recordings):
    """Up to PROBES_PER_BOX well-seen surface points per static box."""
    person_region = scene.person.swept_box()
    probes = []
    for index, box in enumerate(scene.static):
        points, normals = face_candidates(box)
        if len(points) == 0:
            continue
        neighbours = [b for i, b in enumerate(scene.static) if i != index] + [person_region]
        isolated = distance_to_boxes(points, neighbours).min(axis=1) >= PROBE_EDGE_MARGIN_M
        points, normals = points[isolated], normals[isolated]
        views = Evidence(recordings, points).hits().sum(axis=0)
        best = [k for k in np.argsort(-views, kind="stable")[:PROBES_PER_BOX]
                if views[k] >= MIN_OCCUPIED_VIEWS]
        probes += [{"name": f"{box.name}_{rank}", "box": box.name, "point": rounded(points[k]),
                    "normal": rounded(normals[k]), "views": int(views[k])}
                   for rank, k in enumerate(best)]
    return probes


def free_probes(scene, recordings):
    """Points on and around the trajectory and on a grid over the room that beams went through."""
    offsets = FREE_CLEARANCE_M * np.vstack([np.zeros(3), np.eye(3), -np.eye(3)])
    named = []
    for t in np.arange(0.0, scene.duration, 2.0):
        position, _ = scene.trajectory.pose(t)
        named += [(f"trajectory_t{t:g}_{k}", position + offset) for k, offset in enumerate(offsets)]
    for x in np.arange(ROOM_MIN[0] + 0.5, ROOM_MAX[0], 1.0):
        for y in np.arange(ROOM_MIN[1] + 0.5, ROOM_MAX[1], 1.0):
            for z in np.arange(ROOM_MIN[2] + 0.5, ROOM_MAX[2], 0.5):
                named.append((f"grid_{x:g}_{y:g}_{z:g}", np.array([x, y, z])))
    points = np.array([p for _, p in named])
    obstacles = scene.static + [scene.person.swept_box()]
    clear = distance_to_boxes(points, obstacles).min(axis=1) >= FREE_CLEARANCE_M
    views = np.zeros(len(points), dtype=int)
    views[clear] = Evidence(recordings, points[clear]).see_through().sum(axis=0)
    return [{"name": name, "point": rounded(point), "views": int(v)}
            for (name, point), v in zip(named, views) if v >= MIN_FREE_VIEWS]


def unknown_probes(recordings):
    """Points that no beam came near: behind walls, under the floor, inside the solid desk."""
    named = [
        ("behind_north_wall_west", (2.0, 6.6, 1.5)),
        ("behind_north_wall_east", (6.0, 6.6, 1.0)),
        ("behind_east_wall", (8.6, 4.0, 1.5)),
        ("behind_west_wall", (-0.6, 4.5, 1.5)),
        ("below_floor", (4.0, 3.0, -0.6)),
        ("above_ceiling", (4.0, 3.0, 3.6)),
        ("inside_desk_solid", (1.6, 5.6, 0.35)),
        ("far_away", (30.0, 30.0, 1.5)),
    ]
    steps = (-UNKNOWN_NEIGHBOURHOOD_M, 0.0, UNKNOWN_NEIGHBOURHOOD_M)
    neighbourhood = np.array(np.meshgrid(steps, steps, steps)).reshape(3, -1).T
    points = (np.array([p for _, p in named])[:, None] + neighbourhood[None]).reshape(-1, 3)
    reached = Evidence(recordings, points).reached().any(axis=0).reshape(len(named), -1)
    return [{"name": name, "point": list(point)}
            for (name, point), near in zip(named, reached.any(axis=1)) if not near]


FACE_NAMES = {(-1, 0, 0): "west", (1, 0, 0): "east", (0, -1, 0): "south", (0, 1, 0): "north",
              (0, 0, -1): "bottom", (0, 0, 1): "top"}


def person_probes(scene, recordings, start):
    """Points inside the standing person: hit while he stands there, then seen through after
    he left by at least as many readings."""
    person = scene.person
    body, head = person.boxes_at_point(person.STAND_POINT)
    points, normals = face_candidates(body)
    x, y = person.STAND_POINT
    points = np.vstack([points, [x, y, head.hi[2] - PROBE_INSET_M]])
    normals = np.vstack([normals, [0.0, 0.0, 1.0]])
    evidence = Evidence(recordings, points)
    standing = (evidence.times >= person.t_arrive) & (evidence.times <= person.t_leave)
    gone = evidence.times > person.t_exit
    hit_views = (evidence.hits() & standing[:, None]).sum(axis=0)
    free_views = (evidence.see_through() & gone[:, None]).sum(axis=0)
    seen = (hit_views >= MIN_PERSON_HIT_VIEWS) & (free_views >= np.maximum(
        MIN_PERSON_FREE_VIEWS, hit_views))
    return [{"name": f"person_{FACE_NAMES[tuple(normals[k].astype(int))]}_z{points[k][2]:.2f}",
             "point": rounded(points[k]),
             "occupied_interval": [start + person.t_arrive, start + person.t_leave],
             "free_from": start + person.t_exit,
             "views_occupied": int(hit_views[k]), "views_free_after": int(free_views[k])}
            for k in np.flatnonzero(seen)]


def stamp_at(t):
    """ROS time t seconds after START_SEC, exact to the nanosecond."""
    nanoseconds = int(round(t * 1e9))
    return rospy.Time(START_SEC + nanoseconds // 10**9, nanoseconds % 10**9)


def transform(stamp, parent, child, rotation, translation):
    msg = TransformStamped()
    msg.header.stamp = stamp
    msg.header.frame_id = parent
    msg.child_frame_id = child
    msg.transform.translation.x, msg.transform.translation.y, msg.transform.translation.z = (
        float(v) for v in translation)
    q = quaternion_from_matrix(rotation)
    (msg.transform.rotation.x, msg.transform.rotation.y, msg.transform.rotation.z,
     msg.transform.rotation.w) = q
    return msg


def latched_header(topic, msg_class):
    """Connection header that makes rosbag play (and rostopic) republish the topic latched."""
    return {"topic": topic, "type": msg_class._type, "md5sum": msg_class._md5sum,
            "message_definition": msg_class._full_text, "callerid": CALLER_ID, "latching": "1"}


def write_bag(path, scene, recordings, tf_times):
    sensors = [recording.sensor for recording in recordings]
    static_stamp = stamp_at(0.0)
    static_tf = TFMessage([transform(static_stamp, BASE_FRAME, sensor.FRAME,
                                     sensor.MOUNT.rotation, sensor.MOUNT.translation)
                           for sensor in sensors])
    events = []
    for t in tf_times:
        position, yaw = scene.trajectory.pose(t)
        stamp = stamp_at(t)
        events.append((t, TF_TOPIC, TFMessage(
            [transform(stamp, FIXED_FRAME, BASE_FRAME, rot_z(yaw), position)])))
    for recording in recordings:
        for t, ranges in zip(recording.times, recording.ranges):
            for topic, message in recording.sensor.messages(stamp_at(t), ranges):
                events.append((t, topic, message))
    events.sort(key=lambda event: event[0])  # stable: a camera info right after its image
    with rosbag.Bag(path, "w") as bag:
        bag.write(TF_STATIC_TOPIC, static_tf, static_stamp,
                  connection_header=latched_header(TF_STATIC_TOPIC, TFMessage))
        for t, topic, msg in events:
            bag.write(topic, msg, stamp_at(t))


def truth(scene, recordings, seed):
    start = float(START_SEC)
    person = scene.person
    return {
        "frame_id": FIXED_FRAME,
        "start_time": start,
        "end_time": start + scene.duration,
        "seed": seed,
        "room": {"min": list(ROOM_MIN), "max": list(ROOM_MAX)},
        "static_boxes": [box.to_json() for box in scene.static],
        "person": {
            "present_interval": [start + person.t_enter, start + person.t_exit],
            "standing_interval": [start + person.t_arrive, start + person.t_leave],
            "path": {"start": rounded(person.PATH_START), "stand": rounded(person.STAND_POINT)},
            "standing_boxes": [box.to_json() for box in person.boxes_at_point(person.STAND_POINT)],
            "swept_box": person.swept_box().to_json(),
        },
        "tf": {"topic": TF_TOPIC, "static_topic": TF_STATIC_TOPIC, "fixed_frame": FIXED_FRAME,
               "base_frame": BASE_FRAME, "rate_hz": TF_RATE_HZ},
        "sensors": {"depth_camera": recordings[0].sensor.to_json(),
                    "laser": recordings[1].sensor.to_json()},
        "probes": {
            "occupied": occupied_probes(scene, recordings),
            "free": free_probes(scene, recordings),
            "unknown": unknown_probes(recordings),
            "person": person_probes(scene, recordings, start),
        },
    }


def sensor_times(duration, rate_hz):
    return np.arange(SENSOR_MARGIN_S, duration - SENSOR_MARGIN_S + 1e-9, 1.0 / rate_hz)


def parse_args(argv):
    parser = argparse.ArgumentParser(description=__doc__,
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--output", required=True, help="bag file to write")
    parser.add_argument("--truth", help="also write the scene's ground truth to this JSON file")
    parser.add_argument("--duration", type=float, default=40.0,
                        help="recording length in seconds (default: %(default)s)")
    parser.add_argument("--seed", type=int, default=0,
                        help="seed of the range noise (default: %(default)s)")
    parser.add_argument("--camera-rate", type=float, default=2.0,
                        help="depth camera frame rate in Hz (default: %(default)s)")
    parser.add_argument("--pixel-step", type=int, choices=(1, 2, 4), default=2,
                        help="use every n-th pixel of the 176 x 144 camera in both directions "
                             "(default: %(default)s)")
    args = parser.parse_args(argv)
    if args.duration < 2.0:
        parser.error("--duration must be at least 2 s")
    if args.camera_rate <= 0.0:
        parser.error("--camera-rate must be positive")
    return args


def main(argv=None):
    args = parse_args(argv)
    rng = np.random.default_rng(args.seed)
    scene = Scene(args.duration)
    tf_times = np.arange(0.0, args.duration + 1e-9, 1.0 / TF_RATE_HZ)
    scene.check_clearance(tf_times)
    camera = DepthCamera(args.pixel_step, args.camera_rate)
    laser = TiltedLaser()
    recordings = [SensorRecording(sensor, scene, sensor_times(args.duration, sensor.rate_hz), rng)
                  for sensor in (camera, laser)]
    write_bag(args.output, scene, recordings, tf_times)
    print(f"wrote {args.output}: {len(recordings[0].times)} depth frames, "
          f"{len(recordings[1].times)} scans, {len(tf_times)} tf samples", file=sys.stderr)
    if args.truth:
        scene_truth = truth(scene, recordings, args.seed)
        with open(args.truth, "w", encoding="utf-8") as stream:
            json.dump(scene_truth, stream, indent=1)
            stream.write("\n")
        counts = {kind: len(probes) for kind, probes in scene_truth["probes"].items()}
        print(f"wrote {args.truth}: probes {counts}", file=sys.stderr)


if __name__ == "__main__":
    main()
