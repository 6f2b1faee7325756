#!/usr/bin/env python3
"""mvog_merger: keeps a server's map the merge of other maps (launch/multi_robot.launch).

Subscribes to the mvog/MapBinary topics `~sources` (say, the `map` of each robot's mirror) and,
every `~period` seconds in which one of them changed, rebuilds the map of the server `~server`
(an mvog_node without sensors) from them: `reset`, then `merge_map` of each source's latest map
at its transform of `~transforms` (where that map lies in the merged map's frame: x, y, z in m and
yaw in degrees; exact for whole cells in x and y and multiples of 90 degrees, anything else is
refused by the server, which says why). Masses add (the paper's eqs. 7, 8), so each rebuild
starts from an empty map: merging a source twice would count its scans twice. Between the reset
and the last merge the server's readers see a part of the merge (a rebuild takes a few service
calls; the time is logged).

Parameters: ~sources (string[], required), ~transforms (list of [x, y, z, yaw_degrees], default:
all identity), ~server (default `mvog_merged`), ~period (s, default 5.0, on ROS time).
"""
import math
import threading
import time

import rospy
from geometry_msgs.msg import Quaternion, Transform, Vector3
from std_srvs.srv import Trigger

from mvog.msg import MapBinary
from mvog.srv import MergeMap


def to_transform(values, source):
    if len(values) != 4 or not all(math.isfinite(float(v)) for v in values):
        raise ValueError("~transforms: %s: want [x, y, z, yaw_degrees], finite" % source)
    x, y, z, yaw = (float(v) for v in values)
    half = math.radians(yaw) / 2.0
    return Transform(translation=Vector3(x, y, z),
                     rotation=Quaternion(0.0, 0.0, math.sin(half), math.cos(half)))


class Merger:
    def __init__(self):
        self.sources = rospy.get_param("~sources")
        if not self.sources or not all(isinstance(s, str) and s for s in self.sources):
            raise ValueError("~sources: want a list of MapBinary topics")
        transforms = rospy.get_param("~transforms", [[0.0, 0.0, 0.0, 0.0]] * len(self.sources))
        if len(transforms) != len(self.sources):
            raise ValueError("~transforms: %d for %d sources" % (len(transforms),
                                                                  len(self.sources)))
        self.transforms = [to_transform(t, s) for t, s in zip(transforms, self.sources)]
        server = rospy.resolve_name(rospy.get_param("~server", "mvog_merged"))
        period = float(rospy.get_param("~period", 5.0))
        if not (math.isfinite(period) and period > 0.0):
            raise ValueError("~period: want a finite number of seconds > 0")
        self.lock = threading.Lock()
        self.latest = [None] * len(self.sources)
        self.changed = False
        rospy.wait_for_service(server + "/merge_map")
        self.reset = rospy.ServiceProxy(server + "/reset", Trigger)
        self.merge = rospy.ServiceProxy(server + "/merge_map", MergeMap)
        for k, topic in enumerate(self.sources):
            rospy.Subscriber(topic, MapBinary, self.receive, callback_args=k, queue_size=1)
        rospy.loginfo("mvog_merger: merging %s into %s every %.1f s", ", ".join(self.sources),
                      server, period)
        self.timer = rospy.Timer(rospy.Duration(period), self.rebuild)

    def receive(self, message, k):
        with self.lock:
            self.latest[k] = message
            self.changed = True

    def rebuild(self, _event):
        with self.lock:
            if not self.changed:
                return
            self.changed = False
            maps = list(self.latest)
        start = time.monotonic()
        try:
            response = self.reset()
            if not response.success:
                rospy.logwarn("mvog_merger: reset refused: %s", response.message)
                return
            merged = []
            for source, binary, transform in zip(self.sources, maps, self.transforms):
                if binary is None:
                    continue
                response = self.merge(path="", map=binary, map_from_other=transform)
                if response.success:
                    merged.append("%s (%d bytes)" % (source, len(binary.data)))
                else:
                    rospy.logwarn("mvog_merger: %s refused: %s", source, response.message)
        except rospy.ServiceException as e:
            rospy.logwarn("mvog_merger: the server does not answer: %s", e)
            with self.lock:
                self.changed = True  # try again next period
            return
        rospy.loginfo("mvog_merger: merged %s in %.3f s", ", ".join(merged) or "nothing",
                      time.monotonic() - start)


def main():
    rospy.init_node("mvog_merger")
    try:
        Merger()
    except (ValueError, KeyError) as e:
        rospy.logfatal("mvog_merger: cannot start: %s", e)
        raise SystemExit(1)
    rospy.spin()


if __name__ == "__main__":
    main()
