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
view as detected when a detection's feet fall near the person's, and
measures how far from the person's true ground point the feet fall (the
detector's pixel noise).
"""

from dataclasses import dataclass

import numpy as np
from scipy.optimize import minimize

from ptztrack.detect.simulated import realistic_recall
from ptztrack.geometry.ptz import PTZCamera, apply_homography, ground_to_image
from ptztrack.roles import CameraBackend, Detector
from ptztrack.types import GroundTruth

# Beyond this share of its height, a box's feet are not this person's.
MATCH_FRACTION_OF_HEIGHT = 0.3
# Keeps the log-likelihood finite where the curve says 0 or 1.
PROBABILITY_FLOOR = 1e-4
MIN_R0_PX = 1.0


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

    # The likelihood has several local optima in (Kd, r0): start from a grid. r0 is at least
    # MIN_R0_PX: the curve then says that nobody under a pixel is found, and the walkable area,
    # which ends where people look smaller than r0, is finite.
    starts = [(np.log(kd), r0) for kd in (0.01, 0.05, 0.2, 0.5) for r0 in (5.0, 10.0, 15.0, 20.0)]
    bounds = [(None, None), (MIN_R0_PX, None)]
    best = min(
        (minimize(negative_log_likelihood, start, method="Nelder-Mead", bounds=bounds) for start in starts),
        key=lambda result: result.fun,
    )
    return float(np.exp(best.x[0])), float(best.x[1])


@dataclass(frozen=True)
class DetectionTrials:
    """People in view, whether a detector found each, and where it put their feet.

    height_px : (K,) their pixel heights; detected : (K,) bool;
    feet_error_px : (M, 2) for each found person, the detected feet minus the pixel of the person's
    true ground position (the error the tracker maps to the ground).
    """

    height_px: np.ndarray
    detected: np.ndarray
    feet_error_px: np.ndarray

    @property
    def pixel_noise_px(self) -> float:
        """The root mean square of the feet errors per axis: the detector's pixel noise, 1 sigma."""
        return float(np.sqrt(np.mean(self.feet_error_px**2))) if len(self.feet_error_px) else float("nan")


def detection_trials(
    camera: CameraBackend,
    detector: Detector,
    model: PTZCamera,
    truth: GroundTruth,
    poses,
    steps,
    max_hidden: float,
) -> DetectionTrials:
    """The people wholly in view and hidden at most ``max_hidden``, in the views at ``poses`` of
    ``steps``, as ``camera.people`` knows them, and the detections near them.

    A person counts as found when a detection's feet lie within ``MATCH_FRACTION_OF_HEIGHT`` of its
    height from the person's feet; the feet error is taken against the pixel of the person's true
    ground position (``truth``, through the camera ``model``'s homography at the pose).
    """
    heights, found, errors = [], [], []
    rng = np.random.default_rng(0)
    for step in steps:
        for pose in poses:
            people = camera.people(step, pose)
            if people is None:
                raise RuntimeError("fitting a detector model needs a camera that knows who is in view (a simulation)")
            visible = people.in_view & (people.hidden <= max_hidden)
            if not visible.any():
                continue
            feet_px = detector.detect(camera, step, pose, rng).feet_px
            distance = np.full((visible.sum(), max(len(feet_px), 1)), np.inf)
            if len(feet_px):
                distance = np.linalg.norm(people.feet_px[visible, None] - feet_px[None], axis=-1)
            nearest = distance.argmin(axis=1)
            hit = distance[np.arange(len(nearest)), nearest] <= MATCH_FRACTION_OF_HEIGHT * people.height_px[visible]
            true_px = apply_homography(
                ground_to_image(model, pose), truth.positions_m[step, people.person_index[visible]]
            )
            heights.append(people.height_px[visible])
            found.append(hit)
            if len(feet_px):
                errors.append(feet_px[nearest[hit]] - true_px[hit])
    return DetectionTrials(
        np.concatenate(heights), np.concatenate(found), np.concatenate(errors) if errors else np.zeros((0, 2))
    )
