"""Association of measurements with tracks: the chi-square gate on squared Mahalanobis distances and the
Hungarian assignment among the gated pairs (the tracker's default; :mod:`ptztrack.track.jpdaf` is the other)."""

import math

import numpy as np
from scipy.optimize import linear_sum_assignment
from scipy.stats import chi2, f


def gated_innovations(predicted_px, pairable, S, feet_px, gate_probability: float):
    """Innovations of every track w.r.t. every detection, and the chi-square gate.

    predicted_px : (n, 2) from :func:`~ptztrack.track.observation.predicted_feet_px`; pairable : (n,) the
    tracks a detection may be paired with (:func:`~ptztrack.track.observation.gate_in_front`);
    S : (n, 2, 2) innovation covariances; feet_px : (K, 2) detections.
    Returns the innovations (n, K, 2) ``feet - predicted``, their squared
    Mahalanobis distances (n, K), and which pairs are allowed (n, K): those
    within the chi-square quantile ``gate_probability`` (2 degrees of
    freedom) of pairable tracks.
    """
    residual = feet_px[None, :, :] - predicted_px[:, None, :]
    distance2 = np.einsum("tdi,tij,tdj->td", residual, np.linalg.inv(S), residual)
    allowed = pairable[:, None] & (distance2 <= chi2.ppf(gate_probability, df=2))
    return residual, distance2, allowed


def associate(predicted_px, pairable, S, feet_px, gate_probability: float) -> tuple[np.ndarray, np.ndarray]:
    """Hungarian assignment of detections to predicted tracks on the Mahalanobis distance.

    predicted_px : (n, 2) and pairable : (n,) as for :func:`gated_innovations`;
    S : (n, 2, 2) innovation covariances; feet_px : (K, 2) detections.
    Pairs whose squared Mahalanobis distance exceeds the chi-square quantile
    ``gate_probability`` (2 degrees of freedom) are not allowed, nor are
    tracks that are not pairable. Returns matched (track_index, detection_index) arrays.
    """
    if len(predicted_px) == 0 or len(feet_px) == 0:
        return np.zeros(0, dtype=int), np.zeros(0, dtype=int)
    _, distance2, allowed = gated_innovations(predicted_px, pairable, S, feet_px, gate_probability)
    return assign_gated(distance2, allowed, gate_probability)


def assign_gated(distance2, allowed, gate_probability: float) -> tuple[np.ndarray, np.ndarray]:
    """The Hungarian assignment on squared Mahalanobis distances (n, K) among the ``allowed`` (n, K)
    pairs; returns matched (track_index, measurement_index) arrays."""
    cost = np.where(allowed, distance2, chi2.ppf(gate_probability, df=2) * 1e3)
    rows, cols = linear_sum_assignment(cost)
    keep = allowed[rows, cols]
    return rows[keep], cols[keep]


def student_t_gate(gate_probability: float, noise_dof: float) -> float:
    """The chi-square gate probability (2 degrees of freedom) whose threshold holds ``gate_probability`` of a
    bivariate Student-t innovation of ``noise_dof`` degrees of freedom: its squared Mahalanobis distance
    ``d2`` has ``d2 / 2 ~ F(2, noise_dof)``, so the threshold is ``2 F^-1(gate_probability; 2, noise_dof)``;
    ``gate_probability`` itself for Gaussian noise (``noise_dof`` inf)."""
    if math.isinf(noise_dof):
        return gate_probability
    return float(chi2.cdf(2 * f.ppf(gate_probability, 2, noise_dof), df=2))
