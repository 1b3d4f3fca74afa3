"""The robot-cameraman paper's target model (Nair et al. 2008, sections III-B, III-C3): multi-patch colour histograms.

A target is a box with rectangular patches inside it (the paper's head, torso
and legs; by default the torso and the legs are each split into a left and a
right half), each described by a normalised 2-D hue-saturation histogram of
N x N bins (the paper's N = 10), optionally with N more bins by value for
the pixels too grey or too dark to have a hue (:func:`colour_bins`). A candidate box is compared with the
reference patch by patch through the Bhattacharyya distance (equation 2),

    B_p = sqrt(1 - sum_n sqrt(q*_p(n) q_p(n))),

and the colour likelihood is exp(-sum_p B_p^2 / lambda_col) (equation 3).

States are boxes ``(x, y, h)``: the box centre (px) and its height (px); its
width is ``aspect * h``, the aspect ratio of the box the target was
initialised with. Patches are rows ``(left, top, width, height)`` in units of
the box (0 at its left or top edge, 1 at the right or bottom).

Sampling: every patch's histogram is taken from a regular grid of
``samples x samples`` points, the pixel under each point counted once, so
that a particle costs the same whatever its size and all particles are one
array operation. A patch of exactly ``samples x samples`` pixels is counted
pixel by pixel (the test compares it with ``cv2.calcHist``); a smaller patch
counts its pixels by the area they cover, a larger one every k-th pixel.
Points outside the image are not counted; a patch wholly outside has an empty
histogram, at distance 1 from anything.
"""

import cv2
import numpy as np

from ptztrack.track.appearance import CHANNEL_LEVELS, HUE_LEVELS

# Perez, Hue, Vermaak and Gangnet, "Color-based probabilistic tracking" (ECCV 2002), section 3.1.
ACHROMATIC_SATURATION, ACHROMATIC_VALUE = 0.1, 0.2


def colour_bins(image_bgr, bins: int, achromatic: bool = False) -> np.ndarray:
    """The bin (h, w) int32 of every pixel of a uint8 BGR image (h, w, 3): ``hue_bin * bins + saturation_bin``.

    achromatic : as Perez et al. (ECCV 2002) do, pixels whose saturation is below 0.1 or value below
    0.2 (their hue and saturation are noise) go to ``bins`` extra bins by value alone, after the
    ``bins * bins`` hue-saturation ones.
    """
    hsv = cv2.cvtColor(np.ascontiguousarray(image_bgr, dtype=np.uint8), cv2.COLOR_BGR2HSV).astype(np.int32)
    hue, saturation, value = hsv[..., 0], hsv[..., 1], hsv[..., 2]
    labels = hue * bins // HUE_LEVELS * bins + saturation * bins // CHANNEL_LEVELS
    if achromatic:
        grey = (saturation < ACHROMATIC_SATURATION * CHANNEL_LEVELS) | (value < ACHROMATIC_VALUE * CHANNEL_LEVELS)
        labels = np.where(grey, bins * bins + value * bins // CHANNEL_LEVELS, labels)
    return labels


def bin_count(bins: int, achromatic: bool = False) -> int:
    """How many bins :func:`colour_bins` uses."""
    return bins * bins + (bins if achromatic else 0)


def box_of_states(states, aspect: float) -> np.ndarray:
    """Boxes (..., 4) (left, top, width, height) px of states (..., 3) (x_px, y_px, h_px); aspect : width / height."""
    states = np.asarray(states, dtype=float)
    x, y, h = states[..., 0], states[..., 1], states[..., 2]
    return np.stack([x - aspect * h / 2, y - h / 2, aspect * h, h], axis=-1)


def patch_boxes(boxes_px, patches) -> np.ndarray:
    """The patches (K, 4) (box units) of boxes (..., 4) px, as boxes (..., K, 4) (left, top, width, height) px."""
    boxes_px = np.asarray(boxes_px, dtype=float)[..., None, :]
    patches = np.asarray(patches, dtype=float)
    origin = boxes_px[..., :2] + patches[:, :2] * boxes_px[..., 2:]
    return np.concatenate([origin, patches[:, 2:] * boxes_px[..., 2:]], axis=-1)


def patch_histograms(bin_image, boxes_px, total_bins: int, samples: int) -> np.ndarray:
    """Normalised colour histograms (..., total_bins) of boxes (..., 4) px in a bin image (h, w).

    bin_image : from :func:`colour_bins`, pixel ``(row, col)`` covering ``[col, col + 1) x
    [row, row + 1)``. Each box is sampled on a ``samples x samples`` grid of points at the centres of
    equal cells (see the module). A box with no point in the image gets a histogram of zeros.
    """
    boxes_px = np.asarray(boxes_px, dtype=float)
    leading, flat_boxes = boxes_px.shape[:-1], boxes_px.reshape(-1, 4)
    height, width = bin_image.shape
    fractions = (np.arange(samples) + 0.5) / samples
    columns = np.floor(flat_boxes[:, :1] + fractions * flat_boxes[:, 2:3]).astype(np.intp)  # (n, S)
    rows = np.floor(flat_boxes[:, 1:2] + fractions * flat_boxes[:, 3:4]).astype(np.intp)
    # A border of one extra bin, ``total_bins``, catches the points outside the image; it is dropped after.
    padded = np.pad(bin_image.astype(np.int32, copy=False), 1, constant_values=total_bins).ravel()
    at = np.clip(rows + 1, 0, height + 1)[:, :, None] * (width + 2) + np.clip(columns + 1, 0, width + 1)[:, None, :]
    labels = padded.take(at) + (np.arange(len(flat_boxes), dtype=np.int32) * (total_bins + 1))[:, None, None]
    counts = np.bincount(labels.ravel(), minlength=len(flat_boxes) * (total_bins + 1))
    counts = counts.reshape(len(flat_boxes), total_bins + 1)[:, :total_bins]
    return (counts / np.maximum(counts.sum(axis=1, keepdims=True), 1.0)).reshape(*leading, total_bins)


def bhattacharyya_distance(reference, histograms) -> np.ndarray:
    """Equation 2: ``sqrt(1 - sum_n sqrt(q*(n) q(n)))`` over the last axis; broadcasts; in [0, 1]."""
    coefficient = np.sum(np.sqrt(np.asarray(reference) * np.asarray(histograms)), axis=-1)
    return np.sqrt(np.clip(1.0 - coefficient, 0.0, 1.0))


def background_weights(bin_image, box_px, total_bins: int, ring_scale: float) -> np.ndarray:
    """Weights (total_bins,) in [0, 1] that play down the colours of the background around a box.

    Comaniciu, Ramesh and Meer, "Kernel-based object tracking" (PAMI 2003), section 6.2: with ``o``
    the histogram of the ring between the box (left, top, width, height) px and the same box scaled by
    ``ring_scale`` about its centre (clipped to the bin image (h, w)), bin ``u`` weighs
    ``min(o* / o_u, 1)``, ``o*`` the smallest non-zero ``o_u``; a bin absent from the ring weighs 1.
    """
    height, width = bin_image.shape
    left, top, box_width, box_height = (float(value) for value in box_px)
    centre = np.array([left + box_width / 2, top + box_height / 2])
    half_outer = np.array([box_width, box_height]) * ring_scale / 2
    col0, row0 = np.clip(np.floor(centre - half_outer), 0, [width, height]).astype(int)
    col1, row1 = np.clip(np.ceil(centre + half_outer), 0, [width, height]).astype(int)
    rows, cols = np.mgrid[row0:row1, col0:col1] + 0.5
    in_box = (cols >= left) & (cols < left + box_width) & (rows >= top) & (rows < top + box_height)
    ring = np.bincount(bin_image[row0:row1, col0:col1][~in_box], minlength=total_bins)[:total_bins]
    if not ring.any():
        return np.ones(total_bins)
    smallest = ring[ring > 0].min()
    return np.where(ring > 0, smallest / np.maximum(ring, 1), 1.0)


def weigh_histograms(histograms, bin_weights) -> np.ndarray:
    """Histograms (..., B) times the bin weights (B,), normalised again (a histogram of zeros stays so)."""
    weighted = np.asarray(histograms) * bin_weights
    return weighted / np.maximum(weighted.sum(axis=-1, keepdims=True), np.finfo(float).tiny)


def colour_log_likelihood(distances, lambda_colour: float) -> np.ndarray:
    """The log of equation 3, ``-sum_p B_p^2 / lambda_col``, of distances (..., K); returns (...)."""
    return -np.sum(np.asarray(distances) ** 2, axis=-1) / lambda_colour
