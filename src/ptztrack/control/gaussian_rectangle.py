"""Probability that a bivariate Gaussian falls in an axis-aligned rectangle, in closed form.

The bivariate normal CDF is written with Owen's T function (Owen 1956),

    Phi2(h, k; rho) = Phi(h)/2 + Phi(k)/2 - T(h, a_h) - T(k, a_k) - beta,
    a_h = (k - rho h) / (h sqrt(1 - rho^2)),  a_k = (h - rho k) / (k sqrt(1 - rho^2)),
    beta = 1/2 if h k < 0, or h k = 0 and h + k < 0; else 0,

and the rectangle by inclusion-exclusion over its corners. ``owens_t`` is the
costly part (about 130 ns a value), so it is evaluated only where the
Gaussian straddles a corner: when it lies well within one pair of edges (the
marginal probability along that axis is 1 to within 1e-12) the rectangle
probability is exactly the other axis's marginal.
"""

import numpy as np
from scipy.special import ndtr, owens_t

# Below this, a marginal probability counts as 0 or 1: the shortcut then
# errs by at most this much.
SHORTCUT_TOLERANCE = 1e-12


def bivariate_normal_cdf(h, k, rho) -> np.ndarray:
    """P(X <= h, Y <= k) for standard normals with correlation ``rho`` (broadcasts)."""
    h, k, rho = np.broadcast_arrays(*(np.asarray(a, dtype=float) for a in (h, k, rho)))
    # Owen's formula divides by h and k: a zero is replaced by a value far
    # below the CDF's resolution, where T takes its limit.
    h = np.where(h == 0, 1e-300, h)
    k = np.where(k == 0, 1e-300, k)
    root = np.sqrt(np.maximum(1.0 - rho**2, 1e-300))
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        a_h = (k - rho * h) / (h * root)
        a_k = (h - rho * k) / (k * root)
    beta = np.where(h * k < 0, 0.5, 0.0)
    value = 0.5 * ndtr(h) + 0.5 * ndtr(k) - owens_t(h, a_h) - owens_t(k, a_k) - beta
    return np.clip(value, 0.0, 1.0)


def gaussian_rectangle_probability(mean, cov, low, high) -> np.ndarray:
    """P(low <= X <= high) for X ~ N(mean, cov) in 2-D.

    mean, low, high : (..., 2); cov : (..., 2, 2). Empty rectangles
    (high < low on an axis) have probability 0. Returns (...).
    """
    mean, low, high = (np.asarray(a, dtype=float) for a in (mean, low, high))
    cov = np.asarray(cov, dtype=float)
    sigma = np.sqrt(np.stack([cov[..., 0, 0], cov[..., 1, 1]], axis=-1))
    rho = cov[..., 0, 1] / (sigma[..., 0] * sigma[..., 1])
    high = np.maximum(high, low)
    lower = (low - mean) / sigma
    upper = (high - mean) / sigma
    marginal = ndtr(upper) - ndtr(lower)
    inside = marginal >= 1.0 - SHORTCUT_TOLERANCE
    probability = np.where(inside[..., 0], marginal[..., 1], np.where(inside[..., 1], marginal[..., 0], 0.0))
    corner = ~inside[..., 0] & ~inside[..., 1] & np.all(marginal > SHORTCUT_TOLERANCE, axis=-1)
    if np.any(corner):
        lo, hi, r = lower[corner], upper[corner], rho[corner]
        probability[corner] = np.clip(
            bivariate_normal_cdf(hi[:, 0], hi[:, 1], r)
            - bivariate_normal_cdf(lo[:, 0], hi[:, 1], r)
            - bivariate_normal_cdf(hi[:, 0], lo[:, 1], r)
            + bivariate_normal_cdf(lo[:, 0], lo[:, 1], r),
            0.0,
            1.0,
        )
    return probability
