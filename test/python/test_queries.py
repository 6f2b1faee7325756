"""Depth images, the map's edits and what planners ask, through Python: each against the same
thing done another way (the points of a depth image inserted as a scan, a C++ check against the
volumes it looks at)."""

import math

import numpy as np
import pytest

import mvog


def floor_map():
    """A sensor 1 m above a floor of hits at z = 0 over [-2, 2] x [-2, 2] m."""
    world = mvog.Map(mvog.MapConfig(resolution=0.1))
    xs, ys = np.meshgrid(np.arange(-2, 2, 0.05), np.arange(-2, 2, 0.05))
    floor = np.stack([xs.ravel(), ys.ravel(), np.zeros(xs.size)], axis=1)
    world.insert_scan([0, 0, 1], floor)
    return world


def test_a_depth_image_is_its_back_projected_points():
    # Pixel (u, v) at depth z is ((u - cx) z / fx, (v - cy) z / fy, z) in the optical frame; the
    # pose turns the optical frame to look down from 2 m (x right, y down, z forward = -z).
    depth_m = np.array([[1.5, 2.0, 0.0], [1.8, math.nan, 1.9]], np.float32)
    camera = mvog.PinholeCamera(fx=2.0, fy=2.0, cx=1.0, cy=0.5)
    pose = np.array([[1, 0, 0, 0.33], [0, -1, 0, 0.21], [0, 0, -1, 2.04], [0, 0, 0, 1]], float)
    world = mvog.Map()
    result, skipped = world.insert_depth_image(depth_m, camera, pose)
    assert skipped == 2 and result.obstacle_readings == 4
    points = []
    for v, u in [(0, 0), (0, 1), (1, 0), (1, 2)]:
        z = float(depth_m[v, u])
        optical = np.array([(u - 1.0) * z / 2.0, (v - 0.5) * z / 2.0, z, 1.0])
        points.append((pose @ optical)[:3])
    by_points = mvog.Map()
    by_points.insert_scan(pose[:3, 3], np.array(points))
    assert mvog.serialize_map(world) == mvog.serialize_map(by_points)
    # The same image in uint16 millimetres (0: no measurement).
    depth_mm = np.array([[1500, 2000, 0], [1800, 0, 1900]], np.uint16)
    in_mm = mvog.Map()
    assert in_mm.insert_depth_image(depth_mm, camera, pose)[1] == 2
    # Depths within a float's rounding of the metres: the same cells at the ends, occupied.
    states_mm, _ = in_mm.occupancy(np.array(points))
    states_m, _ = world.occupancy(np.array(points))
    assert (states_mm == int(mvog.OccupancyState.OCCUPIED)).all()
    assert (states_m == int(mvog.OccupancyState.OCCUPIED)).all()


def test_volumes_is_one_structured_array():
    world = floor_map()
    volumes = world.volumes()
    assert volumes.dtype.names == ("x", "y", "sign", "bottom", "top", "mass")
    usage = world.memory_usage()
    assert len(volumes) == usage.positive_volumes + usage.negative_volumes
    assert (volumes["sign"] == 1).sum() == usage.positive_volumes
    assert (volumes["top"] > volumes["bottom"]).all() and (volumes["mass"] > 0).all()
    positive = volumes[volumes["sign"] == 1]
    # Floor hits at z = 0: positive volumes around height 0 (grid units).
    assert (positive["bottom"] <= 0.5).all() and (positive["top"] >= -0.5).all()
    assert world.bounds == [volumes["x"].min(), volumes["y"].min(), volumes["x"].max(),
                            volumes["y"].max()]


def test_checks_of_segments_and_boxes():
    world = floor_map()
    # Down through the floor; level through the cone of free space the rays swept; far away.
    starts = np.array([[0.05, 0.05, 0.9], [0.05, 0.05, 0.5], [30.0, 30.0, 1.0]])
    ends = np.array([[0.05, 0.05, -0.5], [0.85, 0.05, 0.5], [31.0, 30.0, 1.0]])
    states, blocked_at = mvog.check_segments(world, starts, ends)
    assert list(states) == [int(mvog.OccupancyState.OCCUPIED), int(mvog.OccupancyState.FREE),
                            int(mvog.OccupancyState.UNKNOWN)]
    assert 0.6 < blocked_at[0] < 1.0 and math.isnan(blocked_at[1]) and blocked_at[2] == 0.0
    states, known, highest = mvog.check_boxes(world, np.array([[-0.5, -0.5, -0.1]]),
                                              np.array([[0.5, 0.5, 0.1]]))
    # The floor's volume spans [-0.05, 0.05] m, free space lies above it, nothing is known below.
    assert states[0] == int(mvog.OccupancyState.OCCUPIED) and known[0] == pytest.approx(0.75)
    assert highest[0] > 0.5
    with pytest.raises(ValueError, match="max_query_cells"):
        mvog.check_segments(world, starts, ends, config=mvog.PlanningConfig(max_query_cells=1))
    # The checker that keeps block summaries answers alike, before and after a change.
    checker = mvog.SegmentChecker()
    for _ in range(2):
        kept = checker.check(world, starts, ends)
        fresh = mvog.check_segments(world, starts, ends)
        np.testing.assert_array_equal(kept[0], fresh[0])
        np.testing.assert_array_equal(kept[1], fresh[1])
        world.clear_box([0.0, 0.0, -1.0], [0.2, 0.2, 1.0])


def test_surfaces_frontiers_and_the_traversable_map():
    world = floor_map()
    surfaces = mvog.Surfaces().update(world)
    assert surfaces.dtype.names == ("x", "y", "z", "clearance", "capped", "probability")
    assert len(surfaces) > 1000 and np.abs(surfaces["z"]).max() < 0.2
    frontiers = mvog.Frontiers(mvog.PlanningConfig(frontier_min_cells=1))
    points = frontiers.update(world)
    assert points.dtype.names == ("x", "y", "z", "cluster")
    assert len(points) > 0 and frontiers.num_clusters == points["cluster"].max() + 1
    traversable = mvog.traversable_map(world, rectangle=(-1, -1, 1, 1))
    assert traversable.values.dtype == np.int8 and traversable.values.shape == (21, 21)
    assert traversable.origin == [pytest.approx(-1.0), pytest.approx(-1.0)]
    assert (traversable.values[5:15, 5:15] == int(mvog.Traversability.TRAVERSABLE)).all()


def test_edits_clear_box_merge_and_drop_tiles():
    world = floor_map()
    cells = world.memory_usage().cells_with_volumes
    changed = world.clear_box([-0.5, -0.5, -math.inf], [0.5, 0.5, math.inf])
    assert changed == 100
    assert world.occupancy(np.array([[0.0, 0.0, 0.0]]))[0][0] == int(mvog.OccupancyState.UNKNOWN)
    copy = mvog.Map(mvog.MapConfig(resolution=0.1))
    copy.merge(world)
    assert mvog.serialize_map(copy) == mvog.serialize_map(world)
    moved = mvog.Map(mvog.MapConfig(resolution=0.1))
    moved.merge(world, np.array([[1, 0, 0, 10.0], [0, 1, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1]]))
    assert moved.bounds[0] == world.bounds[0] + 100
    world.merge(world)  # a map merged into itself: masses doubled, probabilities the same
    far = world.drop_tiles_farther_than([10.0, 10.0], 1.0)
    assert world.empty and far.memory_usage().cells_with_volumes == cells - changed
    assert world.tiles_modified_since(0).shape == (0, 2)
