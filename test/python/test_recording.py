"""A recording through Python: its rays inserted from numpy give, at every hit, the occupancy the
C++ core answers (mvog_ray_export), states and probabilities alike."""

import numpy as np

import mvog
from test_files import scans_of


def test_occupancy_of_the_recordings_ends_equals_the_cpp_answers(reference):
    directory, printed = reference
    world = mvog.Map(mvog.MapConfig(resolution=0.1))
    for origin, hits in scans_of(directory):
        world.insert_scan(origin, hits)
    hits = np.load(directory / "hits.npy")
    assert len(hits) == printed["readings"] > 10000 - 1
    states, probabilities = world.occupancy(hits)
    cpp_states = np.load(directory / "states.npy")
    cpp_probabilities = np.load(directory / "probabilities.npy")
    np.testing.assert_array_equal(states, cpp_states)
    np.testing.assert_array_equal(probabilities, cpp_probabilities)  # NaN where unknown, alike
    assert (states == int(mvog.OccupancyState.OCCUPIED)).mean() > 0.5
    # The same answers for the points in float64 and for a non-contiguous view of them.
    np.testing.assert_array_equal(world.occupancy(hits.astype(np.float64))[1], cpp_probabilities)
    doubled = np.repeat(hits, 2, axis=0)[::2]
    np.testing.assert_array_equal(world.occupancy(doubled)[0], cpp_states)
