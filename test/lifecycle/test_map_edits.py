#!/usr/bin/env python3
"""~clear_box and ~merge_map of a running mvog_node, and the bad input they refuse (see
map_edits.test, README and RELIABILITY.md).

The scene: a laser 0.5 m up at the map origin sees a ring of wall 2 m around it (360 degrees), at
0.1 m. Checked: a box cleared is unknown inside, every cell outside its footprint keeps its lists
bit for bit, and the markers and grids show it; a box given in a turned frame clears the map
frame's box around its corners; merging a map with no transform is mass-exact, with a quarter turn
and a shift it lands where the transform says; every refused request leaves the map byte for byte
as it was. The outcomes of the bad input are printed as a table (RELIABILITY.md reproduces it).
"""
import math
import os
import re
import sys
import unittest

import rostest
from std_srvs.srv import Trigger

import mvog_lifecycle as life
from mvog_lifecycle import rel

RESOLUTION = 0.1
RING = 2.0        # m, the wall's distance from the laser
BEAMS = 720
NAN, INF = float("nan"), float("inf")
OUTCOMES = []     # (input, outcome) for RELIABILITY.md


class MapEdits(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.broadcaster = rel.init_test_node("test_map_edits")
        cls.broadcaster.sendTransform([rel.transform("map", "laser", z=rel.LASER_HEIGHT),
                                       rel.transform("map", "turned", yaw=math.pi / 4.0)])
        cls.server = rel.Server("mapper_edits", {"publish_period": 0.1}).wait_ready()
        cls.node = life.Node(cls.server.ns)
        cls.merger = rel.Server("merger_edits", {"publish_period": 0.1},
                                directory=cls.server.directory).wait_ready()
        cls.merger_node = life.Node(cls.merger.ns)

    @classmethod
    def tearDownClass(cls):
        alive = cls.server.alive() and cls.merger.alive()
        cls.merger.stop()
        cls.server.stop()
        print("\n| input | outcome |\n|---|---|")
        for what, outcome in OUTCOMES:
            print("| %s | %s |" % (what, outcome))
        sys.stdout.flush()
        assert alive, "a server died"

    def setUp(self):
        for server in (self.server, self.merger):
            server.service("reset", Trigger)()
        before = self.server.stats().messages_inserted
        for _ in range(3):
            self.server.scans.publish(rel.scan([RING] * BEAMS))
        self.server.wait_counter("messages_inserted", before + 3)

    # ---- clear_box ------------------------------------------------------------------------

    def test_a_cleared_box_is_unknown_and_the_rest_unchanged_bit_for_bit(self):
        occupied = life.MarkerState(self.server.ns + "/occupied")
        grid = life.LatestGrid(self.server.ns + "/projected_map")
        rel.wait_for(lambda: grid.messages > 0 and occupied.messages > 0, "markers and grids")
        _, before = life.read_map(self.node.snapshot())
        wall = (RING * math.cos(0.7), RING * math.sin(0.7), rel.LASER_HEIGHT)
        inside = [(1.0, 1.0, rel.LASER_HEIGHT), wall]
        outside = [(-1.0, -1.0, rel.LASER_HEIGHT), (-RING, 0.05, rel.LASER_HEIGHT)]
        self.assertEqual(self.node.states(inside), [life.FREE, life.OCCUPIED])
        self.assertEqual(self.node.states(outside), [life.FREE, life.OCCUPIED])
        rel.wait_for(lambda: grid.value_at(1.05, 1.05) == 0, "the box's cells free in the grid")

        # On cell boundaries, every height: the columns inside go whole.
        response = self.node.clear_box((0.0, 0.0, -INF), (3.0, 3.0, INF))
        self.assertTrue(response.success, response.message)
        self.assertGreater(response.cells_changed, 0)
        self.assertEqual(self.node.states(inside), [life.UNKNOWN, life.UNKNOWN])
        self.assertEqual(self.node.states(outside), [life.FREE, life.OCCUPIED])
        _, after = life.read_map(self.node.snapshot())
        footprint = lambda cell: 0 <= cell[0] < 30 and 0 <= cell[1] < 30  # noqa: E731
        self.assertEqual(response.cells_changed, sum(1 for c in before if footprint(c)))
        self.assertEqual({c: v for c, v in before.items() if not footprint(c)}, after,
                         "cells outside the box changed")
        # The outputs follow: no occupied marker and no known grid cell in the box any more.
        rel.wait_for(lambda: not any(0.0 < x < 3.0 and 0.0 < y < 3.0
                                     for x, y, _ in occupied.points()),
                     "the box's occupied markers to go")
        rel.wait_for(lambda: grid.value_at(1.05, 1.05) == -1 and
                     grid.value_at(wall[0], wall[1]) == -1, "the box's grid cells to be unknown")
        self.assertEqual(grid.value_at(-1.05, -1.05), 0)
        self.assertTrue(any(x < 0.0 for x, _, _ in occupied.points()))

        # Between two heights: the laser's plane (0.5 m) goes, nothing is seen there any more.
        response = self.node.clear_box((-3.0, -3.0, 0.4), (0.0, 0.0, 0.6))
        self.assertTrue(response.success, response.message)
        self.assertEqual(self.node.states([(-1.0, -1.0, rel.LASER_HEIGHT)]), [life.UNKNOWN])

    def test_a_box_in_a_turned_frame_clears_the_map_box_around_its_corners(self):
        # A 0.4 m square around (-2, 0) of a frame turned by 45 degrees: a diamond around
        # (-1.41, -1.41) in the map frame, cleared over the box of the map frame that holds its
        # corners, [-1.70, -1.13] in x and y: the cells [-1.7, -1.1).
        self.assertEqual(self.node.states([(-1.25, -1.25, 0.5), (-1.0, -1.0, 0.5)]),
                         [life.FREE, life.FREE])
        _, before = life.read_map(self.node.snapshot())
        response = self.node.clear_box((-2.2, -0.2, 0.0), (-1.8, 0.2, 1.0), frame_id="turned")
        self.assertTrue(response.success, response.message)
        self.assertEqual(response.cells_changed,
                         sum(1 for x, y in before if -17 <= x < -11 and -17 <= y < -11))
        # (-1.25, -1.25) lies outside the diamond, inside the box around it.
        self.assertEqual(self.node.states([(-1.25, -1.25, 0.5), (-1.0, -1.0, 0.5)]),
                         [life.UNKNOWN, life.FREE])

    # ---- merge_map ------------------------------------------------------------------------

    def test_merging_with_no_transform_is_mass_exact(self):
        source = self.node.snapshot()
        with open(os.path.join(self.server.directory, "source.mvog"), "wb") as f:
            f.write(source)
        # Into an empty map: the same map, byte for byte.
        response = self.merger_node.merge_map(path="source.mvog")
        self.assertTrue(response.success, response.message)
        self.assertEqual(self.merger_node.snapshot(), source)
        # Into itself: the same volumes, every mass doubled exactly.
        response = self.node.merge_map(path="source.mvog")
        self.assertTrue(response.success, response.message)
        _, once = life.read_map(source)
        _, twice = life.read_map(self.node.snapshot())
        self.assertEqual(set(once), set(twice))
        for cell, (positive, negative) in once.items():
            self.assertEqual(twice[cell], ([(b, t, 2 * m) for b, t, m in positive],
                                           [(b, t, 2 * m) for b, t, m in negative]), cell)

    def test_a_quarter_turn_and_a_shift_of_whole_cells_move_the_map_exactly(self):
        wall = (RING - 0.05, 0.05, rel.LASER_HEIGHT)
        self.assertEqual(self.node.states([wall]), [life.OCCUPIED])
        response = self.merger_node.merge_map(
            data=self.node.snapshot(),
            map_from_other=life.transform(x=1.0, y=-0.3, z=0.2, yaw=math.pi / 2.0))
        self.assertTrue(response.success, response.message)
        # (x, y, z) of the other map is (1 - y, x - 0.3, z + 0.2) here.
        moved = (1.0 - wall[1], wall[0] - 0.3, wall[2] + 0.2)
        self.assertEqual(self.merger_node.states([moved, wall]), [life.OCCUPIED, life.UNKNOWN])

    # ---- Bad input ------------------------------------------------------------------------

    def expect_refused(self, what, request, *message_parts):
        """Sends a bad request: refused, saying so, the map byte for byte as it was."""
        snapshot = self.node.snapshot()
        response = request()
        self.assertFalse(response.success, what)
        for part in message_parts:
            self.assertIn(part, response.message, what)
        self.assertEqual(self.node.snapshot(), snapshot, what + ": the map changed")
        OUTCOMES.append((what, "refused, map untouched: \"%s\"" % re.sub(
            re.escape(self.server.directory), "MAP_DIR", response.message)))

    def test_bad_merges_are_refused_and_leave_the_map_untouched(self):
        other = self.node.snapshot()
        flipped = bytearray(other)
        flipped[len(flipped) // 2] ^= 0x04
        finer = life.patched_header(other, 16, "<d", RESOLUTION / 2)
        rules = life.read_map(other)[0]["rules"]
        self.assertNotEqual(rules & 2, 0, "the server counts mass per scan")
        per_reading = life.patched_header(other, 48, "<I", rules & ~2)
        with open(os.path.join(self.server.directory, "other.mvog"), "wb") as f:
            f.write(other)
        outside = os.path.join(os.path.dirname(self.server.directory), "outside.mvog")
        merge = self.node.merge_map
        cases = [
            ("MergeMap: a corrupt MapBinary (one bit flipped)",
             lambda: merge(data=bytes(flipped)), "checksum"),
            ("MergeMap: a foreign MapBinary (PNG)",
             lambda: merge(data=b"\x89PNG\r\n\x1a\n" + b"\0" * 100), "not an MVOG map"),
            ("MergeMap: a truncated MapBinary", lambda: merge(data=other[:-9]), "truncated"),
            ("MergeMap: neither a path nor a map", lambda: merge(), "truncated"),
            ("MergeMap: a path and a map", lambda: merge(path="other.mvog", data=other),
             "not both"),
            ("MergeMap: a map of another resolution", lambda: merge(data=finer), "resolution"),
            ("MergeMap: a map that counts mass per reading",
             lambda: merge(data=per_reading), "count mass differently"),
            ("MergeMap: a NaN translation",
             lambda: merge(data=other, map_from_other=life.transform(x=NAN)), "not finite"),
            ("MergeMap: a NaN rotation",
             lambda: merge(data=other, map_from_other=life.transform(quaternion=(NAN, 0, 0, 1))),
             "unit quaternion"),
            ("MergeMap: a rotation of all zeros (no w)",
             lambda: merge(data=other, map_from_other=life.transform(quaternion=(0, 0, 0, 0))),
             "unit quaternion"),
            ("MergeMap: a yaw of 45 degrees",
             lambda: merge(data=other, map_from_other=life.transform(yaw=math.pi / 4.0)),
             "multiple of 90 degrees"),
            ("MergeMap: a roll of 90 degrees",
             lambda: merge(data=other, map_from_other=life.transform(
                 quaternion=(math.sqrt(0.5), 0.0, 0.0, math.sqrt(0.5)))), "roll or pitch"),
            ("MergeMap: a shift of half a cell",
             lambda: merge(data=other, map_from_other=life.transform(x=RESOLUTION / 2)),
             "whole number of cells"),
            ("MergeMap: a path outside ~map_directory", lambda: merge(path=outside),
             "outside the map directory"),
            ("MergeMap: '..' out of ~map_directory", lambda: merge(path="../outside.mvog"),
             "outside the map directory"),
            ("MergeMap: a path that does not exist", lambda: merge(path="missing.mvog"),
             "does not exist"),
        ]
        with open(outside, "wb") as f:
            f.write(other)
        try:
            for what, request, part in cases:
                self.expect_refused(what, request, part)
        finally:
            os.unlink(outside)

    def test_bad_boxes_are_refused_and_leave_the_map_untouched(self):
        box = self.node.clear_box
        cases = [
            ("ClearBox: an empty box (min = max in z)",
             lambda: box((0.0, 0.0, 0.5), (1.0, 1.0, 0.5)), "empty in z"),
            ("ClearBox: an inverted box", lambda: box((1.0, 0.0, 0.0), (0.0, 1.0, 1.0)),
             "inverted"),
            ("ClearBox: a NaN corner", lambda: box((NAN, 0.0, 0.0), (1.0, 1.0, 1.0)), "NaN"),
            ("ClearBox: an inverted box in another frame",
             lambda: box((1.0, 0.0, 0.0), (0.0, 1.0, 1.0), frame_id="turned"),
             "min_corner below max_corner"),
            ("ClearBox: an infinite corner in another frame",
             lambda: box((0.0, 0.0, -INF), (1.0, 1.0, 1.0), frame_id="turned"), "finite"),
            ("ClearBox: an unknown frame",
             lambda: box((0.0, 0.0, 0.0), (1.0, 1.0, 1.0), frame_id="nowhere"),
             "cannot transform from 'nowhere'"),
        ]
        for what, request, part in cases:
            self.expect_refused(what, request, part)


if __name__ == "__main__":
    rostest.rosrun("mvog", "test_map_edits", MapEdits, sys.argv)
