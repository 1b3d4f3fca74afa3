import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from ptztrack.facecapture.parameters import RoadSceneParameters
from ptztrack.facecapture.roads import RoadScene, joins_and_splits, walk_roads


def walk(seed=0, **fields):
    return walk_roads(RoadSceneParameters(**fields), np.random.default_rng(seed))


def lattice(scene):
    """(T, N, 2) coordinates ((x + y) / s, (x - y) / s): roads are their integer lines."""
    x, y = scene.positions_m[..., 0], scene.positions_m[..., 1]
    return np.stack([x + y, x - y], -1) / scene.road_spacing_m


def group_speed_m_s(scene, t, n):
    """The speed person n walks at at step t: its own alone, the slowest member's in a group."""
    group = scene.group_id[t, n]
    return scene.speed_m_s[n] if group < 0 else scene.speed_m_s[scene.group_id[t] == group].min()


scenes = st.builds(
    walk,
    seed=st.integers(0, 2**32 - 1),
    people=st.integers(2, 30),
    area_m=st.sampled_from([20.0, 33.0, 40.0]),
    road_spacing_m=st.sampled_from([6.0, 10.0]),
    duration_s=st.just(60.0),
    entry_window_s=st.just((0.0, 40.0)),
    join_probability=st.floats(0.0, 1.0),
    turn_probability=st.floats(0.0, 1.0),
    group_duration_s=st.just((2.0, 10.0)),
)


@settings(deadline=None, max_examples=30)
@given(scene=scenes)
def test_people_walk_on_the_roads_inside_the_area_and_once(scene):
    present = scene.present
    block_m = scene.road_spacing_m / np.sqrt(2)
    w = lattice(scene)[present]
    assert np.all(np.min(np.abs(w - np.round(w)), axis=-1) * block_m < 1e-6), "on a road"
    inside = scene.positions_m[present]
    assert np.all((inside >= -1e-9) & (inside <= scene.area_m + 1e-9))
    assert np.allclose(np.abs(scene.heading[present]), np.sqrt(0.5)), "headings are the diagonals"
    assert np.all(np.isnan(scene.heading[~present]))
    for n in range(present.shape[1]):
        steps = np.flatnonzero(present[:, n])
        if steps.size:
            assert np.all(np.diff(steps) == 1), "a person is present for one stretch and never returns"
            first = scene.positions_m[steps[0], n]
            assert np.min(np.abs(np.r_[first, scene.area_m - first])) < 1e-9, "enters on the border"


@settings(deadline=None, max_examples=30)
@given(scene=scenes)
def test_steps_follow_the_walkers_or_the_groups_speed(scene):
    dt_s = 1 / scene.frame_rate_hz
    w = lattice(scene)
    # Paths run along the roads, so a step's length (turns included) is its L1 length in lattice units.
    step_m = np.abs(np.diff(w, axis=0)).sum(-1) * scene.road_spacing_m / np.sqrt(2)
    both = scene.present[:-1] & scene.present[1:]
    assert np.all(step_m[both] <= np.broadcast_to(scene.speed_m_s * dt_s, both.shape)[both] + 1e-9)
    at_node = np.all(np.abs(w - np.round(w)) < 1e-9, axis=-1)
    for t, n in np.argwhere(both & (scene.group_id[:-1] == scene.group_id[1:])):
        expected_m = group_speed_m_s(scene, t + 1, n) * dt_s
        assert step_m[t, n] == pytest.approx(expected_m, abs=1e-9) or (
            step_m[t, n] < expected_m and at_node[t + 1, n]
        ), "only those waiting at an intersection for a partner walk slower"


@settings(deadline=None, max_examples=30)
@given(scene=scenes)
def test_groups_walk_as_one_and_ids_change_exactly_at_joins_and_splits(scene):
    gid, present, positions = scene.group_id, scene.present, scene.positions_m
    ids = np.unique(gid[gid >= 0])
    first_steps = [np.argmax((gid == group).any(axis=1)) for group in ids]
    assert np.all(np.diff(first_steps) >= 0), "every join makes a fresh id"
    for group in ids:
        steps, members = np.nonzero(gid == group)
        first, last = steps.min(), steps.max()
        crew = np.unique(members)
        assert crew.size >= 2
        assert np.all(gid[first : last + 1, crew] == group), "members stay together while it lasts"
        assert np.all(np.abs(positions[first : last + 1, crew] - positions[first : last + 1, crew[:1]]) < 1e-9)
        assert first > 0 and present[first - 1, crew].all(), "people enter alone"
        assert np.ptp(positions[first - 1, crew], axis=0).max() <= 2 * 1.5, "units join where they meet"
        if last + 1 < len(gid) and present[last + 1, crew].any():
            after = gid[last + 1, crew]
            if np.all(after == -1):  # a split at an intersection (next to the border one may leave at once)
                assert len(np.unique(scene.heading[last + 1, crew], axis=0)) >= 2, "a split parts ways"
            else:
                assert present[last + 1, crew].all(), "a group leaves the scene together"
                assert np.all(after == after[0]) and after[0] > group, "absorbed into a new group"


def test_joins_and_splits_counts_only_joins_that_end_alone():
    nan = np.nan
    group_id = np.array(
        [
            [-1, -1, -1, -1],
            [-1, -1, -1, -1],
            [0, 0, -1, -1],  # 0 and 1 join
            [1, 1, 1, -1],  # 2 joins them: a fresh id
            [-1, -1, -1, -1],  # all three split
            [-1, 2, 2, -1],  # 1 and 2 join again and leave together
            [-1, -1, -1, -1],
        ]
    )
    positions_m = np.zeros(group_id.shape + (2,))
    positions_m[6, 1:3] = nan
    positions_m[:, 3] = nan  # never enters
    scene = RoadScene(positions_m, group_id, np.zeros_like(positions_m), np.ones(4), 5.0, 40.0, 10.0)
    np.testing.assert_array_equal(joins_and_splits(scene), [1, 1, 1, 0])
    assert scene.nj_s == 3


CROSSING = dict(
    people=2,
    area_m=10.0,  # one intersection, at the centre; the roads run between the corners
    duration_s=20.0,
    entry_window_s=(0.0, 0.0),
    speed_m_s=(1.0, 1.0),
)


def test_two_walkers_reaching_the_one_intersection_together_join_and_leave_together():
    scene = walk(3, join_probability=1.0, **CROSSING)
    last = np.flatnonzero(scene.present.all(axis=1))[-1]
    joined = int(np.ceil(np.sqrt(50) * 5.0))  # 7.07 m from a corner to the centre at 1 m/s, 5 steps/s
    np.testing.assert_array_equal(scene.group_id[:joined], -1)
    np.testing.assert_array_equal(scene.group_id[joined : last + 1], 0)
    together = scene.positions_m[joined : last + 1]
    np.testing.assert_allclose(together[:, 0], together[:, 1])
    assert not scene.present[-1].any(), "they have left through a corner"
    assert scene.nj_s == 0, "a join that never splits is no ambiguity"
    assert np.all(walk(3, join_probability=0.0, **CROSSING).group_id == -1)


def test_groups_split_at_the_next_intersection_into_different_ways_and_apart():
    config = dict(CROSSING, area_m=20.0, group_duration_s=(0.0, 0.0), join_probability=1.0, duration_s=40.0)
    block_steps = int(np.ceil(10.0 / np.sqrt(2) * 5.0))  # between intersections at 1 m/s
    split_scenes = 0
    for seed in range(40):
        scene = walk(seed, **config)
        gid, both = scene.group_id[:, 0], scene.present.all(axis=1)
        joins = np.flatnonzero((gid[:-1] < 0) & (gid[1:] >= 0)) + 1
        splits = np.flatnonzero((gid[:-1] >= 0) & (gid[1:] < 0) & both[1:]) + 1
        np.testing.assert_array_equal(joins_and_splits(scene), [splits.size] * 2)
        # A group may leave the scene together (a join without its split): pair each split with its join.
        for joined, split in zip(joins, splits, strict=False):
            assert split - joined <= block_steps, "a group due to split does so at the next intersection"
            later = min(split + 10, np.flatnonzero(both)[-1])
            assert np.linalg.norm(np.diff(scene.positions_m[later], axis=0)) > 1.5, "apart within 2 s"
        split_scenes += splits.size > 0
    assert split_scenes >= 3


def test_more_willingness_to_join_means_more_ambiguity():
    def mean_nj_s(p):
        busy = dict(people=40, duration_s=60.0, entry_window_s=(0.0, 40.0), join_probability=p)
        return np.mean([walk(seed, **busy).nj_s for seed in range(20)])

    assert mean_nj_s(0.9) > mean_nj_s(0.1) + 1


def test_the_seed_fixes_the_scene():
    a, b, c = walk(7, people=30), walk(7, people=30), walk(8, people=30)
    for field in ("positions_m", "group_id", "heading", "speed_m_s"):
        np.testing.assert_array_equal(getattr(a, field), getattr(b, field))
    assert not np.array_equal(a.positions_m, c.positions_m, equal_nan=True)


@pytest.mark.parametrize(
    "fields, name",
    [
        ({"area_m": -40.0}, "area_m"),
        ({"join_probability": 1.5}, "join_probability"),
        ({"turn_probability": -0.1}, "turn_probability"),
        ({"people": -1}, "people"),
        ({"speed_m_s": (1.6, 0.8)}, "speed_m_s"),
        ({"speed_m_s": (1.0, 40.0)}, "speed_m_s"),
        ({"meet_radius_m": 8.0}, "meet_radius_m"),
        ({"walls": 3}, "walls"),
    ],
)
def test_invalid_configurations_are_refused_naming_the_field(fields, name):
    with pytest.raises((TypeError, ValueError)) as error:
        RoadSceneParameters(**fields)
    assert name in str(error.value)
