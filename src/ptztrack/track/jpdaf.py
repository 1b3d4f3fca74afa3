"""Fitzgerald's Cheap JPDAF (CJPDA): soft data association for all tracks at once.

Lisanti, Del Bimbo and Pernici, "Scale invariant 3D multiple person tracking
with PTZ camera" (section 5, equation 6) associates track ``k`` with
measurement ``i`` with probability

    beta_ki = p_ki / (S_k + S_i - p_ki + C),

``p_ki = N(nu_ki; 0, S_k)`` the Gaussian likelihood of the innovation of
track ``k`` w.r.t. measurement ``i`` (0 outside the track's gate),
``S_k = sum_i p_ki``, ``S_i = sum_k p_ki`` and ``C`` a constant (the clutter
density, 1/px^2 like ``p``). A measurement inside one gate weighs heavily, one
where several gates overlap lightly. Each track then takes the probabilistic
data association (PDA) update with its betas: the combined innovation
``nu_k = sum_i beta_ki nu_ki`` moves the mean with the ordinary gain, and the
covariance mixes the prior (no measurement, ``beta_k0``), the updated one
and the spread of the innovations.

Every function works on all tracks x measurements at once: ``n`` tracks,
``m`` measurements; innovations (n, m, 2) in pixels.
"""

import numpy as np

from ptztrack.track import kalman

# A track counts a step as detected (a hit, and no missed step) when the
# measurements in its gate are more likely its own than not: sum_i beta_ki >
# 1/2, i.e. beta_k0 < 1/2. Since sum_k beta_ki <= 1 for every measurement,
# a lone measurement keeps at most one track alive, as the Hungarian assignment
# does, while it still updates every track whose gate it is in: two tracks
# on one person (JPDA's coalescence) do not both live on it, the less
# likely one runs out of missed steps. Two people crossing, both detected,
# give each track 2/3.
MIN_DETECTION_PROBABILITY = 0.5


def likelihoods(distance2, S, allowed) -> np.ndarray:
    """``p_ki`` (n, m) in 1/px^2: the 2-D Gaussian density of each innovation, 0 where not ``allowed``.

    distance2 : (n, m) squared Mahalanobis distances ``nu_ki^T S_k^-1 nu_ki``;
    S : (n, 2, 2) innovation covariances; allowed : (n, m) the gate.
    """
    normaliser = 2.0 * np.pi * np.sqrt(np.linalg.det(S))
    density = np.exp(-0.5 * distance2) / normaliser[:, None]
    return np.where(allowed, density, 0.0)


def association_probabilities(p, clutter_density_per_px2: float) -> tuple[np.ndarray, np.ndarray]:
    """Equation 6: ``beta`` (n, m) and ``beta_0`` (n,), the probability that no measurement is the track's.

    ``beta_k0 = 1 - sum_i beta_ki``, clipped at 0 (it cannot be negative:
    every denominator is at least ``S_k + C``). A pair with ``p_ki = 0`` has
    ``beta_ki = 0``, also when ``C = 0``.
    """
    p = np.asarray(p, dtype=float)
    denominator = p.sum(axis=1)[:, None] + p.sum(axis=0)[None, :] - p + clutter_density_per_px2
    beta = np.divide(p, denominator, out=np.zeros_like(p), where=p > 0)
    beta_0 = np.clip(1.0 - beta.sum(axis=1), 0.0, None)
    return beta, beta_0


def pda_update(mean, covariance, innovation, beta, beta_0, C, V) -> tuple[np.ndarray, np.ndarray]:
    """PDA update of every track with its association probabilities.

    mean (n, 4), covariance (n, 4, 4): the predicted states; innovation
    (n, m, 2): ``o_i - g(x_k-)``; beta (n, m), beta_0 (n,) from
    :func:`association_probabilities`; C (n, 2, 4), V (2, 2) as in
    :mod:`ptztrack.track.kalman`.

    ``x+ = x- + K nu_k`` and ``P+ = beta_k0 P- + (1 - beta_k0) P_c + K (sum_i
    beta_ki nu_ki nu_ki^T - nu_k nu_k^T) K^T`` with ``P_c`` the Joseph-form
    updated covariance. A track without a measurement in its gate keeps its
    prediction exactly.
    """
    mean_plus, covariance_plus = mean.copy(), covariance.copy()
    touched = beta.sum(axis=1) > 0
    beta, beta_0, mean, covariance, C = beta[touched], beta_0[touched], mean[touched], covariance[touched], C[touched]
    # Innovations of tracks behind the camera are meaningless (even infinite); their betas are 0.
    innovation = np.where(beta[..., None] > 0, innovation[touched], 0.0)
    combined = np.einsum("km,kmi->ki", beta, innovation)
    spread = np.einsum("km,kmi,kmj->kij", beta, innovation, innovation) - np.einsum("ki,kj->kij", combined, combined)
    mean_plus[touched], updated_covariance = kalman.update(mean, covariance, combined, C, V)
    K = kalman.gain(covariance, C, V)
    w0 = beta_0[:, None, None]
    mixed = w0 * covariance + (1.0 - w0) * updated_covariance + K @ spread @ np.swapaxes(K, -1, -2)
    covariance_plus[touched] = 0.5 * (mixed + np.swapaxes(mixed, -1, -2))
    return mean_plus, covariance_plus


def cjpdaf_step(mean, covariance, innovation, distance2, allowed, S, C, V, clutter_density_per_px2: float):
    """One CJPDAF update of all tracks with the gated measurements.

    Returns the updated mean (n, 4) and covariance (n, 4, 4), and whether each
    track counts the step as detected: the measurements in its gate explain it
    with probability ``sum_i beta_ki > MIN_DETECTION_PROBABILITY`` (n,).
    """
    beta, beta_0 = association_probabilities(likelihoods(distance2, S, allowed), clutter_density_per_px2)
    mean_plus, covariance_plus = pda_update(mean, covariance, innovation, beta, beta_0, C, V)
    return mean_plus, covariance_plus, beta.sum(axis=1) > MIN_DETECTION_PROBABILITY
