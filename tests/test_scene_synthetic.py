import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from ptztrack.scene.parameters import CrowdParameters
from ptztrack.scene.synthetic import walk_people

AREA = (15.0, 15.0)


def walk(seed, frames=200, **people):
    """Walkers alone unless ``pairs`` is given."""
    crowd = CrowdParameters(**{"paired_fraction": 0.0, **people})
    return walk_people(crowd, AREA, frames, 5.0, np.random.default_rng(seed))


@settings(deadline=None, max_examples=25)
@given(seed=st.integers(0, 2**32 - 1))
def test_walkers_stay_inside_at_human_speeds_with_smooth_turns(seed):
    truth = walk(seed)
    assert truth.present.all()
    assert np.all((truth.positions_m >= 0) & (truth.positions_m <= 15.0))
    step = np.diff(truth.positions_m, axis=0)
    speed = np.linalg.norm(step, axis=-1) * 5.0
    assert np.all(speed <= 1.5 + 1e-9)
    assert np.median(speed) >= 1.0
    heading = np.arctan2(step[..., 1], step[..., 0])
    turn_deg = np.rad2deg(np.abs((np.diff(heading, axis=0) + np.pi) % (2 * np.pi) - np.pi))
    assert np.percentile(turn_deg, 99) < 30.0
    assert np.all((truth.heights_m >= 1.6) & (truth.heights_m <= 1.9))


def test_the_seed_fixes_the_scene():
    np.testing.assert_array_equal(walk(3).positions_m, walk(3).positions_m)
    assert not np.array_equal(walk(3).positions_m, walk(4).positions_m)


def test_people_entering_and_leaving_do_so_once_through_the_border():
    truth = walk(5, frames=300, enter_leave=True, count=12, stay_s=(5.0, 10.0))
    present = truth.present
    for person in range(12):
        frames = np.flatnonzero(present[:, person])
        assert len(frames) > 0
        assert np.all(np.diff(frames) == 1), "a person is present for one contiguous stretch"
        first = truth.positions_m[frames[0], person]
        assert np.min(np.abs(np.concatenate([first, 15.0 - first]))) < 1e-9, "enters on the border"
        if frames[-1] < 299:
            last = truth.positions_m[frames[-1], person]
            assert np.min(np.abs(np.concatenate([last, 15.0 - last]))) < 0.5, "leaves near the border"
    assert not present[0].all(), "entries are spread over time"
    assert not present[-1].all(), "some have left by the end"


@settings(deadline=None, max_examples=25)
@given(seed=st.integers(0, 2**32 - 1), enter_leave=st.booleans())
def test_a_pair_walks_side_by_side_the_second_on_the_left_of_the_first(seed, enter_leave):
    truth = walk(seed, frames=150, count=7, paired_fraction=0.85, enter_leave=enter_leave, stay_s=(5.0, 10.0))
    for leader in (0, 2, 4):
        mate = leader + 1
        np.testing.assert_array_equal(truth.present[:, leader], truth.present[:, mate])
        both = np.flatnonzero(truth.present[:, leader])[1:]
        offset = truth.positions_m[both, mate] - truth.positions_m[both, leader]
        # The leader's walk into its position: the direction the pair faces there.
        heading = truth.positions_m[both, leader] - truth.positions_m[both - 1, leader]
        inside = np.all((truth.positions_m[both, mate] > 0) & (truth.positions_m[both, mate] < 15.0), axis=-1)
        # Steps of the leader's full stride (not stopped or clipped at the border).
        stride = np.linalg.norm(heading, axis=-1)
        moving = np.abs(stride - np.median(stride)) < 1e-9
        # 0.75 m apart, at a right angle to the leader's walk, to its left (positive cross product)
        np.testing.assert_allclose(np.linalg.norm(offset[inside], axis=-1), 0.75)
        cross = heading[:, 0] * offset[:, 1] - heading[:, 1] * offset[:, 0]
        dot = np.sum(heading * offset, axis=-1)
        assert np.all(cross[inside & moving] > 0)
        np.testing.assert_allclose(dot[inside & moving], 0.0, atol=1e-9)
    assert truth.present[:, 6].any()


def test_the_paired_fraction_makes_whole_pairs():
    assert [CrowdParameters(count=count, paired_fraction=0.85).pairs for count in (0, 1, 3, 7, 20)] == [0, 0, 1, 3, 8]
    assert CrowdParameters(count=7, paired_fraction=1.0).pairs == 3
