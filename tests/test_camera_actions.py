"""Tests of the discrete PTZ action grid in ptztrack.camera.actions."""

import itertools

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from ptztrack.camera.actions import ActionGrid
from synthetic_scene import GRID

PROPERTY = settings(deadline=None, max_examples=100)


def small_grid():
    return ActionGrid(
        pan_deg=np.array([-10.0, 0.0, 10.0]),
        tilt_deg=np.array([20.0, 40.0]),
        zoom=np.array([1.0, 2.0, 4.0, 8.0]),
        max_steps=(1, 0, 2),
    )


def expected_reachable(grid, here):
    """Flat indices of the product of the per-axis index ranges allowed from grid indices ``here``."""
    ranges = [
        range(max(0, h - m), min(n - 1, h + m) + 1) for h, m, n in zip(here, grid.max_steps, grid.shape, strict=True)
    ]
    return sorted(int(grid.index(*combo)) for combo in itertools.product(*ranges))


def test_default_grid_layout():
    assert GRID.shape == (7, 10, 4)
    assert GRID.size == 280
    assert GRID.max_steps == (2, 2, 1)
    np.testing.assert_allclose(GRID.pan_deg, np.linspace(-45, 45, 7))
    # From the horizon down past the feet of the nearest people (22.6 deg at 6 m from a camera 2.5 m up).
    np.testing.assert_allclose(GRID.tilt_deg, np.linspace(0, 24, 10))
    np.testing.assert_allclose(GRID.zoom, [1, 2, 3, 4])


@pytest.mark.parametrize("grid", [GRID, small_grid()], ids=["scenario", "small"])
def test_poses_axis_indices_and_index_agree(grid):
    indices = grid.axis_indices
    poses = grid.poses
    assert indices.shape == (grid.size, 3)
    assert poses.shape == (grid.size, 3)
    for k in range(grid.size):
        i, j, z = indices[k]
        assert grid.index(i, j, z) == k
        np.testing.assert_array_equal(poses[k], [grid.pan_deg[i], grid.tilt_deg[j], grid.zoom[z]])
    # every (pan, tilt, zoom) combination appears exactly once
    assert len({tuple(row) for row in indices.tolist()}) == grid.size
    assert len({tuple(row) for row in poses.tolist()}) == grid.size
    # vectorised index is the inverse of axis_indices, pan-major then tilt then zoom
    np.testing.assert_array_equal(grid.index(indices[:, 0], indices[:, 1], indices[:, 2]), np.arange(grid.size))
    assert grid.index(0, 0, 1) == 1
    assert grid.index(0, 1, 0) == grid.shape[2]
    assert grid.index(1, 0, 0) == grid.shape[1] * grid.shape[2]


def test_index_rejects_out_of_range():
    with pytest.raises(ValueError):
        GRID.index(7, 0, 0)
    with pytest.raises(ValueError):
        GRID.index(0, -1, 0)


@pytest.mark.parametrize("corner", list(itertools.product([0, 6], [0, 9], [0, 3])))
def test_reachable_at_corners(corner):
    current = int(GRID.index(*corner))
    reachable = GRID.reachable(current)
    assert len(reachable) == 3 * 3 * 2
    np.testing.assert_array_equal(reachable, expected_reachable(GRID, corner))
    assert current in reachable
    mask = GRID.reachable_mask(current)
    assert mask.shape == (280,) and mask.dtype == bool
    assert mask.sum() == 18
    np.testing.assert_array_equal(np.flatnonzero(mask), reachable)


def test_reachable_at_interior_action():
    here = (3, 5, 1)
    reachable = GRID.reachable(int(GRID.index(*here)))
    assert len(reachable) == 5 * 5 * 3
    np.testing.assert_array_equal(reachable, expected_reachable(GRID, here))
    steps = GRID.axis_indices[reachable] - np.array(here)
    np.testing.assert_array_equal(steps.min(axis=0), [-2, -2, -1])
    np.testing.assert_array_equal(steps.max(axis=0), [2, 2, 1])


def test_reachable_everywhere_matches_product_of_ranges():
    for grid in (GRID, small_grid()):
        for k in range(grid.size):
            np.testing.assert_array_equal(grid.reachable(k), expected_reachable(grid, grid.axis_indices[k]))


def test_small_grid_with_a_frozen_axis():
    grid = small_grid()  # pan +-1, tilt frozen, zoom +-2
    here = (1, 1, 0)
    reachable = grid.reachable(int(grid.index(*here)))
    # pan 0..2 (3), tilt stays 1 (1), zoom 0..2 (3)
    assert len(reachable) == 9
    assert set(grid.axis_indices[reachable][:, 1].tolist()) == {1}
    assert set(grid.axis_indices[reachable][:, 2].tolist()) == {0, 1, 2}
    # tilt can never change, so step_towards keeps the tilt index
    target = int(grid.index(0, 0, 3))
    assert tuple(grid.axis_indices[grid.step_towards(int(grid.index(*here)), target)]) == (0, 1, 2)


def test_reachable_is_symmetric():
    mask = GRID.reachable_mask(np.arange(GRID.size))
    np.testing.assert_array_equal(mask, mask.T)
    assert np.all(np.diag(mask))


@PROPERTY
@given(st.lists(st.integers(0, 279), min_size=1, max_size=12))
def test_reachable_mask_batched_equals_stacked_singles(current):
    current = np.array(current)
    batch = GRID.reachable_mask(current)
    assert batch.shape == (len(current), 280)
    np.testing.assert_array_equal(batch, np.stack([GRID.reachable_mask(int(c)) for c in current]))


def test_step_towards_corner_to_opposite_corner():
    start = int(GRID.index(0, 0, 0))
    target = int(GRID.index(6, 9, 3))
    step = GRID.step_towards(start, target)
    assert isinstance(step, int)
    np.testing.assert_array_equal(GRID.axis_indices[step], [2, 2, 1])
    back = GRID.step_towards(target, start)
    np.testing.assert_array_equal(GRID.axis_indices[back], [4, 7, 2])
    # a target already reachable is reached in one step; the target itself stays put
    near = int(GRID.index(1, 2, 1))
    assert GRID.step_towards(start, near) == near
    assert GRID.step_towards(target, target) == target


@PROPERTY
@given(st.integers(0, 279), st.integers(0, 279))
def test_step_towards_path_reaches_target(start, target):
    here = GRID.axis_indices[start]
    goal = GRID.axis_indices[target]
    steps = np.asarray(GRID.max_steps)
    expected_length = int(np.max(np.ceil(np.abs(goal - here) / steps)))

    path = [start]
    while path[-1] != target:
        previous = path[-1]
        nxt = GRID.step_towards(previous, target)
        assert nxt in GRID.reachable(previous)
        move = GRID.axis_indices[nxt] - GRID.axis_indices[previous]
        remaining = goal - GRID.axis_indices[previous]
        # each axis moves as far as allowed towards the target, never past it
        np.testing.assert_array_equal(move, np.clip(remaining, -steps, steps))
        # and the result is the reachable action closest to the target (grid steps, L1)
        reachable = GRID.reachable(previous)
        distances = np.abs(GRID.axis_indices[reachable] - goal).sum(axis=1)
        assert np.abs(GRID.axis_indices[nxt] - goal).sum() == distances.min()
        path.append(nxt)
        assert len(path) <= expected_length + 1
    assert len(path) == expected_length + 1
