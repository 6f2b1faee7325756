"""Bad inputs: wrong shapes and dtypes raise TypeError or ValueError naming the argument; NaN and
infinite readings are counted as rejected exactly as in C++; never a crash."""

import math
import threading

import numpy as np
import pytest

import mvog


def test_wrong_shapes_raise_value_error():
    world = mvog.Map()
    with pytest.raises(ValueError, match=r"hits: expected shape \(N, 3\), got \(4, 2\)"):
        world.insert_scan([0, 0, 0], np.zeros((4, 2)))
    with pytest.raises(ValueError, match="hits"):
        world.insert_scan([0, 0, 0], np.zeros(3))
    with pytest.raises(ValueError, match="out_of_range"):
        world.insert_scan([0, 0, 0], np.zeros((1, 3)), out_of_range=np.zeros((2, 3, 1)))
    with pytest.raises(ValueError, match="points"):
        world.occupancy(np.zeros((5, 4)))
    with pytest.raises(ValueError, match="starts"):
        mvog.check_segments(world, np.zeros((2, 3)), np.zeros((3, 3)))
    with pytest.raises(TypeError):
        world.insert_scan([0, 0], np.zeros((1, 3)))  # the origin is 3 numbers
    assert world.empty and world.revision == 1


def test_wrong_dtypes_raise_type_error():
    world = mvog.Map()
    with pytest.raises(TypeError, match="hits: expected a float32 or float64 array, got dtype int64"):
        world.insert_scan([0, 0, 0], np.ones((2, 3), np.int64))
    with pytest.raises(TypeError, match="points"):
        world.occupancy(np.ones((2, 3), np.float16))
    with pytest.raises(TypeError, match="hits"):
        world.insert_scan([0, 0, 0], "not points")
    camera = mvog.PinholeCamera(fx=1.0, fy=1.0, cx=0.0, cy=0.0)
    with pytest.raises(TypeError, match="depth"):
        world.insert_depth_image(np.ones((2, 2), np.float64), camera, np.eye(4))
    with pytest.raises(ValueError, match="depth"):
        world.insert_depth_image(np.ones((2, 2, 1), np.float32), camera, np.eye(4))
    assert world.empty


def test_non_finite_and_far_readings_are_counted_as_rejected():
    world = mvog.Map()
    hits = np.array([[1, 0, 0], [math.nan, 0, 0], [0, math.inf, 0], [2e4, 0, 0], [0, 1, 0]],
                    np.float32)
    result = world.insert_scan([0, 0, 0], hits)
    assert result.obstacle_readings == 2
    assert result.rejected_non_finite == 2
    assert result.rejected_out_of_bounds == 1
    assert result.rejected == 3
    result = world.insert_scan([math.nan, 0, 0], hits)  # a non-finite origin: nothing inserted
    assert result.inserted == 0 and result.rejected == len(hits)


def test_bad_poses_rectangles_and_queries_raise_value_error():
    world = mvog.Map()
    world.insert_scan([0, 0, 1], np.array([[1.0, 0.0, 0.0]]))
    camera = mvog.PinholeCamera(fx=1.0, fy=1.0, cx=0.0, cy=0.0)
    with pytest.raises(ValueError, match="pose"):
        world.insert_depth_image(np.ones((2, 2), np.float32), camera, 2 * np.eye(4))
    with pytest.raises(ValueError, match="rectangle"):
        world.cross_section(0.0, rectangle=(0, 0, math.nan, 1))
    with pytest.raises(ValueError, match="rectangle"):
        world.projection(rectangle=(1, 0, 0, 1))
    with pytest.raises(ValueError, match="occupancy_threshold"):
        world.occupancy(np.zeros((1, 3)), occupancy_threshold=1.5)
    with pytest.raises(ValueError):  # a segment with a NaN point
        mvog.check_segments(world, np.array([[0, 0, math.nan]]), np.zeros((1, 3)))
    with pytest.raises(ValueError, match="min_mass"):
        world.forget(-1.0)
    with pytest.raises(ValueError):
        world.clear_box([0, 0, math.nan], [1, 1, 1])
    other = mvog.Map(mvog.MapConfig(resolution=0.2))
    with pytest.raises(ValueError, match="resolution"):
        world.merge(other)


def test_threads_share_a_map_without_corrupting_it():
    # The GIL is released in insertions and queries; the map's lock keeps the core's calls apart.
    world = mvog.Map()
    rng = np.random.default_rng(1)
    scans = [rng.uniform(-3, 3, (2000, 3)).astype(np.float32) for _ in range(8)]
    errors = []

    def insert(points):
        try:
            world.insert_scan([0, 0, 0], points)
            world.occupancy(points)
            world.volumes()
        except Exception as error:  # noqa: BLE001 (reported by the assertion below)
            errors.append(error)

    threads = [threading.Thread(target=insert, args=(points,)) for points in scans]
    for thread in threads:
        thread.start()
    for thread in threads:
        thread.join()
    assert not errors
    alone = mvog.Map()
    for points in scans:
        alone.insert_scan([0, 0, 0], points)
    assert world.memory_usage().cells_with_volumes == alone.memory_usage().cells_with_volumes
