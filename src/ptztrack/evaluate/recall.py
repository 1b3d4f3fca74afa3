"""Fitting the detector model the policies plan with to the detector actually used.

The policies weigh every view by ``recall(r) = 1 - exp(-Kd (r - r0))`` for a
person ``r`` pixels tall (the paper's equation 13, fitted there to HOG on the
Caltech pedestrians). Another detector, or the same one on upsampled views,
has another curve; planning with the wrong one makes a camera zoom in to find
people it could already see. :func:`fit_recall` estimates ``Kd`` and ``r0``
by maximum likelihood from people of known height that were or were not
detected, and :func:`recorded_hog_trials` collects such people from a
recording: it runs the HOG detector on virtual views at every zoom and marks
each unoccluded annotated person as detected when a box's feet fall near its
annotated feet.
"""

import numpy as np
from scipy.optimize import minimize

from ptztrack.camera.recorded import RecordedPTZ
from ptztrack.detect.hog import feet_and_height_px

# Beyond this share of its height, a box's feet are not this person's.
MATCH_FRACTION_OF_HEIGHT = 0.3
# Keeps the log-likelihood finite where the curve says 0 or 1.
PROBABILITY_FLOOR = 1e-4


def recall_curve(height_px, recall_kd: float, recall_r0_px: float) -> np.ndarray:
    # Below r0 the curve is 0; clipping there keeps expm1 from overflowing for the discarded values.
    above_r0_px = np.maximum(np.asarray(height_px, dtype=float) - recall_r0_px, 0.0)
    return np.where(height_px >= recall_r0_px, -np.expm1(-recall_kd * above_r0_px), 0.0)


def fit_recall(height_px, detected) -> tuple[float, float]:
    """Maximum-likelihood ``(Kd, r0)`` of the recall curve from Bernoulli trials.

    height_px : (K,) pixel heights of people fully in view and unoccluded;
    detected : (K,) bool, whether the detector found each.
    """
    height_px = np.asarray(height_px, dtype=float)
    detected = np.asarray(detected, dtype=bool)

    def negative_log_likelihood(parameters):
        log_kd, r0 = parameters
        p = np.clip(recall_curve(height_px, np.exp(log_kd), r0), PROBABILITY_FLOOR, 1 - PROBABILITY_FLOOR)
        return -np.sum(np.where(detected, np.log(p), np.log1p(-p)))

    # The likelihood has several local optima in (Kd, r0): start from a grid.
    starts = [(np.log(kd), r0) for kd in (0.01, 0.05, 0.2, 0.5) for r0 in (5.0, 10.0, 15.0, 20.0)]
    best = min(
        (minimize(negative_log_likelihood, start, method="Nelder-Mead") for start in starts),
        key=lambda result: result.fun,
    )
    return float(np.exp(best.x[0])), float(best.x[1])


def recorded_hog_trials(backend: RecordedPTZ, poses, steps) -> tuple[np.ndarray, np.ndarray]:
    """Heights (K,) and detected flags (K,) of the annotated people, fully in view and not
    occluded, in the virtual views at ``poses`` of the recording's ``steps``."""
    heights, detected = [], []
    for step in steps:
        for pose in poses:
            annotated = backend.observe_annotations(step, pose, np.random.default_rng(0), pixel_noise=False)
            if len(annotated) == 0:
                continue
            boxes = backend.observe_hog_boxes(step, pose)
            feet_px, _ = feet_and_height_px(boxes)
            if len(feet_px):
                distance = np.linalg.norm(annotated.feet_px[:, None] - feet_px[None], axis=-1).min(axis=1)
            else:
                distance = np.full(len(annotated), np.inf)
            heights.append(annotated.height_px)
            detected.append(distance <= MATCH_FRACTION_OF_HEIGHT * annotated.height_px)
    return np.concatenate(heights), np.concatenate(detected)
