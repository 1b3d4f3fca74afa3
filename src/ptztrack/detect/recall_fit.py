"""Fitting the detector model the policies plan with to the detector actually used.

The policies weigh every view by ``recall(r) = 1 - exp(-Kd (r - r0))`` for a
person ``r`` pixels tall (the paper's equation 13, fitted there to HOG on the
Caltech pedestrians). Another detector, or the same one on upsampled views,
has another curve; planning with the wrong one makes a camera zoom in to find
people it could already see. :func:`fit_recall` estimates ``Kd`` and ``r0``
by maximum likelihood from people of known height that were or were not
detected, and :func:`detection_trials` collects such people from a
simulated camera (a recording seen by the virtual camera, say): it runs a
detector on the views at given poses and marks each unoccluded person in
view as detected when a detection's feet fall near the person's.
"""

import numpy as np
from scipy.optimize import minimize

from ptztrack.detect.simulated import realistic_recall
from ptztrack.roles import CameraBackend, Detector

# Beyond this share of its height, a box's feet are not this person's.
MATCH_FRACTION_OF_HEIGHT = 0.3
# Keeps the log-likelihood finite where the curve says 0 or 1.
PROBABILITY_FLOOR = 1e-4


def fit_recall(height_px, detected) -> tuple[float, float]:
    """Maximum-likelihood ``(Kd, r0)`` of the recall curve from Bernoulli trials.

    height_px : (K,) pixel heights of people fully in view and unoccluded;
    detected : (K,) bool, whether the detector found each.
    """
    height_px = np.asarray(height_px, dtype=float)
    detected = np.asarray(detected, dtype=bool)

    def negative_log_likelihood(parameters):
        log_kd, r0 = parameters
        p = np.clip(realistic_recall(height_px, np.exp(log_kd), r0), PROBABILITY_FLOOR, 1 - PROBABILITY_FLOOR)
        return -np.sum(np.where(detected, np.log(p), np.log1p(-p)))

    # The likelihood has several local optima in (Kd, r0): start from a grid.
    starts = [(np.log(kd), r0) for kd in (0.01, 0.05, 0.2, 0.5) for r0 in (5.0, 10.0, 15.0, 20.0)]
    best = min(
        (minimize(negative_log_likelihood, start, method="Nelder-Mead") for start in starts),
        key=lambda result: result.fun,
    )
    return float(np.exp(best.x[0])), float(best.x[1])


def detection_trials(
    camera: CameraBackend, detector: Detector, poses, steps, max_hidden: float
) -> tuple[np.ndarray, np.ndarray]:
    """Heights (K,) and detected flags (K,) of the people wholly in view and hidden at most
    ``max_hidden``, in the views at ``poses`` of ``steps``, as ``camera.people`` knows them."""
    heights, detected = [], []
    rng = np.random.default_rng(0)
    for step in steps:
        for pose in poses:
            people = camera.people(step, pose)
            if people is None:
                raise RuntimeError("fitting a recall curve needs a camera that knows who is in view (a simulation)")
            visible = people.in_view & (people.hidden <= max_hidden)
            if not visible.any():
                continue
            feet_px = detector.detect(camera, step, pose, rng).feet_px
            if len(feet_px):
                distance = np.linalg.norm(people.feet_px[visible, None] - feet_px[None], axis=-1).min(axis=1)
            else:
                distance = np.full(visible.sum(), np.inf)
            heights.append(people.height_px[visible])
            detected.append(distance <= MATCH_FRACTION_OF_HEIGHT * people.height_px[visible])
    return np.concatenate(heights), np.concatenate(detected)
