"""The feet-pixel noise the tracker assumes, and what it makes of an innovation.

A detection's feet pixel is the predicted one plus noise of scale ``V`` (2, 2) px^2, at least
``MIN_PIXEL_NOISE_PX`` per axis (:func:`pixel_noise_covariance`). An innovation ``nu = z - h(x-)``
(k, 2) px of covariance ``S = C P C^T + V`` (k, 2, 2) px^2 has the squared Mahalanobis distance
``d2 = nu^T S^-1 nu`` (:func:`squared_distances`). Gaussian noise (``noise_dof`` inf) gives it the density
``N(nu; 0, S)``; bivariate Student-t noise of ``noise_dof`` degrees of freedom its own density
(:func:`innovation_likelihood`) and a precision weight ``w = (noise_dof + 2) / (noise_dof + d2)``
(:func:`student_t_weight`), with which a detection updates its track under the noise ``V / w``
(:func:`student_t_noise`): a far detection moves its track less.
"""

import numpy as np

# Feet are found on a pixel grid: the tracker trusts them to half a pixel at
# best, which also keeps the innovation covariance invertible for a
# noiseless simulated detector.
MIN_PIXEL_NOISE_PX = 0.5


def pixel_noise_covariance(pixel_noise_px: float) -> np.ndarray:
    """``V`` (2, 2) px^2: the feet-pixel noise the tracker and the policies assume."""
    return max(pixel_noise_px, MIN_PIXEL_NOISE_PX) ** 2 * np.eye(2)


def innovation_likelihood(innovation, S, noise_dof: float = np.inf) -> np.ndarray:
    """The density of innovations (k, d) of covariances (k, d, d), in the inverse units of ``S``'s
    determinant's square root (1/px^2 for feet pixels); (k,). Gaussian, ``N(nu; 0, S)``, for ``noise_dof``
    inf; else the Student-t of scale ``S`` (d = 2 only): ``(1 + d2 / nu) ^ -(nu / 2 + 1) / (2 pi sqrt|S|)``,
    ``d2 = nu^T S^-1 nu``."""
    innovation, S = np.asarray(innovation, dtype=float), np.asarray(S, dtype=float)
    if len(innovation) == 0:
        return np.zeros(0)
    d2 = squared_distances(innovation, S)
    if np.isinf(noise_dof):
        return np.exp(-0.5 * d2) / np.sqrt(np.linalg.det(2 * np.pi * S))
    return (1 + d2 / noise_dof) ** -(noise_dof / 2 + 1) / np.sqrt(np.linalg.det(2 * np.pi * S))


def student_t_weight(d2, noise_dof: float) -> np.ndarray:
    """``w = (nu + 2) / (nu + d2)`` (k,): the expected precision scale of a detection whose innovation has
    the squared Mahalanobis distance ``d2`` (k,) under bivariate Student-t noise of ``noise_dof`` degrees of
    freedom (the variational Student-t filter's, Piche, Sarkka & Hartikainen, MLSP 2012, at the predicted
    state); 1 for Gaussian noise (``noise_dof`` inf)."""
    d2 = np.asarray(d2, dtype=float)
    if np.isinf(noise_dof):
        return np.ones_like(d2)
    return (noise_dof + 2) / (noise_dof + d2)


def squared_distances(innovation, S) -> np.ndarray:
    """``d2 = nu^T S^-1 nu`` (k,) of innovations (k, 2) of covariances (k, 2, 2)."""
    return np.einsum("ki,kij,kj->k", innovation, np.linalg.inv(S), innovation)


def student_t_noise(V, innovation, S, noise_dof: float) -> np.ndarray:
    """The noise each detection updates its track with under Student-t pixel noise of ``noise_dof`` degrees
    of freedom and scale ``V`` (2, 2) px^2: ``V / w`` (k, 2, 2), ``w`` the :func:`student_t_weight` of its
    innovation (k, 2) px of covariance ``S`` (k, 2, 2) px^2. A detection far from its track updates it less.
    ``V`` itself for Gaussian noise (``noise_dof`` inf)."""
    if np.isinf(noise_dof):
        return V
    return V / student_t_weight(squared_distances(innovation, S), noise_dof)[:, None, None]
