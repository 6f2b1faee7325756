#!/usr/bin/env python3
"""people_stationary.bag through mapper.launch with decay on (people_stationary.test).

A stationary 2D laser (Hokuyo, 5.6 m) at the map origin, 0.3 m up (synthetic pose, data README),
while people walk past. Checked: the people are cleared (cells hit in only a few scans, crossed by
free rays at the end of the bag, are free), the static walls stay occupied, the scanner's
surroundings are free, off the scan plane and far away is unknown, and the statistics count every
scan and reading (the NaN readings as rejected).
"""
import numpy as np
import rosbag
import rospy

import mvog_data_test as data

BAG = "people_stationary.bag"
# The data README's counts for this bag.
README_SCANS, README_READINGS, README_VALID = 1265, 647680, 216969
README_INF, README_NAN = 426298, 4413
# 126 s of bag in ~13 s: 100 scans/s of 512 beams, a fraction of the mapper's insertion rate.
# Decay runs on the simulated clock, so the replay rate does not change how much old readings
# are down-weighted.
RATE = 10
FINAL_SCANS = 10     # "at the end": the last second of the bag
QUIET_SCANS = 30     # people: no return in the last 3 s


class PeopleStationary(data.DataTestCase):
    @classmethod
    def setUpClass(cls):
        path = data.require_bag(BAG)
        rospy.init_node("test_people_stationary", disable_signals=True)
        cls.resolution = rospy.get_param(data.MAPPER + "/resolution")
        cls.decay_factor = rospy.get_param(data.MAPPER + "/decay_factor")
        cls.decay_period = rospy.get_param(data.MAPPER + "/decay_period")
        min_range = rospy.get_param(data.MAPPER + "/min_range")
        max_range = rospy.get_param(data.MAPPER + "/max_range")
        insert_out_of_range = rospy.get_param(data.MAPPER + "/insert_out_of_range")

        hit_cells = []   # per scan: the cells (i, j) its returns fall into
        crossed = []     # for the last FINAL_SCANS scans: the cells their rays pass through
        hits = []
        cls.readings = cls.valid = cls.inf = cls.nan = cls.expected_inserted = 0
        with rosbag.Bag(str(path)) as bag:
            buffer = data.tf_buffer(bag)
            scans = [scan for _, scan, _ in data.read_messages(bag, ["/scan"])]
        cls.scans = len(scans)
        for index, scan in enumerate(scans):
            pose = data.sensor_pose(buffer, scan.header)
            ranges, angles, valid = data.scan_beams(scan)
            points = data.scan_points(scan, pose)
            hits.append(points)
            hit_cells.append({tuple(k) for k in data.cell_keys(points, cls.resolution)})
            with np.errstate(invalid="ignore"):
                out_of_range = np.isposinf(ranges) | (ranges > scan.range_max)
            cls.expected_inserted += int(np.sum(valid & (ranges >= min_range)))
            if insert_out_of_range:
                cls.expected_inserted += int(np.sum(out_of_range))
            cls.readings += len(ranges)
            cls.valid += int(np.sum(valid))
            cls.inf += int(np.sum(np.isposinf(ranges)))
            cls.nan += int(np.sum(np.isnan(ranges)))
            if index >= cls.scans - FINAL_SCANS:
                free_to = np.where(valid, ranges, np.where(
                    out_of_range, min(scan.range_max, max_range), 0.0))
                crossed.append(cls.crossed_cells(pose, angles, free_to))
        cls.origin = pose[:3, 3]
        cls.forward = pose[:3, 0]
        cls.hit_cells = hit_cells
        cls.hits = hits
        cls.final_crossed = crossed

        cls.statistics = data.Replay(path, RATE, cls.scans).run()
        print("statistics after the replay:\n%s" % cls.statistics)

    @classmethod
    def crossed_cells(cls, pose, angles, free_to):
        """Cells the rays pass through before the cell they end in (sampled every 1/4 cell)."""
        step = cls.resolution / 4
        along = np.arange(0.0, free_to.max() + step, step)
        inside = along[None, :] < free_to[:, None]
        local = np.stack([np.cos(angles)[:, None] * along, np.sin(angles)[:, None] * along,
                          np.zeros((len(angles), len(along)))], axis=2)
        keys = data.cell_keys(data.transform_points(pose, local.reshape(-1, 3)),
                              cls.resolution).reshape(len(angles), len(along), 2)
        ends = np.stack([free_to * np.cos(angles), free_to * np.sin(angles),
                         np.zeros_like(angles)], axis=1)
        end_keys = data.cell_keys(data.transform_points(pose, ends), cls.resolution)
        keep = inside & np.any(keys != end_keys[:, None, :], axis=2) & (free_to > 0.0)[:, None]
        packed = np.unique(keys[keep][:, 0] * (1 << 32) + keys[keep][:, 1])
        i = (packed + (1 << 31)) >> 32
        return set(zip(i.tolist(), (packed - (i << 32)).tolist()))

    def scan_counts(self):
        """Per cell, in how many scans a return fell into it."""
        counts = {}
        for cells in self.hit_cells:
            for cell in cells:
                counts[cell] = counts.get(cell, 0) + 1
        return counts

    def at_height(self, keys):
        points = data.cell_centres(np.array(sorted(keys)), self.resolution)
        return np.column_stack([points, np.full(len(points), self.origin[2])])

    def test_bag_matches_readme(self):
        self.assertEqual(self.scans, README_SCANS)
        self.assertEqual(self.readings, README_READINGS)
        self.assertEqual(self.valid, README_VALID)
        self.assertEqual(self.inf, README_INF)
        self.assertEqual(self.nan, README_NAN)
        # README: the scanner at the map origin, 0.3 m up, level.
        np.testing.assert_allclose(self.origin, [0.0, 0.0, 0.3], atol=1e-6)

    def test_decay_is_on(self):
        # The configuration under test (people_stationary.test): masses decay over time.
        self.assertLess(self.decay_factor, 1.0)
        self.assertGreater(self.decay_period, 0.0)

    def test_statistics_count_every_message_and_reading(self):
        s = self.statistics
        # README: 1265/1265 transformable (one static transform).
        self.assertEveryMessageInserted(s, README_SCANS, "scans", RATE)
        # Returns and +Inf readings (free space to range_max) are inserted; NaN readings have no
        # meaning (REP-117) and are rejected.
        self.assertEqual(s.readings_inserted, self.expected_inserted)
        self.assertEqual(s.readings_inserted, README_VALID + README_INF)
        self.assertEqual(s.readings_rejected, README_NAN)

    def test_people_are_cleared(self):
        # Cells hit in at most 20 % of the scans (someone walked there), not in the last 3 s,
        # and crossed by a ray of each of the last 10 scans (the scanner saw through them at the
        # end). With eq. (9) the many later free rays outweigh the few hits of a passer-by; the
        # decay (Sec. III-E) weights those later rays more still. Queried at the cell centres.
        # Note: people here walk past and do not linger, so even without decay a plain
        # hits/(hits + misses) count over the whole bag leaves 99.8 % of these cells free: this
        # checks the outcome with decay on, it cannot tell that decay is what cleared them.
        counts = self.scan_counts()
        recent = set().union(*self.hit_cells[-QUIET_SCANS:])
        seen_free = set.intersection(*self.final_crossed)
        people = [cell for cell, n in counts.items()
                  if n <= 0.2 * self.scans and cell not in recent and cell in seen_free]
        self.assertGreater(len(people), 500, "expected many cells people walked through")
        # Mostly, not all: a cell a ray only clips at its corner gets little free space.
        self.assertFraction(data.sample(self.at_height(people), 3000), data.FREE, 0.9,
                            "cells people walked through")

    def test_static_walls_stay_occupied(self):
        # Cells hit in at least 80 % of the scans and in each of the last 10: the walls.
        counts = self.scan_counts()
        final = set.intersection(*self.hit_cells[-FINAL_SCANS:])
        walls = [cell for cell, n in counts.items() if n >= 0.8 * self.scans and cell in final]
        self.assertGreater(len(walls), 20, "expected static walls")
        # The scanner does not move, so the same beams end in the same cells every scan; a few
        # cells still get rays of neighbouring beams through a corner (Sec. V.B).
        self.assertFraction(self.at_height(walls), data.OCCUPIED, 0.97, "static walls")

    def test_in_front_of_the_scanner_is_free(self):
        points = self.origin + np.outer([0.2, 0.3, 0.4], self.forward)
        self.assertFraction(points, data.FREE, 1.0, "in front of the scanner")

    def test_off_the_scan_plane_and_far_away_is_unknown(self):
        counts = self.scan_counts()
        points = self.at_height(counts.keys())
        for offset in (-0.5, 1.0):
            shifted = points + [0.0, 0.0, offset]
            self.assertFraction(shifted, data.UNKNOWN, 1.0, "%+.1f m off the scan plane" % offset)
        # Beyond the 5.6 m range (and the 20 m ~max_range) no ray reaches.
        angles = np.linspace(-np.pi, np.pi, 36, endpoint=False)
        far = self.origin + 25.0 * np.column_stack([np.cos(angles), np.sin(angles),
                                                    np.zeros_like(angles)])
        self.assertFraction(far, data.UNKNOWN, 1.0, "25 m away")
        # Behind the scanner (it sees -90 to +90 degrees): 1 m behind it.
        self.assertFraction(self.origin - self.forward[None], data.UNKNOWN, 1.0,
                            "behind the scanner")


if __name__ == "__main__":
    data.main("people_stationary", PeopleStationary)
