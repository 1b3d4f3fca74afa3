import numpy as np
import pytest
from scipy.stats import chi2

from ptztrack.track.adaptive_noise import AdaptiveNoise, gate_second_moment


def test_the_gate_correction_is_the_truncated_gaussians_second_moment():
    rng = np.random.default_rng(0)
    w = rng.standard_normal((400_000, 2))
    inside = np.sum(w**2, axis=1) <= chi2.ppf(0.9, df=2)
    np.testing.assert_allclose(np.mean(w[inside] ** 2), gate_second_moment(0.9), rtol=0.01)


def simulated_noise(true_V, prior_V, spread_px2, steps=400, per_step=5, seed=1):
    """A camera's noise learned from innovations of covariance ``spread + true_V`` kept to their gate."""
    rng = np.random.default_rng(seed)
    noise = AdaptiveNoise(prior_V, 1.0, 0.99)
    threshold = chi2.ppf(0.99, df=2)
    for _ in range(steps):
        S_true = spread_px2 + true_V
        innovation = rng.multivariate_normal(np.zeros(2), S_true, size=per_step)
        S_model = spread_px2 + noise.covariance()
        gated = np.einsum("ki,ij,kj->k", innovation, np.linalg.inv(S_model), innovation) <= threshold
        noise.observe(innovation[gated], np.broadcast_to(spread_px2, (int(gated.sum()), 2, 2)))
    return noise.covariance()


@pytest.mark.parametrize("true_sd_px", [3.0, 6.0])
def test_a_noise_wider_than_the_prior_is_learned_through_the_gate(true_sd_px):
    true_V = np.diag([true_sd_px**2, (true_sd_px / 2) ** 2])
    learned = simulated_noise(true_V, 4.0 * np.eye(2), 0.5 * np.eye(2))
    np.testing.assert_allclose(np.diag(learned), np.maximum(np.diag(true_V), 4.0), rtol=0.15)


def test_the_noise_never_falls_below_the_prior():
    learned = simulated_noise(0.25 * np.eye(2), 4.0 * np.eye(2), 0.5 * np.eye(2))
    np.testing.assert_allclose(learned, 4.0 * np.eye(2))


def test_a_track_the_camera_barely_constrains_leaves_the_noise_as_it_was():
    noise = AdaptiveNoise(4.0 * np.eye(2), 1.0, 0.99)
    noise.observe(np.array([[300.0, -200.0]]), np.array([1e6 * np.eye(2)]))
    np.testing.assert_allclose(noise.covariance(), 4.0 * np.eye(2), rtol=1e-3)
