"""The paper's equations through Python: Fig. 3's two rays (eqs. 3-6, s = 1 so heights in grid
units are metres), merging (eqs. 7, 8), eq. (9) at points and over a cross-section, and decay
(Sec. III-E). The same cases and numbers as test/core/test_insertion.cpp and test_volume.cpp."""

import math

import numpy as np
import pytest

import mvog

SLOPE_LEFT = 10.0 / 4.5
SLOPE_RIGHT = 4.0 / 10.5


def unit_map():
    """The paper's model at s = 1 (test_util.h's unitConfig)."""
    return mvog.Map(mvog.MapConfig(resolution=1.0, rules=mvog.ModelRules.paper()))


def volume(bottom, top, mass):
    return pytest.approx([bottom, top, mass], rel=1e-5, abs=1e-5)


def test_fig3_left_ray_has_a_padding_volume():
    world = unit_map()
    result = world.insert_reading([0, 0, 0], [0, 4.5, 10], mvog.ReadingKind.OBSTACLE)
    assert result.obstacle_readings == 1
    for j in range(4):
        # Eq. (3): [2.222 j, 2.222 (j + 1)], height >= 1, density 1: mass = height.
        positive, negative = world.cell_volumes(0, j)
        assert len(positive) == 0
        assert list(negative[0]) == volume(SLOPE_LEFT * j, SLOPE_LEFT * (j + 1), SLOPE_LEFT)
    # Eq. (5): V = [9.5, 10.5], mass 1; the padding [8.889, 9.5] is lower than 1, so eq. (6)
    # centres it on 9.194: [8.694, 9.694], mass 1.
    positive, negative = world.cell_volumes(0, 4)
    assert [list(v) for v in positive] == [volume(9.5, 10.5, 1.0)]
    pad_centre = 0.5 * (4 * SLOPE_LEFT + 9.5)
    assert [list(v) for v in negative] == [volume(pad_centre - 0.5, pad_centre + 0.5, 1.0)]
    volumes = world.volumes()
    assert len(volumes) == 6
    assert set(zip(volumes["x"], volumes["y"])) == {(0, j) for j in range(5)}


def test_fig3_right_ray_has_no_padding_volume():
    world = unit_map()
    world.insert_reading([0, 0, 0], [0, 10.5, 4])
    for j in range(10):
        # Eq. (3) gives a height of 0.381 < 1: eq. (6) centres it with height 1, mass 1.
        positive, negative = world.cell_volumes(0, j)
        centre = SLOPE_RIGHT * (j + 0.5)
        assert len(positive) == 0
        assert [list(v) for v in negative] == [volume(centre - 0.5, centre + 0.5, 1.0)]
    positive, negative = world.cell_volumes(0, 10)
    assert [list(v) for v in positive] == [volume(3.5, 4.5, 1.0)]
    assert len(negative) == 0


def test_fig3_left_ray_as_an_out_of_range_reading_is_free_up_to_its_end():
    world = unit_map()
    result = world.insert_reading([0, 0, 0], [0, 4.5, 10], mvog.ReadingKind.OUT_OF_RANGE)
    assert (result.out_of_range_readings, result.obstacle_readings) == (1, 0)
    positive, negative = world.cell_volumes(0, 4)
    assert len(positive) == 0  # eq. (4): [8.889, 10], mass 1.111
    assert [list(v) for v in negative] == [volume(4 * SLOPE_LEFT, 10.0, 10.0 - 4 * SLOPE_LEFT)]
    assert (world.volumes()["sign"] == -1).all()


def test_the_same_scan_from_insert_scan_with_out_of_range_readings():
    world = unit_map()
    result = world.insert_scan(np.zeros(3), np.array([[0, 10.5, 4]], np.float32),
                               out_of_range=np.array([[0, 4.5, 10]], np.float64))
    assert (result.obstacle_readings, result.out_of_range_readings) == (1, 1)


def test_merging_conserves_mass():
    # Eqs. (4), (7), (8): test_insertion.cpp's ReadingsMergeAndConserveMass.
    world = unit_map()
    out = mvog.ReadingKind.OUT_OF_RANGE
    world.insert_reading([0.5, 0.5, 0], [0.5, 0.5, 2], out)      # [0, 2], mass 2
    world.insert_reading([0.5, 0.5, 2.5], [0.5, 0.5, 4.5], out)  # gap 0.5 closed: [0, 4.5]
    assert [list(v) for v in world.cell_volumes(0, 0)[1]] == [volume(0.0, 4.5, 4.5)]
    world.insert_reading([0.5, 0.5, 1], [0.5, 0.5, 3], out)      # inside: mass + 2
    assert [list(v) for v in world.cell_volumes(0, 0)[1]] == [volume(0.0, 4.5, 6.5)]
    world.insert_reading([0.5, 0.5, 6], [0.5, 0.5, 7], out)      # gap 1.5: a second volume
    assert len(world.cell_volumes(0, 0)[1]) == 2
    assert world.volumes()["mass"].sum() == pytest.approx(7.5)
    # Two hits 0.8 apart: [2.5, 3.5] and [4.3, 5.3] merge: [2.5, 5.3], mass 1 + 0.8 + 1.
    world.insert_reading([0.5, 0.5, 0], [0.5, 0.5, 3])
    world.insert_reading([0.5, 0.5, 0], [0.5, 0.5, 4.8])
    assert [list(v) for v in world.cell_volumes(0, 0)[0]] == [volume(2.5, 5.3, 2.8)]


def test_eq9_at_points_and_over_a_cross_section():
    world = unit_map()
    world.insert_reading([0, 0, 0], [0, 4.5, 10])
    points = np.array([[0.5, 4.5, 10.0],   # the hit only: p = 1
                       [0.5, 4.5, 9.6],    # hit [9.5, 10.5] and pad [8.694, 9.694]: p = 1 / 2
                       [0.5, 2.5, 5.0],    # free only: p = 0
                       [0.5, 2.5, 50.0],   # unknown
                       [math.nan, 0, 0]])  # unknown
    states, probabilities = world.occupancy(points)
    assert states.dtype == np.uint8 and probabilities.dtype == np.float32
    assert list(states) == [int(mvog.OccupancyState.OCCUPIED), int(mvog.OccupancyState.OCCUPIED),
                            int(mvog.OccupancyState.FREE), 0, 0]
    assert probabilities[:3] == pytest.approx([1.0, 0.5, 0.0])
    assert np.isnan(probabilities[3:]).all()
    states, _ = world.occupancy(points[1:2], occupancy_threshold=0.5)
    assert states[0] == int(mvog.OccupancyState.FREE)  # p > threshold is occupied: 0.5 is not

    section = world.cross_section(5.0)
    assert section.values.shape == (5, 1) and section.values.dtype == np.float32
    assert section.origin == [0.0, 0.0] and section.resolution == 1.0
    # z = 5 lies in cells j = 2 ([4.44, 6.67]) only: free there, unknown elsewhere.
    assert section.values[2, 0] == 0.0
    assert np.isnan(np.delete(section.values[:, 0], 2)).all()
    top = world.projection()
    assert top.values.dtype == np.uint8
    assert list(top.values[:, 0]) == [1, 1, 1, 1, 2]


def test_decay_scales_masses_and_keeps_probabilities():
    world = unit_map()
    world.insert_reading([0, 0, 0], [0, 4.5, 10])
    before = world.volumes()
    _, p_before = world.occupancy(np.array([[0.5, 4.5, 9.6]]))
    revision = world.revision
    world.decay(0.5)
    assert world.revision > revision
    assert world.volumes()["mass"] == pytest.approx(0.5 * before["mass"])
    assert world.occupancy(np.array([[0.5, 4.5, 9.6]]))[1] == pytest.approx(p_before)
    with pytest.raises(ValueError, match="k_d"):
        world.decay(1.5)
    # Forgetting removes what is lighter than min_mass: the unit volumes now weigh 0.5.
    forgotten = world.forget(0.75)
    assert forgotten.volumes_removed == 2
    assert len(world.volumes()) == 4
