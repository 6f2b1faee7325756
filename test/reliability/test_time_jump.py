#!/usr/bin/env python3
"""Time jumping backwards, as when a bag is replayed with `rosbag play --loop --clock` (see
time_jump.test and RELIABILITY.md).

The test is the clock: it publishes /clock (from t = 1000 s), a moving map -> base transform on
/tf at every tick and LaserScans in `base`. After a first pass it sets the clock back to 1000 s
and replays from a pose 6 m away. tf2_ros::TransformListener clears its buffer when it sees the
clock go back (its warning "Detected jump back in time ... Clearing TF buffer" is expected in the
server's output); without that, the scans of the second pass would be placed with the first
pass's transforms of the same stamps. Checked: the second pass is mapped where it was taken, the
first pass is still in the map, the server's timers (statistics) keep running, it stays alive.
"""
import sys
import threading
import time
import unittest

import rospy
import rostest
from rosgraph_msgs.msg import Clock
from tf2_msgs.msg import TFMessage

import mvog_reliability as rel

START = 1000.0
TICK = 0.02       # s of sim time per clock message
SPEED = 2.0       # sim time runs at twice the wall time
SCANS = 20        # per pass
SCAN_PERIOD = 0.2  # s of sim time between scans
BASE_HEIGHT = 0.5
OCCUPIED = 2


class SimClock(threading.Thread):
    """Publishes /clock and map -> base (x moving slowly, y = offset) at every tick."""

    def __init__(self):
        super().__init__(daemon=True)
        self.lock = threading.Lock()
        self.time = START
        self.offset = 0.05
        self.running = True
        self.clock = rospy.Publisher("/clock", Clock, queue_size=10)
        self.tf = rospy.Publisher("/tf", TFMessage, queue_size=100)

    def now(self):
        with self.lock:
            return rospy.Time.from_sec(self.time)

    def jump(self, to, offset):
        with self.lock:
            self.time = to
            self.offset = offset

    def run(self):
        while self.running:
            with self.lock:
                self.time += TICK
                stamp = rospy.Time.from_sec(self.time)
                x = 0.05 + 0.001 * (self.time - START)  # near cell centres: no ray on a wall
                offset = self.offset
            self.clock.publish(Clock(clock=stamp))
            self.tf.publish(TFMessage([rel.transform("map", "base", x=x, y=offset,
                                                     z=BASE_HEIGHT, stamp=stamp)]))
            time.sleep(TICK / SPEED)


class TimeJump(unittest.TestCase):
    def test_scans_after_a_jump_back_in_time_are_mapped_where_they_were_taken(self):
        rospy.init_node("test_time_jump", disable_signals=True)
        self.assertTrue(rospy.get_param("/use_sim_time"))
        clock = SimClock()
        clock.start()
        server = rel.Server("mapper_time_jump", {"sensor_queue_size": 10}).wait_ready()
        try:
            def one_pass(first_count):
                for k in range(SCANS):
                    target = clock.now() + rospy.Duration(SCAN_PERIOD)
                    rel.wait_for(lambda: clock.now() >= target, "the clock to advance")
                    server.scans.publish(rel.scan([2.0] * 64, frame="base", stamp=clock.now()))
                    # One at a time, each inserted before the next (no queue in the way).
                    server.wait_counter("messages_inserted", first_count + k + 1)

            one_pass(0)
            before = server.statistics
            self.assertEqual(before.messages_dropped_tf, 0)
            # The bag restarts: the clock goes back, the robot is elsewhere in the new pass.
            clock.jump(START, 6.05)
            rel.wait_for(lambda: "Detected jump back in time" in server.output(),
                         "tf2_ros to report the jump back and clear its buffer")
            rel.wait_for(lambda: server.statistics.header.stamp.to_sec() < START + 5.0,
                         "statistics stamped after the jump (the server's timers run on)")
            one_pass(before.messages_inserted)
            after = server.statistics

            # Where each pass was taken (walls 2 m around the base), obstacles; the second pass
            # was not placed with the first pass's transforms.
            response = server.occupancy([(2.05, 0.05, BASE_HEIGHT), (-1.95, 0.05, BASE_HEIGHT),
                                         (2.05, 6.05, BASE_HEIGHT), (-1.95, 6.05, BASE_HEIGHT),
                                         (0.05, 8.05, BASE_HEIGHT)])
            self.assertTrue(response.success, response.message)
            self.assertEqual(list(response.state), [OCCUPIED] * 5, list(response.probability))
            self.assertEqual(after.messages_dropped_tf, 0)
            self.assertEqual(after.messages_dropped_invalid, 0)
            self.assertTrue(server.alive())
            print("\n%d scans before the jump, %d after, all mapped in place; tf buffer cleared"
                  % (SCANS, SCANS))

            # The clock stops (a replay over without --keep-alive): a query in a frame tf does
            # not know is refused after ~tf_timeout (0.2 s) of wall time, not left waiting for
            # ROS time that no longer moves; one in a known frame is answered.
            clock.running = False
            clock.join()
            started = time.monotonic()
            response = server.occupancy([(0.0, 0.0, 0.0)], frame_id="nowhere")
            waited = time.monotonic() - started
            self.assertFalse(response.success)
            self.assertIn("cannot transform from 'nowhere'", response.message)
            self.assertLess(waited, 10.0, "the refusal waited on the stopped clock")
            response = server.occupancy([(0.0, 0.0, 0.0)], frame_id="base")
            self.assertTrue(response.success, response.message)
            print("with the clock stopped: a query in an unknown frame refused after %.2f s"
                  % waited)
        finally:
            clock.running = False
            clock.join()
            server.stop()


if __name__ == "__main__":
    rostest.rosrun("mvog", "test_time_jump", TimeJump, sys.argv)
