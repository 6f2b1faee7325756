#!/usr/bin/env python3
"""SIGKILL during autosaves, many times; every restart resumes (see kill_during_save.test).

A mvog_node autosaves every 0.1 s (~autosave_period) while clouds keep changing its map. The test
waits until a save is under way (its temporary file beside autosave.mvog exists), kills the
server with SIGKILL, checks that autosave.mvog is a complete map file (its size is exactly what
its header's counts say; the loader checks the rest), and starts the next server with
~map_file: autosave.mvog, which must load it (a server that cannot load its ~map_file refuses to
start) and hold exactly the map of the file. The kills that interrupted a save are counted; the
temporaries they left must not pile up (each save removes those of killed saves before it).
"""
import math
import os
import struct
import sys
import tempfile
import threading
import time
import unittest
import shutil

import rostest

import mvog_reliability as rel

KILLS = 10
AUTOSAVE = "autosave.mvog"
TEMPORARY_PREFIX = "." + AUTOSAVE + ".saving-"  # a save's temporary (include/mvog/map_io.h)


def header_counts(path):
    """(cells, volumes) of a map file, checked against its size (include/mvog/map_io.h)."""
    with open(path, "rb") as f:
        header = f.read(64)
    size = os.path.getsize(path)
    assert header[:8] == b"MVOGMAP\0", "not a map file"
    cells, volumes = struct.unpack_from("<QQ", header, 32)
    assert size == 64 + 16 * cells + 12 * volumes + 8, (
        "%s: %d bytes, but the header says %d cells and %d volumes" % (path, size, cells, volumes))
    return cells, volumes


class CloudFeeder(threading.Thread):
    """Clouds of a room seen from a turning camera, 10 a second, until stopped."""

    def __init__(self, publisher):
        super().__init__(daemon=True)
        self.publisher = publisher
        self.running = True
        self.sent = 0

    def run(self):
        while self.running:
            yaw = 0.3 * self.sent
            points = []
            for k in range(4000):
                a = yaw + 2.0 * math.pi * k / 4000.0
                r = 3.0 + 0.5 * math.sin(5.0 * a + 0.1 * self.sent)
                points.append((r * math.cos(a), r * math.sin(a), -0.8 + 1.6 * ((k * 7) % 13) / 13))
            self.publisher.publish(rel.cloud(points))
            self.sent += 1
            time.sleep(0.1)


class KillDuringSave(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.broadcaster = rel.init_test_node("test_kill_during_save")

    def test_every_kill_leaves_a_map_the_next_server_resumes(self):
        directory = tempfile.mkdtemp(prefix="mvog_reliability_kill_")
        path = os.path.join(directory, AUTOSAVE)
        kills_during_saves = 0
        resumed = 0
        try:
            for kill in range(KILLS + 1):
                params = {"resolution": 0.05, "autosave_period": 0.1,
                          "autosave_file": AUTOSAVE}
                expected = None
                if os.path.exists(path):
                    params["map_file"] = AUTOSAVE
                    expected = header_counts(path)
                server = rel.Server("mapper_kill_%d" % kill, params, directory=directory)
                try:
                    rel.wait_for(lambda: not server.alive() or server.statistics is not None,
                                 "server %d to start" % kill)
                    self.assertTrue(server.alive(), "server %d did not start: %s"
                                    % (kill, server.output()))
                    server.wait_ready()
                    if expected is not None:
                        statistics = server.statistics
                        self.assertEqual((statistics.cells_with_volumes,
                                          statistics.positive_volumes +
                                          statistics.negative_volumes), expected,
                                         "server %d did not resume the autosaved map" % kill)
                        resumed += 1
                    if kill == KILLS:
                        break
                    feeder = CloudFeeder(server.clouds)
                    feeder.start()
                    try:
                        server.wait_counter("messages_inserted", 3)
                        # Kill while a save is under way: once its temporary file exists.
                        def saving():
                            return any(name.startswith(TEMPORARY_PREFIX)
                                       for name in os.listdir(directory))
                        before = set(os.listdir(directory))
                        rel.wait_for_or_not(lambda: saving() and
                                            set(os.listdir(directory)) != before, 20.0)
                        server.kill()
                    finally:
                        feeder.running = False
                        feeder.join()
                    if any(name.startswith(TEMPORARY_PREFIX) and name not in before
                           for name in os.listdir(directory)):
                        kills_during_saves += 1
                    self.assertTrue(os.path.exists(path), "no autosave after kill %d" % kill)
                    header_counts(path)
                finally:
                    server.stop()
            leftovers = [n for n in os.listdir(directory) if n.startswith(TEMPORARY_PREFIX)]
            left_bytes = sum(os.path.getsize(os.path.join(directory, n)) for n in leftovers)
            print("\n%d SIGKILLs, %d of them during a save; %d restarts resumed the autosave; "
                  "%d temporaries (%d bytes) left beside it" % (KILLS, kills_during_saves, resumed,
                                                               len(leftovers), left_bytes))
            self.assertEqual(resumed, KILLS)
            # Each save removes the temporaries of the killed ones before it: at most the last
            # kill's can be left (if the last server had no reason to save).
            self.assertLessEqual(len(leftovers), 1, "temporaries of killed saves pile up")
            self.assertGreater(kills_during_saves, 0, "no kill landed during a save")
        finally:
            shutil.rmtree(directory, ignore_errors=True)

    def test_a_clean_shutdown_saves_what_was_mapped_since_the_last_autosave(self):
        directory = tempfile.mkdtemp(prefix="mvog_reliability_shutdown_")
        try:
            # An autosave period far longer than the test: only the shutdown can save.
            server = rel.Server("mapper_shutdown", {"autosave_period": 3600.0,
                                                    "autosave_file": AUTOSAVE},
                                directory=directory).wait_ready()
            try:
                server.scans.publish(rel.scan([2.0] * 32))
                statistics = server.wait_counter("messages_inserted", 1)
                self.assertFalse(os.path.exists(os.path.join(directory, AUTOSAVE)))
            finally:
                server.stop()  # SIGINT
            self.assertEqual(server.process.returncode, 0)
            self.assertEqual(header_counts(os.path.join(directory, AUTOSAVE)),
                             (statistics.cells_with_volumes,
                              statistics.positive_volumes + statistics.negative_volumes))
        finally:
            shutil.rmtree(directory, ignore_errors=True)


if __name__ == "__main__":
    rostest.rosrun("mvog", "test_kill_during_save", KillDuringSave, sys.argv)
