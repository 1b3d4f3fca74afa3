"""Probability that a bivariate Gaussian falls in an axis-aligned rectangle, in closed form.

The bivariate normal CDF is written with Owen's T function (Owen 1956),

    Phi2(h, k; rho) = Phi(h)/2 + Phi(k)/2 - T(h, a_h) - T(k, a_k) - beta,
    a_h = (k - rho h) / (h sqrt(1 - rho^2)),  a_k = (h - rho k) / (k sqrt(1 - rho^2)),
    beta = 1/2 if h k < 0, else 0,

and the rectangle by inclusion-exclusion over its corners. ``T`` is SciPy's
compiled ``owens_t`` from ``scipy.special.cython_special``, bound for Numba
by its public name the way Numba documents
(``numba.extending.get_cython_function_address``); ``Phi(x) = erfc(-x /
sqrt(2)) / 2`` with the C library's ``erfc``, which Numba compiles (SciPy's
own ``ndtr`` is a fused function whose compiled symbol has no public
name). The information-gain reward evaluates this for every action and
track, and NumPy's per-call overhead on thousands of small arrays was ten
times the arithmetic.
``owens_t`` is the costly part, so it is evaluated only where it matters:
when the Gaussian lies well within one pair of edges (the marginal
probability along that axis is 1 to within 1e-12) the rectangle probability
is exactly the other axis's marginal, and a corner more than 8 standard
deviations out on either axis has a CDF equal, to 1e-15, to 0 or to a
univariate one.

``bivariate_normal_cdf`` and ``gaussian_rectangle_probability`` are NumPy
ufuncs (they broadcast); compiled code calls their ``*_scalar`` cores.
"""

import ctypes
import math

import numba
from numba.extending import get_cython_function_address

# Below this, a marginal probability counts as 0 or 1: the shortcut then
# errs by at most this much.
SHORTCUT_TOLERANCE = 1e-12
# Phi(-8) = 6e-16: beyond 8 standard deviations a corner is at infinity.
FAR_SIGMA = 8.0
SQRT_HALF = math.sqrt(0.5)

_owens_t = ctypes.CFUNCTYPE(ctypes.c_double, ctypes.c_double, ctypes.c_double)(
    get_cython_function_address("scipy.special.cython_special", "owens_t")
)


@numba.njit
def _ndtr(x):
    """The standard normal CDF."""
    return 0.5 * math.erfc(-x * SQRT_HALF)


@numba.njit
def bivariate_normal_cdf_scalar(h, k, rho):
    """P(X <= h, Y <= k) for standard normals with correlation ``rho``."""
    if h <= -FAR_SIGMA or k <= -FAR_SIGMA:
        return 0.0
    if h >= FAR_SIGMA:
        return _ndtr(k)
    if k >= FAR_SIGMA:
        return _ndtr(h)
    # Owen's formula divides by h and k: a zero is replaced by a value far
    # below the CDF's resolution, where T takes its limit.
    if h == 0.0:
        h = 1e-300
    if k == 0.0:
        k = 1e-300
    root = math.sqrt(max(1.0 - rho * rho, 1e-300))
    a_h = (k - rho * h) / (h * root)
    a_k = (h - rho * k) / (k * root)
    # Opposite signs; the product h * k could underflow to -0.0 and hide them.
    beta = 0.5 if (h < 0.0) != (k < 0.0) else 0.0
    value = 0.5 * _ndtr(h) + 0.5 * _ndtr(k) - _owens_t(h, a_h) - _owens_t(k, a_k) - beta
    return min(max(value, 0.0), 1.0)


@numba.njit
def _marginal(lower, upper):
    """Phi(upper) - Phi(lower), without calling Phi for bounds beyond FAR_SIGMA."""
    if lower <= -FAR_SIGMA and upper >= FAR_SIGMA:
        return 1.0
    return (1.0 if upper >= FAR_SIGMA else _ndtr(upper)) - (0.0 if lower <= -FAR_SIGMA else _ndtr(lower))


@numba.njit
def rectangle_probability_scalar(mean_u, mean_v, var_u, cov_uv, var_v, low_u, high_u, low_v, high_v):
    """P(low_u <= U <= high_u, low_v <= V <= high_v) for (U, V) Gaussian.

    Arguments are the means, variances and covariance of the Gaussian and
    the rectangle's bounds. An empty rectangle has probability 0.
    """
    sigma_u, sigma_v = math.sqrt(var_u), math.sqrt(var_v)
    lower_u = (low_u - mean_u) / sigma_u
    upper_u = (max(high_u, low_u) - mean_u) / sigma_u
    lower_v = (low_v - mean_v) / sigma_v
    upper_v = (max(high_v, low_v) - mean_v) / sigma_v
    if upper_u <= -FAR_SIGMA or lower_u >= FAR_SIGMA or upper_v <= -FAR_SIGMA or lower_v >= FAR_SIGMA:
        return 0.0
    marginal_u = _marginal(lower_u, upper_u)
    marginal_v = _marginal(lower_v, upper_v)
    if marginal_u >= 1.0 - SHORTCUT_TOLERANCE:
        return marginal_v
    if marginal_v >= 1.0 - SHORTCUT_TOLERANCE:
        return marginal_u
    if marginal_u <= SHORTCUT_TOLERANCE or marginal_v <= SHORTCUT_TOLERANCE:
        return 0.0
    rho = cov_uv / (sigma_u * sigma_v)
    value = (
        bivariate_normal_cdf_scalar(upper_u, upper_v, rho)
        - bivariate_normal_cdf_scalar(lower_u, upper_v, rho)
        - bivariate_normal_cdf_scalar(upper_u, lower_v, rho)
        + bivariate_normal_cdf_scalar(lower_u, lower_v, rho)
    )
    return min(max(value, 0.0), 1.0)


bivariate_normal_cdf = numba.vectorize(["float64(float64, float64, float64)"])(bivariate_normal_cdf_scalar)
bivariate_normal_cdf.__doc__ = bivariate_normal_cdf_scalar.__doc__
gaussian_rectangle_probability = numba.vectorize(["float64(" + ", ".join(["float64"] * 9) + ")"])(
    rectangle_probability_scalar
)
gaussian_rectangle_probability.__doc__ = rectangle_probability_scalar.__doc__
