"""The multi-patch hue-saturation model of the robot-cameraman paper (equations 2 and 3)."""

import cv2
import numpy as np
import pytest

from ptztrack.follow.colour_model import (
    background_weights,
    bhattacharyya_distance,
    bin_count,
    box_of_states,
    colour_bins,
    colour_log_likelihood,
    patch_boxes,
    patch_histograms,
    weigh_histograms,
)


def test_bhattacharyya_distance_of_a_pair_computed_by_hand():
    reference = np.array([0.5, 0.5, 0.0, 0.0])
    candidate = np.array([0.25, 0.25, 0.5, 0.0])
    # sum sqrt(q* q) = 2 sqrt(0.125) = 0.70711; B = sqrt(1 - 0.70711) = 0.54120
    assert bhattacharyya_distance(reference, candidate) == pytest.approx(0.541196, abs=1e-6)
    # OpenCV's Bhattacharyya distance of normalised histograms is the same quantity.
    opencv = cv2.compareHist(reference.astype(np.float32), candidate.astype(np.float32), cv2.HISTCMP_BHATTACHARYYA)
    assert bhattacharyya_distance(reference, candidate) == pytest.approx(opencv, abs=1e-6)
    assert bhattacharyya_distance(reference, reference) == pytest.approx(0.0, abs=1e-8)
    assert bhattacharyya_distance(reference, [0.0, 0.0, 0.5, 0.5]) == 1.0


def test_colour_likelihood_of_equation_3():
    distances = np.array([[0.1, 0.2, 0.3], [0.0, 0.0, 0.0]])
    # -(0.01 + 0.04 + 0.09) / 0.5 = -0.28
    np.testing.assert_allclose(colour_log_likelihood(distances, 0.5), [-0.28, 0.0])


def test_a_patch_of_samples_x_samples_pixels_has_opencvs_histogram():
    rng = np.random.default_rng(0)
    image = rng.integers(0, 256, (60, 80, 3), dtype=np.uint8)
    bins, samples = 10, 16
    box = np.array([21.0, 13.0, samples, samples])  # whole pixels: every grid point on its own pixel
    ours = patch_histograms(colour_bins(image, bins), box, bin_count(bins), samples)
    hsv = cv2.cvtColor(image[13:29, 21:37], cv2.COLOR_BGR2HSV)
    theirs = cv2.calcHist([hsv], [0, 1], None, [bins, bins], [0, 180, 0, 256]).ravel()
    np.testing.assert_allclose(ours, theirs / theirs.sum(), atol=1e-12)


def test_histograms_of_many_boxes_at_once_equal_one_at_a_time():
    rng = np.random.default_rng(1)
    labels = colour_bins(rng.integers(0, 256, (50, 70, 3), dtype=np.uint8), 10)
    boxes = np.array(
        [[[3.2, 4.7, 20.0, 11.5], [40.0, 30.0, 9.0, 30.0]], [[-5.0, -5.0, 10.0, 10.0], [60.0, 45.0, 30, 30]]]
    )
    together = patch_histograms(labels, boxes, 100, 12)
    assert together.shape == (2, 2, 100)
    for index in np.ndindex(2, 2):
        np.testing.assert_array_equal(together[index], patch_histograms(labels, boxes[index], 100, 12))
    np.testing.assert_allclose(together.sum(axis=-1), 1.0)


def test_a_box_outside_the_image_has_no_pixels_and_is_as_far_as_can_be():
    labels = np.zeros((20, 20), dtype=np.intp)
    outside = patch_histograms(labels, [25.0, 0.0, 5.0, 5.0], 100, 8)
    assert not outside.any()
    inside = patch_histograms(labels, [2.0, 2.0, 5.0, 5.0], 100, 8)
    assert bhattacharyya_distance(inside, outside) == 1.0


def test_grey_and_dark_pixels_go_to_value_bins_only_when_asked():
    # BGR: saturated red, mid grey, near black.
    image = np.array([[[0, 0, 200], [128, 128, 128], [10, 12, 14]]], dtype=np.uint8)
    hsv = cv2.cvtColor(image, cv2.COLOR_BGR2HSV)[0].astype(int)
    plain = colour_bins(image, 10)
    np.testing.assert_array_equal(plain, [(hsv[:, 0] * 10 // 180) * 10 + hsv[:, 1] * 10 // 256])
    split = colour_bins(image, 10, achromatic=True)
    assert split[0, 0] == plain[0, 0]  # red keeps its hue-saturation bin
    np.testing.assert_array_equal(split[0, 1:], [100 + 128 * 10 // 256, 100 + 14 * 10 // 256])
    assert bin_count(10, achromatic=True) == 110


def test_patches_are_placed_in_box_units():
    box = box_of_states([50.0, 100.0, 80.0], aspect=0.5)  # centre (50, 100), 40 x 80
    np.testing.assert_allclose(box, [30.0, 60.0, 40.0, 80.0])
    head_and_legs = patch_boxes(box, [[0.25, 0.0, 0.5, 0.125], [0.0, 0.5, 1.0, 0.5]])
    np.testing.assert_allclose(head_and_legs, [[40.0, 60.0, 20.0, 10.0], [30.0, 100.0, 40.0, 40.0]])


def test_background_weights_of_a_ring_counted_by_hand():
    """Comaniciu et al.'s weights min(o*/o_u, 1): a box of bin 0 in a ring of 36 pixels of bin 1 and 12 of
    bin 2 (o* = 12); bins 0 and 3 are not in the ring; pixels beyond the ring do not count."""
    bin_image = np.full((12, 12), 3)
    bin_image[1:9, 1:9] = 1  # the ring's outer box: 8 x 8 pixels around the 4 x 4 box
    bin_image[1, 1:9] = 2
    bin_image[2, 1:5] = 2
    bin_image[3:7, 3:7] = 0  # the box
    weights = background_weights(bin_image, (3.0, 3.0, 4.0, 4.0), 4, ring_scale=2.0)
    np.testing.assert_allclose(weights, [1.0, 12 / 36, 1.0, 1.0])
    # Weighted histograms are normalised again; the background's colour counts for less.
    np.testing.assert_allclose(weigh_histograms([[0.5, 0.5, 0.0, 0.0]], weights), [[0.75, 0.25, 0.0, 0.0]])
    np.testing.assert_array_equal(weigh_histograms(np.zeros(4), weights), np.zeros(4))


def test_a_box_on_plain_background_plays_down_the_background_colour_only():
    """A red figure with a grey head on grey paving: the grey bins weigh little, the red ones fully, and
    the empty paving, which shares the head's grey, is further from the figure once weighted."""
    paving = np.full((80, 80, 3), 128, np.uint8)
    paving[::7, ::5] = (120, 128, 136)  # a few pixels of a second grey: the paving is not uniform
    figure = paving.copy()
    cv2.rectangle(figure, (30, 20), (49, 59), (30, 30, 220), -1)
    figure[20:30, 30:50] = 128
    bins = colour_bins(figure, 10)
    box = np.array([30.0, 20.0, 20.0, 40.0])
    weights = background_weights(bins, box, bin_count(10), ring_scale=3**0.5)
    assert weights[bins[40, 40]] == 1.0 and weights[bins[1, 1]] < 0.1
    target, empty = (patch_histograms(b, box, bin_count(10), 20) for b in (bins, colour_bins(paving, 10)))
    unweighted = bhattacharyya_distance(target, empty)
    weighted = bhattacharyya_distance(weigh_histograms(target, weights), weigh_histograms(empty, weights))
    assert weighted > unweighted + 0.1
