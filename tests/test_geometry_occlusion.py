"""Tests of occluded_fraction in ptztrack.geometry.occlusion: the share of each person's box (left, top,
right, bottom) px hidden by the boxes of nearer people, on hand-computed cases and against rasters."""

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from information_gain_reference import occluded_fraction_by_cells
from ptztrack.geometry.occlusion import occluded_fraction

PROPERTY = settings(deadline=None, max_examples=100)


def fraction(boxes, depths, valid=None):
    boxes = np.asarray(boxes, dtype=float)
    depths = np.asarray(depths, dtype=float)
    valid = np.ones(depths.shape, dtype=bool) if valid is None else np.asarray(valid, dtype=bool)
    return occluded_fraction(boxes, depths, valid)


# ---------------------------------------------------------------------------
# occluded_fraction: hand-computed cases


def test_two_boxes_partial_overlap():
    result = fraction([[0, 0, 10, 10], [5, 5, 15, 15]], [5.0, 1.0])
    np.testing.assert_allclose(result, [0.25, 0.0], rtol=0, atol=1e-15)
    # swapping the depths swaps who is hidden
    result = fraction([[0, 0, 10, 10], [5, 5, 15, 15]], [1.0, 5.0])
    np.testing.assert_allclose(result, [0.0, 0.25], rtol=0, atol=1e-15)


def test_overlapping_occluders_are_not_double_counted():
    boxes = [[0, 0, 10, 10], [0, 0, 6, 10], [4, 0, 10, 10]]
    result = fraction(boxes, [10.0, 1.0, 2.0])
    # target fully covered (not 1.2); the second occluder is a third behind the first
    np.testing.assert_allclose(result, [1.0, 0.0, 20.0 / 60.0], rtol=0, atol=1e-15)


def test_union_of_two_partial_occluders():
    boxes = [[0, 0, 10, 10], [0, 0, 5, 5], [3, 3, 8, 8]]
    result = fraction(boxes, [10.0, 1.0, 1.0])  # equal-depth occluders do not hide each other
    np.testing.assert_allclose(result, [(25 + 25 - 4) / 100.0, 0.0, 0.0], rtol=0, atol=1e-15)


def test_occluder_larger_than_target_is_clipped():
    result = fraction([[2, 2, 4, 6], [-100, 3, 100, 100]], [3.0, 2.0])
    np.testing.assert_allclose(result, [3.0 / 4.0, 0.0], rtol=0, atol=1e-15)


def test_invalid_occluder_has_no_effect():
    boxes = [[0, 0, 10, 10], [5, 5, 15, 15], [0, 0, 6, 10]]
    depths = [5.0, 1.0, 1.0]
    np.testing.assert_allclose(fraction(boxes, depths, [True, False, False]), [0.0, 0.0, 0.0], atol=1e-15)
    np.testing.assert_allclose(fraction(boxes, depths, [True, True, False]), [0.25, 0.0, 0.0], atol=1e-15)
    np.testing.assert_allclose(fraction(boxes, depths, [True, False, True]), [0.6, 0.0, 0.0], atol=1e-15)
    # an invalid target is reported as not hidden
    np.testing.assert_allclose(fraction(boxes, depths, [False, True, True]), [0.0, 0.0, 0.0], atol=1e-15)


def test_nearer_box_is_not_hidden_by_farther_people():
    boxes = [[0, 0, 10, 10], [0, 0, 10, 10], [-5, -5, 20, 20]]
    result = fraction(boxes, [1.0, 2.0, 3.0])
    # the nearest sees everything; the middle one is exactly covered by the nearest;
    # the farthest (area 625) has the 100 px of the two nearer boxes hidden
    np.testing.assert_allclose(result, [0.0, 1.0, 100.0 / 625.0], rtol=0, atol=1e-15)


def test_equal_depths_and_disjoint_and_degenerate_boxes():
    # identical boxes at identical depth do not hide each other
    np.testing.assert_allclose(fraction([[0, 0, 4, 4], [0, 0, 4, 4]], [2.0, 2.0]), [0.0, 0.0])
    # disjoint boxes and boxes touching along an edge
    np.testing.assert_allclose(fraction([[0, 0, 4, 4], [4, 0, 8, 4], [20, 20, 30, 30]], [3.0, 1.0, 0.5]), [0, 0, 0])
    # zero-area targets come out as 0, not NaN
    result = fraction([[1, 1, 1, 5], [0, 0, 10, 10]], [5.0, 1.0])
    np.testing.assert_array_equal(result, [0.0, 0.0])
    # a single person and no people at all
    np.testing.assert_array_equal(fraction([[0, 0, 1, 1]], [1.0]), [0.0])
    assert fraction(np.zeros((0, 4)), np.zeros(0)).shape == (0,)


# ---------------------------------------------------------------------------
# occluded_fraction against a brute-force raster


GRID_PX = 12


def raster(box):
    left, top, right, bottom = (int(v) for v in box)
    mask = np.zeros((GRID_PX, GRID_PX), dtype=bool)
    mask[top:bottom, left:right] = True
    return mask


def brute_force_fraction(boxes, depths, valid):
    boxes = np.asarray(boxes)
    result = np.zeros(len(boxes))
    for i, box in enumerate(boxes):
        target = raster(box)
        if not valid[i] or not target.any():
            continue
        union = np.zeros_like(target)
        for j, other in enumerate(boxes):
            if j != i and valid[j] and depths[j] < depths[i]:
                union |= raster(other)
        result[i] = np.count_nonzero(target & union) / np.count_nonzero(target)
    return result


@st.composite
def integer_people(draw, count):
    boxes = []
    for _ in range(count):
        left, right = sorted(draw(st.lists(st.integers(0, GRID_PX), min_size=2, max_size=2)))
        top, bottom = sorted(draw(st.lists(st.integers(0, GRID_PX), min_size=2, max_size=2)))
        boxes.append([left, top, right, bottom])
    depths = draw(st.lists(st.integers(0, 4), min_size=count, max_size=count))  # ties on purpose
    valid = draw(st.lists(st.booleans(), min_size=count, max_size=count))
    return np.array(boxes, dtype=float), np.array(depths, dtype=float), np.array(valid, dtype=bool)


@PROPERTY
@given(st.integers(1, 7).flatmap(integer_people))
def test_occluded_fraction_matches_raster(people):
    boxes, depths, valid = people
    result = occluded_fraction(boxes, depths, valid)
    expected = brute_force_fraction(boxes, depths, valid)
    np.testing.assert_allclose(result, expected, rtol=1e-12, atol=1e-12)
    assert np.all((result >= 0) & (result <= 1))
    # scaling by a power of two and shifting (exact in floating point) changes nothing
    moved = boxes * 0.25 + np.array([100.5, -7.25, 100.5, -7.25])
    np.testing.assert_allclose(occluded_fraction(moved, depths, valid), expected, rtol=1e-12, atol=1e-12)


@PROPERTY
@given(st.integers(1, 5).flatmap(lambda count: st.lists(integer_people(count), min_size=1, max_size=4)))
def test_occluded_fraction_batched_matches_raster(frames):
    boxes = np.stack([f[0] for f in frames])  # (B, N, 4)
    depths = np.stack([f[1] for f in frames])
    valid = np.stack([f[2] for f in frames])
    result = occluded_fraction(boxes, depths, valid)
    assert result.shape == depths.shape
    for b, (box, depth, ok) in enumerate(frames):
        np.testing.assert_allclose(result[b], brute_force_fraction(box, depth, ok), rtol=1e-12, atol=1e-12)
    # two leading axes
    twice = occluded_fraction(
        np.stack([boxes, boxes[::-1]]), np.stack([depths, depths[::-1]]), np.stack([valid, valid[::-1]])
    )
    assert twice.shape == (2,) + depths.shape
    np.testing.assert_allclose(twice[0], result, rtol=1e-12, atol=1e-12)
    np.testing.assert_allclose(twice[1], result[::-1], rtol=1e-12, atol=1e-12)


def test_occluded_fraction_matches_cutting_every_box_along_all_edges():
    """Real-valued boxes of crowds, where each target meets many occluders: the kernel cuts a
    box only along the edges of the boxes that overlap it, the reference along all of them."""
    rng = np.random.default_rng(12)
    frames, count = 200, 12
    corner = rng.uniform(0, 60, size=(frames, count, 2))
    size = rng.uniform(0, 30, size=(frames, count, 2)) * (rng.random((frames, count, 1)) > 0.05)
    boxes = np.concatenate([corner, corner + size], axis=-1)
    depths = rng.integers(0, 6, size=(frames, count)).astype(float)  # ties on purpose
    valid = rng.random((frames, count)) > 0.1
    result = occluded_fraction(boxes, depths, valid)
    expected = occluded_fraction_by_cells(boxes, depths, valid)
    np.testing.assert_allclose(result, expected, rtol=1e-12, atol=1e-12)
    assert np.mean((expected > 0.05) & (expected < 0.95)) > 0.2, "many boxes must be partly hidden"
