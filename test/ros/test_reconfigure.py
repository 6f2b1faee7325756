#!/usr/bin/env python3
"""dynamic_reconfigure on a running mapping server (see reconfigure.test and README).

One mvog_node named mvog_mapper, as mapper.launch names it. A laser beam hits a cell once and
then crosses it once (its p between 0 and 1; each scan a group of its own). `rosrun dynamic_reconfigure dynparam set` puts the
occupancy threshold below that p, the Python client above it: ~projected_map and ~get_occupancy
follow each time. Bad values (a threshold of 1.5, forgetting without decay, cross-section heights
that are not numbers or not as many as at start) are refused: the reported configuration and the
parameter server keep the old values, the server warns naming the parameter, the map and what it
publishes stay as they were. A new cross-section height moves ~cross_section_0.
"""
import math
import os
import subprocess
import sys
import unittest

import rospy
import rostest
from dynamic_reconfigure.client import Client

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "lifecycle"))
import mvog_lifecycle as life  # noqa: E402
from mvog_lifecycle import rel  # noqa: E402

NAME = "mvog_mapper"
ANGLE = 0.02  # rad: the beam, off the cell boundaries
HIT = (2.0 * math.cos(ANGLE), 2.0 * math.sin(ANGLE), rel.LASER_HEIGHT)
OCCUPIED_VALUE, FREE_VALUE = 100, 0


def beam(distance):
    return rel.scan([distance], angle_min=ANGLE, angle_increment=0.1)


class Reconfigure(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.broadcaster = rel.init_test_node("test_reconfigure")
        # Each scan a group of its own (~hit_memory_scans 0): the second beam's crossing counts
        # against the first's hit, which the default's scan groups of line scans would keep.
        cls.server = rel.Server(NAME, {"publish_period": 0.2, "cross_section_heights": [0.5],
                                       "decay_factor": 1.0, "hit_memory_scans": 0}).wait_ready()
        cls.server.scans.publish(beam(2.0))
        cls.server.wait_counter("messages_inserted", 1)
        cls.server.scans.publish(beam(3.0))  # crosses the cell it hit
        cls.server.wait_counter("messages_inserted", 2)
        cls.projected = life.LatestGrid(cls.server.ns + "/projected_map")
        cls.cross_section = life.LatestGrid(cls.server.ns + "/cross_section_0")
        cls.client = Client(cls.server.ns, timeout=rel.TIMEOUT)

    @classmethod
    def tearDownClass(cls):
        cls.client.close()
        assert cls.server.stop_alive(), "the server died"

    def probability(self):
        response = self.server.occupancy([HIT])
        self.assertTrue(response.success, response.message)
        return response.probability[0], response.state[0]

    def wait_projected(self, value):
        rel.wait_for(lambda: self.projected.grid is not None and
                     self.projected.value_at(HIT[0], HIT[1]) == value,
                     "~projected_map to show %d at the cell (now %s)" % (
                         value, self.projected.grid and self.projected.value_at(HIT[0], HIT[1])))

    def refused(self, values, parameter, reason):
        """Sends bad `values`: all are refused, naming `parameter` and `reason`."""
        before = self.client.get_configuration(timeout=rel.TIMEOUT)
        snapshot = self.server.snapshot()
        grids = self.projected.messages
        reported = self.client.update_configuration(values)
        for name in values:
            self.assertEqual(reported[name], before[name], name)
            self.assertEqual(rospy.get_param(self.server.ns + "/" + name), before[name], name)
        warning = "refused, the values in force are kept: ~%s: %s" % (parameter, reason)
        rel.wait_for(lambda: warning in self.server.output(), "the warning '%s'" % warning)
        self.assertEqual(self.server.snapshot(), snapshot)
        self.assertEqual(self.projected.messages, grids, "a refused value republished the grid")

    def test_1_the_threshold_changes_and_the_next_grid_follows(self):
        p, _ = self.probability()
        self.assertTrue(0.0 < p < 1.0, "the cell's p is %s" % p)
        low, high = round(p - 0.1, 3), round(p + 0.1, 3)
        # The command of the README, as a user types it.
        subprocess.check_call(["rosrun", "dynamic_reconfigure", "dynparam", "set", "/" + NAME,
                               "occupancy_threshold", str(low)])
        self.wait_projected(OCCUPIED_VALUE)
        self.assertEqual(self.probability()[1], life.OCCUPIED)
        self.assertEqual(rospy.get_param(self.server.ns + "/occupancy_threshold"), low)

        reported = self.client.update_configuration({"occupancy_threshold": high})
        self.assertEqual(reported["occupancy_threshold"], high)
        self.wait_projected(FREE_VALUE)
        self.assertEqual(self.probability()[1], life.FREE)

    def test_2_bad_values_are_refused_and_the_old_ones_kept(self):
        self.wait_projected(FREE_VALUE)  # test_1's threshold, above the cell's p
        self.refused({"occupancy_threshold": 1.5}, "occupancy_threshold", "must be in [0, 1)")
        self.refused({"occupancy_threshold": -0.1}, "occupancy_threshold", "must be in [0, 1)")
        self.refused({"forget_mass": 0.5}, "forget_mass", "needs decay")
        self.refused({"publish_period": 0.0}, "publish_period", "must be in (0, ")
        self.refused({"cross_section_heights_text": "1.0, 2.0"}, "cross_section_heights_text",
                     "2 heights, not 1")
        self.refused({"cross_section_heights_text": "one"}, "cross_section_heights_text",
                     "'one' is not a number")
        self.refused({"cross_section_heights_text": "1e9"}, "cross_section_heights",
                     "every height must be finite and within max_coordinate")
        # Several values at once, one bad: none is taken.
        self.refused({"occupancy_threshold": 0.2, "decay_factor": 2.0}, "decay_factor",
                     "must be in (0, 1]")
        self.assertEqual(self.probability()[1], life.FREE)
        self.assertTrue(self.server.alive())

    def test_4_max_range_changes_and_the_next_scan_follows(self):
        angle = 1.0  # rad: a beam of its own, away from the cell of the other tests
        along = lambda distance: (distance * math.cos(angle), distance * math.sin(angle),  # noqa
                                  rel.LASER_HEIGHT)
        self.refused({"max_range": 0.0}, "max_range", "must be")
        self.refused({"min_range": 2.0, "max_range": 1.5}, "min_range",
                     "must be smaller than max_range")
        reported = self.client.update_configuration({"max_range": 1.5})
        self.assertEqual(reported["max_range"], 1.5)
        inserted = self.server.stats().messages_inserted
        self.server.scans.publish(rel.scan([2.5], angle_min=angle, angle_increment=0.1))
        self.server.wait_counter("messages_inserted", inserted + 1)
        # The hit at 2.5 m lies beyond ~max_range: free space up to 1.5 m, nothing beyond.
        states = self.server.occupancy([along(1.0), along(2.5)]).state
        self.assertEqual(list(states), [life.FREE, life.UNKNOWN])

    def test_3_a_new_cross_section_height_moves_its_grid(self):
        rel.wait_for(lambda: self.cross_section.grid is not None, "~cross_section_0")
        self.assertAlmostEqual(self.cross_section.grid.info.origin.position.z, 0.5)
        projected_before = self.projected.messages
        reported = self.client.update_configuration({"cross_section_heights_text": "0.75"})
        self.assertEqual(reported["cross_section_heights_text"], "0.75")
        rel.wait_for(lambda: abs(self.cross_section.grid.info.origin.position.z - 0.75) < 1e-9,
                     "~cross_section_0 at z = 0.75")
        # An accepted change republishes every grid, ~projected_map too, on a topic of its own
        # that may arrive after ~cross_section_0's: awaited here, or it would land in the next
        # test's count of grids a refused value must not republish.
        rel.wait_for(lambda: self.projected.messages > projected_before,
                     "~projected_map republished")


if __name__ == "__main__":
    rostest.rosrun("mvog", "test_reconfigure", Reconfigure, sys.argv)
