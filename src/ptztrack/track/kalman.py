"""Kalman filter steps for a batch of constant-velocity ground-plane states.

State ``x = [x_m, y_m, vx_m_s, vy_m_s]``; every function takes a batch of
``n`` filters: ``x`` (n, 4), ``P`` (n, 4, 4). Matrices are named as in the
paper's equations (2): ``F``, ``U`` (process noise), ``C`` (linearised
observation), ``V`` (observation noise). The paper prints
``P- = F^T P F + U``; the standard and intended form is ``F P F^T + U``.
"""

import math

import numpy as np


def constant_velocity_model(
    dt_s: float, acceleration_sigma_m_s2: float, velocity_time_constant_s: float = math.inf
) -> tuple[np.ndarray, np.ndarray]:
    """``F`` and ``U`` (4, 4) for a walker driven by white acceleration noise, its velocity constant or,
    with a finite ``velocity_time_constant_s`` ``tau``, decaying towards 0: ``v' = e^(-dt/tau) v``,
    ``x' = x + tau (1 - e^(-dt/tau)) v`` (an integrated Ornstein-Uhlenbeck velocity, the Singer model's
    mean), so that a walker unseen for long is predicted to have gone ``tau v`` at most, not on at ``v``
    for ever. ``U`` is the constant-velocity model's either way."""
    F = np.eye(4)
    if math.isinf(velocity_time_constant_s):
        F[0, 2] = F[1, 3] = dt_s
    else:
        decay = math.exp(-dt_s / velocity_time_constant_s)
        F[0, 2] = F[1, 3] = velocity_time_constant_s * (1.0 - decay)
        F[2, 2] = F[3, 3] = decay
    block = acceleration_sigma_m_s2**2 * np.array([[dt_s**4 / 4, dt_s**3 / 2], [dt_s**3 / 2, dt_s**2]])
    U = np.kron(block, np.eye(2))
    return F, U


def predict(x, P, F, U) -> tuple[np.ndarray, np.ndarray]:
    """``x- = F x``, ``P- = F P F^T + U``."""
    return x @ F.T, F @ P @ F.T + U


def innovation_covariance(P, C, V) -> np.ndarray:
    """``S = C P C^T + V``; C (n, 2, 4), returns (n, 2, 2)."""
    return C @ P @ np.swapaxes(C, -1, -2) + V


def gain(P, C, V) -> np.ndarray:
    """Kalman gain ``K = P C^T S^-1`` (n, 4, 2), solved without inverting ``S``."""
    S = innovation_covariance(P, C, V)
    return np.swapaxes(np.linalg.solve(S, C @ P), -1, -2)


def update_position(x, P, innovation, R) -> tuple[np.ndarray, np.ndarray]:
    """:func:`update` with a measurement of the position, ``z = [I 0] x + r``: innovation (n, 2) m, R (n, 2, 2)
    m^2."""
    return update(x, P, innovation, np.broadcast_to(np.eye(2, x.shape[-1]), (*x.shape[:-1], 2, x.shape[-1])), R)


def update(x, P, innovation, C, V) -> tuple[np.ndarray, np.ndarray]:
    """EKF update with the innovation ``o - g(x-)`` (n, 2) and ``C = dg/dx`` at ``x-``.

    Uses the Joseph form of ``P+ = (I - K C) P-`` so that P stays symmetric
    positive definite when the gain is large (zoomed-in views).
    """
    K = gain(P, C, V)
    x_plus = x + (K @ innovation[..., None])[..., 0]
    I_KC = np.eye(x.shape[-1]) - K @ C
    P_plus = I_KC @ P @ np.swapaxes(I_KC, -1, -2) + K @ V @ np.swapaxes(K, -1, -2)
    return x_plus, P_plus
