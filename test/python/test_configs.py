"""The configuration classes: keyword arguments with the C++ defaults, validated by the core (a
bad field raises ValueError, mvog.ConfigError, naming it)."""

import copy
import math

import pytest

import mvog


def test_defaults_are_the_cpp_defaults():
    config = mvog.MapConfig()
    assert config.resolution == 0.1
    assert config.max_coordinate == 10000.0
    rules = config.rules
    assert rules.clip_free_space_at_hits and rules.split_free_space_at_obstacles
    assert rules.mass_counting == mvog.MassCounting.PER_SCAN
    assert rules.out_of_range_free_length == 2.0
    insertion = mvog.InsertionConfig()
    assert (insertion.min_range, insertion.max_range) == (0.0, math.inf)
    assert insertion.insert_out_of_range and insertion.model_negative_space
    assert insertion.insertion_threads == 1
    assert insertion.free_space_rays == mvog.FreeSpaceRays.ONE_PER_END_VOXEL
    assert insertion.evidence_limit == 14.0
    assert insertion.hit_memory_scans == 5
    assert insertion.hit_memory_scope == mvog.HitMemoryScope.LINE_SCANS
    planning = mvog.PlanningConfig()
    assert planning.occupancy_threshold == mvog.DEFAULT_OCCUPANCY_THRESHOLD == 0.324
    assert planning.max_query_cells == 50000000
    assert (planning.frontier_min_z, planning.frontier_max_z) == (-math.inf, math.inf)
    assert planning.frontier_min_cells == 10
    assert (planning.robot_height, planning.max_step) == (0.5, 0.1)
    assert (planning.traversable_min_z, planning.traversable_max_z) == (-0.5, 0.5)


def test_paper_rules():
    paper = mvog.ModelRules.paper()
    assert not paper.clip_free_space_at_hits and not paper.split_free_space_at_obstacles
    assert paper.mass_counting == mvog.MassCounting.PER_READING
    assert paper.out_of_range_free_length == math.inf
    assert paper == mvog.ModelRules(clip_free_space_at_hits=False,
                                    mass_counting=mvog.MassCounting.PER_READING,
                                    split_free_space_at_obstacles=False,
                                    out_of_range_free_length=math.inf)


def test_keyword_arguments_only():
    assert mvog.MapConfig(resolution=0.05).resolution == 0.05
    with pytest.raises(TypeError):
        mvog.MapConfig(0.05)


@pytest.mark.parametrize("make, field", [
    (lambda: mvog.MapConfig(resolution=0.0), "resolution"),
    (lambda: mvog.MapConfig(resolution=math.nan), "resolution"),
    (lambda: mvog.MapConfig(max_coordinate=-1.0), "max_coordinate"),
    (lambda: mvog.MapConfig(resolution=0.001, max_coordinate=10000.0), "max_coordinate"),
    (lambda: mvog.ModelRules(out_of_range_free_length=0.0), "out_of_range_free_length"),
    (lambda: mvog.InsertionConfig(min_range=-1.0), "min_range"),
    (lambda: mvog.InsertionConfig(max_range=math.nan), "max_range"),
    (lambda: mvog.InsertionConfig(min_range=5.0, max_range=2.0), "min_range"),
    (lambda: mvog.InsertionConfig(insertion_threads=0), "insertion_threads"),
    (lambda: mvog.InsertionConfig(evidence_limit=0.5), "evidence_limit"),
    (lambda: mvog.InsertionConfig(hit_memory_scans=101), "hit_memory_scans"),
    (lambda: mvog.PlanningConfig(occupancy_threshold=1.0), "occupancy_threshold"),
    (lambda: mvog.PlanningConfig(max_query_cells=0), "max_query_cells"),
    (lambda: mvog.PlanningConfig(frontier_min_z=2.0, frontier_max_z=1.0), "frontier_min_z"),
    (lambda: mvog.PlanningConfig(frontier_min_cells=0), "frontier_min_cells"),
    (lambda: mvog.PlanningConfig(robot_height=math.inf), "robot_height"),
    (lambda: mvog.PlanningConfig(max_step=-0.1), "max_step"),
    (lambda: mvog.PlanningConfig(traversable_min_z=math.nan), "traversable_min_z"),
    (lambda: mvog.DepthImageConfig(stride=0), "stride"),
    (lambda: mvog.PinholeCamera(fx=0.0, fy=1.0, cx=0.0, cy=0.0), "fx"),
])
def test_a_bad_field_raises_value_error_naming_it(make, field):
    with pytest.raises(ValueError, match="^" + field + ":"):
        make()


def test_a_bad_assignment_raises_and_keeps_the_old_value():
    config = mvog.InsertionConfig(max_range=8.0)
    with pytest.raises(mvog.ConfigError, match="min_range"):
        config.min_range = 9.0
    assert config.min_range == 0.0
    config.min_range = 1.0
    assert config.min_range == 1.0
    rules = mvog.ModelRules()
    with pytest.raises(ValueError, match="out_of_range_free_length"):
        rules.out_of_range_free_length = -1.0
    assert rules == mvog.ModelRules()


def test_a_configs_rules_change_in_place():
    config = mvog.MapConfig()
    config.rules.out_of_range_free_length = 5.0
    assert config.rules.out_of_range_free_length == 5.0
    with pytest.raises(ValueError, match="out_of_range_free_length"):
        config.rules.out_of_range_free_length = 0.0
    assert mvog.Map(config).config.rules.out_of_range_free_length == 5.0


def test_a_map_takes_its_config_and_copies_are_independent():
    config = mvog.MapConfig(resolution=0.25, rules=mvog.ModelRules.paper())
    other = copy.deepcopy(config)
    other.resolution = 0.5
    other.rules.out_of_range_free_length = 3.0
    assert config.rules == mvog.ModelRules.paper()
    assert mvog.Map(config).resolution == 0.25
    assert mvog.Map(config).config.rules == mvog.ModelRules.paper()
    assert "resolution=0.25" in repr(config)


def test_grid_transform_from_matrix():
    import numpy as np
    quarter = np.array([[0, -1, 0, 0.2], [1, 0, 0, 0.3], [0, 0, 1, 0.5], [0, 0, 0, 1]], float)
    transform = mvog.GridTransform.from_matrix(quarter, 0.1)
    assert (transform.quarter_turns % 4, transform.dx_cells, transform.dy_cells) == (1, 2, 3)
    assert transform.dz == pytest.approx(0.5)
    quarter[0, 3] = 0.25  # half a cell
    with pytest.raises(ValueError):
        mvog.GridTransform.from_matrix(quarter, 0.1)
