import numpy as np

from ptztrack.track.sensor_bias import PixelBias

PRIOR = 4.0 * np.eye(2)


def test_one_detection_gives_the_gaussian_posterior_mean():
    bias = PixelBias.centred(PRIOR)
    S = np.array([[2.0, 0.5], [0.5, 1.0]])
    innovation = np.array([3.0, -1.0])
    bias.observe(innovation[None], S[None], np.array([0.5]))
    # b = (V0^-1 + w S^-1)^-1 w S^-1 nu
    information = np.linalg.inv(PRIOR) + 0.5 * np.linalg.inv(S)
    expected = np.linalg.solve(information, 0.5 * np.linalg.solve(S, innovation))
    np.testing.assert_allclose(bias.estimate(), expected)


def test_no_detection_leaves_no_bias():
    bias = PixelBias.centred(PRIOR)
    bias.observe(np.zeros((0, 2)), np.zeros((0, 2, 2)), np.zeros(0))
    np.testing.assert_array_equal(bias.estimate(), [0.0, 0.0])


def test_a_constant_bias_is_found_among_noisy_innovations():
    rng = np.random.default_rng(2)
    true_bias = np.array([1.5, -0.7])
    S = np.array([[5.0, 1.0], [1.0, 3.0]])
    bias = PixelBias.centred(PRIOR)
    for _ in range(1000):
        innovation = true_bias + rng.multivariate_normal(np.zeros(2), S, size=4)
        bias.observe(innovation, np.broadcast_to(S, (4, 2, 2)), np.ones(4))
    np.testing.assert_allclose(bias.estimate(), true_bias, atol=0.12)
