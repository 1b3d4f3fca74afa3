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


def associate(
    predicted_px, pairable, S, feet_px, gate_probability: float, cost: str = "mahalanobis"
) -> tuple[np.ndarray, np.ndarray]:
    """Hungarian assignment of detections to predicted tracks.

    predicted_px : (n, 2) and pairable : (n,) as for :func:`gated_innovations`;
    S : (n, 2, 2) innovation covariances; feet_px : (K, 2) detections.
    Pairs whose squared Mahalanobis distance exceeds the chi-square quantile
    ``gate_probability`` (2 degrees of freedom) are not allowed, nor are
    tracks that are not pairable. cost : 'mahalanobis', the squared Mahalanobis distance ``d2``, or
    'likelihood', the pair's negative log-likelihood ``d2 + log det S`` (up to a constant), under which
    an uncertain track, whose every detection is near, no longer outbids a sure one for its detection.
    Returns matched (track_index, detection_index) arrays.
    """
    if len(predicted_px) == 0 or len(feet_px) == 0:
        return np.zeros(0, dtype=int), np.zeros(0, dtype=int)
    _, distance2, allowed = gated_innovations(predicted_px, pairable, S, feet_px, gate_probability)
    if cost == "likelihood":
        distance2 = distance2 + np.linalg.slogdet(S)[1][:, None]
    return assign_gated(distance2, allowed)


def associate_on_ground(
    mean, covariance, position_m, covariance_m2, gate_probability: float, cost: str = "mahalanobis"
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Hungarian assignment of ground measurements to tracks.

    mean : (n, 4) and covariance : (n, 4, 4) the tracks; position_m : (K, 2) and covariance_m2 : (K, 2, 2) the
    measurements ``z = [I 0] x + r``, ``r ~ N(0, R_k)``. A pair's innovation covariance is ``P_xy + R_k``; pairs
    beyond the chi-square quantile ``gate_probability`` (2 degrees of freedom) of its squared Mahalanobis
    distance are not allowed; cost as :func:`associate`. Returns matched (track_index, measurement_index)
    and every pair's residual (n, K, 2) m.
    """
    residual = position_m[None, :, :] - mean[:, None, :2]
    S = covariance[:, None, :2, :2] + covariance_m2[None, :, :, :]
    distance2 = np.einsum("tki,tkij,tkj->tk", residual, np.linalg.inv(S), residual)
    allowed = distance2 <= chi2.ppf(gate_probability, df=2)
    if cost == "likelihood":
        distance2 = distance2 + np.linalg.slogdet(S)[1]
    track_index, measurement_index = assign_gated(distance2, allowed)
    return track_index, measurement_index, residual


def assign_gated(cost, allowed) -> tuple[np.ndarray, np.ndarray]:
    """The Hungarian assignment on the costs (n, K) among the ``allowed`` (n, K) pairs: as many pairs as
    can be allowed, at the least total cost among those; returns matched (track_index, measurement_index)
    arrays."""
    cost = np.asarray(cost, dtype=float)
    # A pair not allowed costs more than every allowed assignment together, so it is taken only where
    # no allowed pair is left, and then dropped.
    forbidden = (np.abs(cost[allowed]).sum() + 1.0) * 2.0 if np.any(allowed) else 1.0
    rows, cols = linear_sum_assignment(np.where(allowed, cost, forbidden))
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
