#!/usr/bin/env python3
"""The load benchmark of RELIABILITY.md (run it with scripts/load.sh, which starts a ROS master).

A depth sensor turns and moves in a closed 20 m x 12 m x 3 m room: every message is a
PointCloud2 of --points points (float32 x, y, z in the sensor frame, 1 cm noise) published at
--rate Hz for --duration s, with its pose on /tf (map -> load_sensor, stamped like the cloud) at
twice that rate. With --depth WIDTHxHEIGHT the sensor is a depth camera instead (Kinect-like
intrinsics, 1 cm noise): every message is a depth image of --depth-encoding with its camera info,
in the optical frame load_sensor_optical (a static transform from load_sensor). With --lidar
BEAMSxCOLUMNS it is a rotating lidar: every message is a whole turn, BEAMS x COLUMNS points.
Meanwhile a client asks ~get_occupancy for --query-points random points of the room at
--query-rate Hz. The script starts its own mvog_node (the server's defaults but for
--resolution, --max-range and --insertion-threads) and reports:

- readings inserted per second (the server's own counters over the run),
- messages published, inserted, dropped by the server and counted (by queue), and lost before the
  server saw them (roscpp's subscriber queue of ~sensor_queue_size messages drops silently),
- query latency p50 / p99 / max, as the client sees it over a persistent connection
  (serialisation of the request and the answer included),
- the server's RSS and the map's bytes_held every --sample-period s.

This is a benchmark, not a test: nothing is asserted about time. It fails (exit 1) only if the
server dies, a query fails, or a message is counted twice.
"""
import argparse
import json
import os
import sys
import threading
import time

import numpy as np
import rospy
from geometry_msgs.msg import Point
from geometry_msgs.msg import TransformStamped
from tf2_msgs.msg import TFMessage
import tf2_ros

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "test",
                                "reliability"))
import mvog_reliability as rel  # noqa: E402
from mvog.srv import GetOccupancy  # noqa: E402

ROOM_MIN = np.array([-10.0, -6.0, 0.0])
ROOM_MAX = np.array([10.0, 6.0, 3.0])
SENSOR_FRAME = "load_sensor"
OPTICAL_FRAME = "load_sensor_optical"  # x right, y down, z forward


def arguments():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--points", type=int, default=300000, help="points per cloud")
    parser.add_argument("--depth", metavar="WIDTHxHEIGHT",
                        help="publish depth images of this size instead of clouds")
    parser.add_argument("--lidar", metavar="BEAMSxCOLUMNS",
                        help="publish the clouds of a rotating lidar instead, a turn a cloud")
    parser.add_argument("--depth-encoding", choices=("16UC1", "32FC1"), default="16UC1")
    parser.add_argument("--depth-stride", type=int, default=1, help="the server's ~depth_stride")
    parser.add_argument("--rate", type=float, default=30.0, help="messages per second")
    parser.add_argument("--duration", type=float, default=60.0, help="s of publishing")
    parser.add_argument("--query-points", type=int, default=10000)
    parser.add_argument("--query-rate", type=float, default=10.0)
    parser.add_argument("--resolution", type=float, default=0.05)
    parser.add_argument("--max-range", type=float, default=8.0)
    parser.add_argument("--insertion-threads", type=int, default=1)
    parser.add_argument("--sample-period", type=float, default=5.0, help="s between memory rows")
    parser.add_argument("--json", help="also write the figures to this file")
    return parser.parse_args(rospy.myargv()[1:])


def sensor_pose(t):
    """Position and yaw at time t (s): an ellipse around the room's centre at 0.4 m/s, turning."""
    angle = 0.08 * t
    position = np.array([6.0 * np.cos(angle), 3.0 * np.sin(angle), 1.2 + 0.4 * np.sin(0.3 * t)])
    return position, 0.5 * t


def room_distances(directions, position, yaw):
    """Distance along each unit direction (N, 3) of the sensor frame (float32) to the room's
    walls, floor and ceiling, the sensor at `position` turned by `yaw`."""
    c, s = np.float32(np.cos(yaw)), np.float32(np.sin(yaw))
    x, y, z = directions.T
    world = (c * x - s * y, s * x + c * y, z)
    distance = None
    for axis in range(3):
        with np.errstate(divide="ignore", invalid="ignore"):
            to_wall = np.where(world[axis] > 0, np.float32(ROOM_MAX[axis] - position[axis]),
                               np.float32(ROOM_MIN[axis] - position[axis])) / world[axis]
        to_wall[~(to_wall > 0)] = np.inf
        distance = to_wall if distance is None else np.minimum(distance, to_wall)
    return distance


class RaySet:
    """Unit directions in the sensor frame filling a 90 x 60 degree frustum around +x, with a
    range noise (1 cm) per direction; float32 throughout, so that a 300k-point cloud takes a few
    milliseconds to make."""

    def __init__(self, count, seed):
        random = np.random.default_rng(seed)
        azimuth = random.uniform(-np.pi / 4, np.pi / 4, count)
        elevation = random.uniform(-np.pi / 6, np.pi / 6, count)
        self.directions = np.stack([np.cos(elevation) * np.cos(azimuth),
                                    np.cos(elevation) * np.sin(azimuth),
                                    np.sin(elevation)], axis=1).astype(np.float32)
        self.noise = random.normal(0.0, 0.01, count).astype(np.float32)

    def room_cloud(self, position, yaw):
        """The room's walls, floor and ceiling where the rays hit them, in the sensor frame, as
        the bytes of float32 x, y, z."""
        distance = room_distances(self.directions, position, yaw)
        return (self.directions * (distance + self.noise)[:, None]).tobytes()


class RotatingLidar(RaySet):
    """A rotating lidar of `beams` beams from +2 to -24.8 degrees of elevation (a Velodyne
    HDL-64E's) and `columns` firings a turn, a whole turn a cloud, range noise (1 cm) per ray."""

    def __init__(self, beams, columns, seed):
        random = np.random.default_rng(seed)
        elevation = np.repeat(np.radians(np.linspace(2.0, -24.8, beams)), columns)
        azimuth = np.tile(np.linspace(-np.pi, np.pi, columns, endpoint=False), beams)
        self.directions = np.stack([np.cos(elevation) * np.cos(azimuth),
                                    np.cos(elevation) * np.sin(azimuth),
                                    np.sin(elevation)], axis=1).astype(np.float32)
        self.noise = random.normal(0.0, 0.01, beams * columns).astype(np.float32)


class DepthCamera:
    """A depth camera of width x height pixels looking along the sensor's +x, fx = fy = 525
    pixels at 640 wide (a Kinect's 62 x 49 degrees), with a range noise (1 cm) per pixel."""

    def __init__(self, width, height, encoding, seed):
        self.width, self.height, self.encoding = width, height, encoding
        self.f = 525.0 * width / 640.0
        self.cx, self.cy = (width - 1) / 2.0, (height - 1) / 2.0
        u, v = np.meshgrid(np.arange(width), np.arange(height))
        optical = np.stack([(u.ravel() - self.cx) / self.f, (v.ravel() - self.cy) / self.f,
                            np.ones(width * height)], axis=1)
        self.depth_per_range = (1.0 / np.linalg.norm(optical, axis=1)).astype(np.float32)
        unit = optical * self.depth_per_range[:, None]
        # The optical frame's x right, y down, z forward in the sensor's x forward, y left, z up.
        self.directions = np.stack([unit[:, 2], -unit[:, 0], -unit[:, 1]],
                                   axis=1).astype(np.float32)
        self.noise = np.random.default_rng(seed).normal(0.0, 0.01, width * height).astype(
            np.float32)

    def room_image(self, position, yaw):
        """The depth image's bytes (16UC1 millimetres or 32FC1 metres) of the room."""
        depth = (room_distances(self.directions, position, yaw) + self.noise) * self.depth_per_range
        if self.encoding == "16UC1":
            return (depth * 1000.0 + 0.5).astype("<u2").tobytes()
        return depth.astype("<f4").tobytes()

    def camera_info(self, image):
        return rel.camera_info(image, fx=self.f, fy=self.f, cx=self.cx, cy=self.cy)


def optical_frame_transform():
    """load_sensor -> load_sensor_optical: the optical axes (REP-103's camera convention)."""
    t = TransformStamped()
    t.header.frame_id = SENSOR_FRAME
    t.child_frame_id = OPTICAL_FRAME
    t.transform.rotation.x, t.transform.rotation.y = -0.5, 0.5
    t.transform.rotation.z, t.transform.rotation.w = -0.5, 0.5
    return t


class Sampler(threading.Thread):
    """RSS of the server and its statistics every `period` s."""

    def __init__(self, server, period):
        super().__init__(daemon=True)
        self.server, self.period, self.rows = server, period, []
        self.done = threading.Event()
        self.start_time = time.monotonic()

    def run(self):
        while not self.done.wait(self.period):
            statistics = self.server.statistics
            self.rows.append({"t": round(time.monotonic() - self.start_time, 1),
                              "rss_mb": rel.rss_kb(self.server.process.pid) / 1024.0,
                              "bytes_held_mb": statistics.bytes_held / 1e6,
                              "messages_inserted": statistics.messages_inserted})


class Querier(threading.Thread):
    """A planner's client: one persistent connection, the same random points of the room."""

    def __init__(self, server, points, rate):
        super().__init__(daemon=True)
        random = np.random.default_rng(7)
        self.points = [Point(*p) for p in random.uniform(ROOM_MIN, ROOM_MAX, (points, 3))]
        self.service = rospy.ServiceProxy(server.ns + "/get_occupancy", GetOccupancy,
                                          persistent=True)
        self.period = 1.0 / rate
        self.latencies, self.failures, self.known = [], [], []
        self.done = threading.Event()

    def run(self):
        while not self.done.is_set():
            start = time.monotonic()
            try:
                response = self.service(frame_id="", points=self.points)
            except (rospy.ServiceException, rospy.ROSException) as e:
                self.failures.append(str(e))
                response = None
            self.latencies.append(time.monotonic() - start)
            if response is not None and response.success:
                self.known.append(sum(1 for state in response.state if state != 0))
            elif response is not None:
                self.failures.append(response.message)
            self.done.wait(max(0.0, self.period - (time.monotonic() - start)))
        self.service.close()


def percentile(values, fraction):
    ordered = sorted(values)
    return ordered[min(len(ordered) - 1, int(fraction * len(ordered)))] if ordered else float("nan")


def main():
    args = arguments()
    rospy.init_node("mvog_load_test", disable_signals=True)
    server = rel.Server("mvog_load", {"resolution": args.resolution, "max_range": args.max_range,
                                      "insertion_threads": args.insertion_threads,
                                      "depth_stride": args.depth_stride,
                                      "statistics_period": 1.0, "publish_period": 1.0,
                                      "binary_map_period": 5.0}).wait_ready()
    sampler = Sampler(server, args.sample_period)
    querier = Querier(server, args.query_points, args.query_rate)
    try:
        tf_publisher = rospy.Publisher("/tf", TFMessage, queue_size=100)
        if args.depth:
            width, height = (int(v) for v in args.depth.split("x"))
            cameras = [DepthCamera(width, height, args.depth_encoding, seed) for seed in range(4)]
            template = rel.depth_image([0] * (width * height), width,
                                       encoding=args.depth_encoding, frame=OPTICAL_FRAME)
            static_broadcaster = tf2_ros.StaticTransformBroadcaster()
            static_broadcaster.sendTransform(optical_frame_transform())
            what = "%dx%d %s depth images" % (width, height, args.depth_encoding)
        elif args.lidar:
            beams, columns = (int(v) for v in args.lidar.split("x"))
            ray_sets = [RotatingLidar(beams, columns, seed) for seed in range(4)]
            template = rel.cloud([], width=beams * columns, frame=SENSOR_FRAME,
                                 data=bytes(12 * beams * columns))
            what = "%d-beam lidar turns of %d columns" % (beams, columns)
        else:
            ray_sets = [RaySet(args.points, seed) for seed in range(4)]
            template = rel.cloud([], width=args.points, frame=SENSOR_FRAME,
                                 data=bytes(12 * args.points))
            what = "%d-point clouds" % args.points
        before = server.stats()
        sampler.start()
        querier.start()
        print("publishing %s at %.0f Hz for %.0f s, querying %d points at %.0f Hz ..."
              % (what, args.rate, args.duration, args.query_points, args.query_rate), flush=True)
        published, skipped, slot = 0, 0, 0
        start = time.monotonic()
        while slot < args.duration * args.rate:
            now = time.monotonic()
            due = start + slot / args.rate
            if now < due:
                time.sleep(due - now)
            elif now - due >= 1.0 / args.rate:
                # This machine could not make and send the previous cloud within its period: the
                # slots missed are skipped (and reported), so that the run lasts --duration.
                missed = int((now - due) * args.rate)
                skipped += missed
                slot += missed
                continue
            slot += 1
            stamp = rospy.Time.now()
            t = time.monotonic() - start
            position, yaw = sensor_pose(t)
            transform = rel.transform("map", SENSOR_FRAME, *position, yaw=yaw, stamp=stamp)
            tf_publisher.publish(TFMessage([transform]))
            template.header.stamp = stamp
            if args.depth:
                camera = cameras[published % len(cameras)]
                template.data = camera.room_image(position, yaw)
                server.camera_infos.publish(camera.camera_info(template))
                server.depth_images.publish(template)
            else:
                template.data = ray_sets[published % len(ray_sets)].room_cloud(position, yaw)
                server.clouds.publish(template)
            published += 1
            # A second pose between clouds, so that tf interpolates (poses at twice the rate).
            half = stamp + rospy.Duration(0.5 / args.rate)
            position, yaw = sensor_pose(t + 0.5 / args.rate)
            tf_publisher.publish(TFMessage([rel.transform("map", SENSOR_FRAME, *position, yaw=yaw,
                                                          stamp=half)]))
        publishing_seconds = time.monotonic() - start
        # The server drains what it queued; then its counters are final.
        final = server.stats()
        while True:
            time.sleep(2.0)
            now = server.stats()
            if now.messages_inserted == final.messages_inserted:
                break
            final = now
        alive = server.alive()
        rss_end = rel.rss_kb(server.process.pid) / 1024.0 if alive else float("nan")
    except AssertionError as e:  # a wait for the server timed out
        print("FAILED: %s (server log: %s)" % (e, server.log_path))
        return 1
    finally:
        querier.done.set()
        sampler.done.set()
        if querier.is_alive():
            querier.join()
        if sampler.is_alive():
            sampler.join()
        server.stop()

    inserted = final.messages_inserted - before.messages_inserted
    dropped_queue = final.messages_dropped_queue - before.messages_dropped_queue
    dropped_tf = final.messages_dropped_tf - before.messages_dropped_tf
    dropped_invalid = final.messages_dropped_invalid - before.messages_dropped_invalid
    dropped_camera_info = (final.messages_dropped_camera_info
                           - before.messages_dropped_camera_info)
    counted = inserted + dropped_queue + dropped_tf + dropped_invalid + dropped_camera_info
    readings = final.readings_inserted - before.readings_inserted
    insertion_seconds = final.insertion_seconds - before.insertion_seconds
    figures = {
        "messages": what, "points_per_cloud": None if args.depth else len(template.data) // 12,
        "cloud_rate_hz": args.rate, "resolution": args.resolution,
        "published": published, "slots_skipped": skipped, "publishing_seconds": publishing_seconds,
        "messages_inserted": inserted, "messages_dropped_queue": dropped_queue,
        "messages_dropped_tf": dropped_tf, "messages_dropped_invalid": dropped_invalid,
        "messages_dropped_camera_info": dropped_camera_info,
        "messages_lost_uncounted": published - counted,
        "readings_inserted_per_second": readings / publishing_seconds,
        "readings_per_insertion_second": readings / insertion_seconds if insertion_seconds else 0,
        "queries": len(querier.latencies), "query_points": args.query_points,
        "query_failures": len(querier.failures),
        "query_latency_p50_s": percentile(querier.latencies, 0.5),
        "query_latency_p99_s": percentile(querier.latencies, 0.99),
        "query_latency_max_s": max(querier.latencies, default=float("nan")),
        "known_points_last_query": querier.known[-1] if querier.known else 0,
        "rss_end_mb": rss_end, "bytes_held_end_mb": final.bytes_held / 1e6,
        "memory": sampler.rows, "server_alive": alive,
    }
    print("\n%s: %d published in %.1f s (%d slots skipped: publisher too slow), %d inserted, "
          "%d dropped from the insertion queue (counted), %d dropped waiting for tf, %d invalid, "
          "%d without camera info, %d lost uncounted"
          % (what, published, publishing_seconds, skipped, inserted, dropped_queue, dropped_tf,
             dropped_invalid, dropped_camera_info, published - counted))
    print("readings inserted: %.0f per second of publishing, %.0f per second of insertion"
          % (figures["readings_inserted_per_second"], figures["readings_per_insertion_second"]))
    print("queries of %d points: %d, %d failed; latency p50 %.3f s, p99 %.3f s, max %.3f s; "
          "%d of %d points known at the end"
          % (args.query_points, len(querier.latencies), len(querier.failures),
             figures["query_latency_p50_s"], figures["query_latency_p99_s"],
             figures["query_latency_max_s"], figures["known_points_last_query"],
             args.query_points))
    print("\n| t (s) | server RSS (MB) | map bytes_held (MB) | messages inserted |")
    print("|---:|---:|---:|---:|")
    for row in sampler.rows:
        print("| %.0f | %.1f | %.1f | %d |" % (row["t"], row["rss_mb"], row["bytes_held_mb"],
                                              row["messages_inserted"]))
    if args.json:
        temporary = args.json + ".tmp"
        with open(temporary, "w") as f:
            json.dump(figures, f, indent=1)
        os.replace(temporary, args.json)
    problems = []
    if not alive:
        problems.append("the server died (log: %s)" % server.log_path)
    if querier.failures:
        problems.append("%d queries failed: %s" % (len(querier.failures), querier.failures[0]))
    if published - counted < 0:
        problems.append("a message was counted twice")
    for problem in problems:
        print("FAILED: " + problem)
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main())
