"""What a look that finds nobody, and a walkable area, say about where a track's person is.

A track not detected at a pose where the detector would have found its person with probability ``q``
loses existence by Bayes' rule (:mod:`ptztrack.track.lifecycle`); that is the miss's evidence about
*whether* the person is there. It is also evidence about *where*: given that the person exists, the
position's posterior is the prior times the probability of the miss,

    p(x | missed) ∝ N(x; m, P) (1 - q(x)),

mass taken from where the camera looked ("negative information", Koch 2007, "On exploiting 'negative'
sensor evidence for target tracking and sensor data fusion"). Without it the position stays where the
camera has just not found anybody, the next look goes there again, and each such look takes the
existence down as if it were new evidence, until a person merely looked for in the wrong place is
deleted. Here ``q(x)`` is ``q_in`` where the feet fall in the image and 0 elsewhere, with ``q_in``
such that its mean over the prior is the tracker's own ``q`` (so the two updates agree).

A walkable area that people never leave is the same kind of evidence, with ``1 - q(x)`` the area's
indicator (density truncation, Simon and Simon 2010, "Constrained Kalman filtering via density
function truncation for turbofan engine health estimation").

Either posterior is moment-matched to a Gaussian over the position, integrated on a fixed quasi-random
point set (:func:`unit_points`), and carried to the velocity through the prior's cross-covariance:
with ``K = P_{:,x} P_xx^-1`` (4, 2), ``m' = m + K (mu' - m_x)`` and ``P' = P + K (Sigma' - P_xx) K^T``,
the exact moments of a Gaussian prior whose position alone the evidence concerns.
"""

import functools

import numpy as np
from matplotlib.path import Path
from scipy.stats import norm, qmc

from ptztrack.geometry.ptz import PTZCamera, apply_homography, ground_to_image, inside_image


@functools.cache
def unit_points() -> np.ndarray:
    """The quadrature of the position's posterior moments (M, 2): 256 scrambled Sobol points in two
    dimensions mapped through the normal quantile, then centred and whitened, so that their mean is
    exactly 0 and their covariance exactly I (evidence that weighs every point alike leaves a track
    exactly as it was). The seed fixes the rule, not a draw of a run; made at its first use, not at
    import (a command's Ctrl-C under scipy's compiled code waits for it to return:
    :mod:`ptztrack.cli.interrupt`)."""
    points = norm.ppf(qmc.Sobol(d=2, scramble=True, seed=20071).random_base2(8))
    points -= points.mean(axis=0)
    factor = np.linalg.cholesky(np.cov(points.T, bias=True))
    return points @ np.linalg.inv(factor).T


# A track whose evidence weighs every point within this of 1 is left as it is.
UNCHANGED_WEIGHT = 1e-9


def position_points(mean, covariance) -> np.ndarray:
    """The quadrature points (n, M, 2) m of each track's position ``N(mean[:, :2], covariance[:, :2, :2])``
    (mean (n, 4), covariance (n, 4, 4))."""
    factor = np.linalg.cholesky(covariance[:, :2, :2])
    return mean[:, None, :2] + unit_points()[None] @ np.swapaxes(factor, -1, -2)


def moment_matched(mean, covariance, points, weights) -> tuple[np.ndarray, np.ndarray]:
    """The Gaussian moments of each track's posterior ``N(x; m, P) w(x)``, ``w`` given at the quadrature
    points.

    mean : (n, 4); covariance : (n, 4, 4); points : (n, M, 2) from :func:`position_points`; weights : (n, M)
    in [0, 1], with a positive sum per track. Returns the mean (n, 4) and covariance (n, 4, 4) (the
    module's docstring).

    The points resolve a spread no finer than one point's share of the prior: each eigenvalue of the
    position's covariance is at least ``lambda_min(P_xx) / M``, so that evidence leaving weight on one
    point, or on points in a line, still gives a positive definite covariance.
    """
    share = weights / weights.sum(axis=1, keepdims=True)
    position_mean = np.einsum("nm,nmi->ni", share, points)
    centred = points - position_mean[:, None, :]
    position_covariance = np.einsum("nm,nmi,nmj->nij", share, centred, centred)
    spread, axes = np.linalg.eigh(position_covariance)
    resolution = np.linalg.eigvalsh(covariance[:, :2, :2])[:, :1] / points.shape[1]
    unresolved = spread[:, 0] < resolution[:, 0]
    floored = np.maximum(spread[unresolved], resolution[unresolved])
    position_covariance[unresolved] = (axes[unresolved] * floored[:, None, :]) @ np.swapaxes(axes[unresolved], -1, -2)
    gain = covariance[:, :, :2] @ np.linalg.inv(covariance[:, :2, :2])
    mean = mean + np.einsum("nij,nj->ni", gain, position_mean - mean[:, :2])
    change = position_covariance - covariance[:, :2, :2]
    covariance = covariance + gain @ change @ np.swapaxes(gain, -1, -2)
    return mean, 0.5 * (covariance + np.swapaxes(covariance, -1, -2))


def _reweighted(mean, covariance, weights, points):
    """Each track moment-matched to its weights (n, M), those whose weights are all 1 left as they are."""
    changed = np.any(weights < 1.0 - UNCHANGED_WEIGHT, axis=1) & (weights.sum(axis=1) > 0)
    mean, covariance = mean.copy(), covariance.copy()
    if np.any(changed):
        mean[changed], covariance[changed] = moment_matched(
            mean[changed], covariance[changed], points[changed], weights[changed]
        )
    return mean, covariance


def after_miss(camera: PTZCamera, pose, mean, covariance, detectable) -> tuple[np.ndarray, np.ndarray]:
    """Each track's state after a look at ``pose`` that did not detect it (the module's docstring).

    mean : (n, 4); covariance : (n, 4, 4); detectable : (n,) the probability ``q`` that the detector would
    have found each person at ``pose``. The miss takes ``q_in = min(1, q / f)`` of the prior's mass where
    the feet fall in the image (a share ``f`` of the prior). Returns the mean (n, 4) and covariance
    (n, 4, 4).
    """
    if len(mean) == 0:
        return mean, covariance
    points = position_points(mean, covariance)
    H = ground_to_image(camera, pose)
    in_front = points @ H[2, :2] + H[2, 2] > 0
    with np.errstate(divide="ignore", invalid="ignore"):
        in_image = in_front & inside_image(camera, apply_homography(H, points))
    share_in_image = in_image.mean(axis=1)
    rate = np.minimum(1.0, np.divide(detectable, share_in_image, out=np.zeros(len(mean)), where=share_in_image > 0))
    return _reweighted(mean, covariance, 1.0 - rate[:, None] * in_image, points)


def within_area(mean, covariance, area_polygon_m) -> tuple[np.ndarray, np.ndarray]:
    """Each track's state truncated to the walkable area ``area_polygon_m`` (K, 2) m (the module's
    docstring); a track wholly outside it is left as it is. mean : (n, 4); covariance : (n, 4, 4)."""
    if len(mean) == 0:
        return mean, covariance
    points = position_points(mean, covariance)
    inside = Path(area_polygon_m).contains_points(points.reshape(-1, 2)).reshape(points.shape[:2])
    return _reweighted(mean, covariance, inside.astype(float), points)
