"""A track's birth and the Bayes update of its existence probability.

A new track stands at the ground point of a detection, with the detection's pixel noise carried to the
ground as its position covariance (m^2), or at a measured ground position with that measurement's
covariance; its velocity starts at 0. Its existence ``r``, the probability that its person is there,
follows Bayes' rule with ``q``, the probability that the detector would have found the person at the
pose: missed, ``r' = r (1 - q) / (1 - r q)``; detected with a detection of likelihood ``g`` (1/px^2)
against false detections of density ``kappa`` (1/px^2), ``r' = r (1 - q + q g / kappa) / (1 - r q +
r q g / kappa)``, at most a cap. The tracker (:mod:`ptztrack.track.tracker`) applies both every step.
"""

import numpy as np

from ptztrack.geometry.ptz import PTZCamera, feet_jacobian
from ptztrack.track.observation import ground_points
from ptztrack.types import Tracks


def start_tracks(
    feet_px, camera: PTZCamera, pose, V, initial_speed_sigma_m_s: float, first_id: int, existence: float = 0.5
) -> Tracks:
    """New tracks at the ground points of detections, with the pixel noise carried to the ground.

    Velocity starts at 0 with spread ``initial_speed_sigma_m_s`` per axis; the existence probability
    at ``existence``. Detections at or above the horizon cannot start a track and are dropped.
    """
    ground_xy, ok = ground_points(feet_px, camera, pose)
    ground_xy = ground_xy[ok]
    J_inv = np.linalg.inv(feet_jacobian(camera, pose, ground_xy))
    covariance_m2 = J_inv @ V @ np.swapaxes(J_inv, -1, -2)
    return start_ground_tracks(ground_xy, covariance_m2, initial_speed_sigma_m_s, first_id, existence)


def start_ground_tracks(
    position_m, covariance_m2, initial_speed_sigma_m_s: float, first_id: int, existence: float = 0.5
) -> Tracks:
    """New tracks at ground positions (K, 2) m with position covariances (K, 2, 2) m^2; velocity 0
    with spread ``initial_speed_sigma_m_s`` per axis; the existence probability at ``existence``."""
    count = len(position_m)
    covariance = np.zeros((count, 4, 4))
    covariance[:, :2, :2] = covariance_m2
    covariance[:, 2:, 2:] = initial_speed_sigma_m_s**2 * np.eye(2)
    return Tracks(
        ids=first_id + np.arange(count),
        mean=np.concatenate([np.reshape(position_m, (count, 2)), np.zeros((count, 2))], axis=-1),
        covariance=covariance,
        existence=np.full(count, existence),
        hits=np.ones(count, dtype=int),
        next_id=first_id + count,
    )


def existence_after_detection(existence, detectable, likelihood, clutter_density, cap: float) -> np.ndarray:
    """Bayes' rule for a detected track (the module's docstring): ``r (1 - q + q g / kappa) / (1 - r q +
    r q g / kappa)`` for existence ``r``, detection probability ``q`` and the detection's likelihood ``g``
    (all (n,)) against clutter of density ``kappa``, at most ``cap``; ``cap`` where ``kappa`` is 0."""
    r, q, g = (np.asarray(value, dtype=float) for value in (existence, detectable, likelihood))
    if clutter_density <= 0:
        return np.full(r.shape, cap)
    ratio = 1.0 - q + q * g / clutter_density
    return np.minimum(r * ratio / (1.0 - r + r * ratio), cap)


def existence_after_miss(existence, detectable) -> np.ndarray:
    """Bayes' rule for a track not detected: ``r (1 - q) / (1 - r q)`` for existence ``r`` and the
    probability ``q`` that the detector would have found the person were it there (both (n,))."""
    existence, detectable = np.asarray(existence, dtype=float), np.asarray(detectable, dtype=float)
    return existence * (1.0 - detectable) / (1.0 - existence * detectable)
