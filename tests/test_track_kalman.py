import numpy as np
import pytest

from ptztrack.track import kalman
from ptztrack.track.tracker import tracks_ahead
from ptztrack.types import Tracks


def test_predict_of_a_certain_state_is_the_process_noise():
    F, U = kalman.constant_velocity_model(0.2, 1.5)
    x, P = kalman.predict(np.array([[1.0, 2.0, 0.5, -1.0]]), np.zeros((1, 4, 4)), F, U)
    np.testing.assert_allclose(x, [[1.1, 1.8, 0.5, -1.0]])
    np.testing.assert_allclose(P[0], U)
    np.testing.assert_allclose(U[0, 0], 1.5**2 * 0.2**4 / 4)
    np.testing.assert_allclose(U[0, 2], 1.5**2 * 0.2**3 / 2)


def test_update_matches_the_scalar_closed_form():
    prior_var, obs_scale, noise_var = 0.7, 3.0, 2.0
    P = np.diag([prior_var, prior_var, 1.0, 1.0])[None]
    C = np.array([[[obs_scale, 0, 0, 0], [0, obs_scale, 0, 0]]], dtype=float)
    x, P_plus = kalman.update(np.zeros((1, 4)), P, np.array([[1.5, -0.5]]), C, noise_var * np.eye(2))
    gain = prior_var * obs_scale / (obs_scale**2 * prior_var + noise_var)
    np.testing.assert_allclose(x[0, :2], [gain * 1.5, gain * -0.5])
    np.testing.assert_allclose(P_plus[0, 0, 0], prior_var * noise_var / (noise_var + obs_scale**2 * prior_var))
    np.testing.assert_allclose(x[0, 2:], 0.0)


@pytest.mark.parametrize("acceleration_sigma, noise_sigma", [(1.5, 0.05), (0.5, 0.3), (3.0, 0.01)])
def test_steady_state_gain_is_the_alpha_beta_filter(acceleration_sigma, noise_sigma):
    """Bar-Shalom's closed form for the discrete white-noise acceleration model:
    tracking index lambda = sigma_a T^2 / sigma_w gives the steady-state alpha and beta."""
    dt = 0.2
    F, U = kalman.constant_velocity_model(dt, acceleration_sigma)
    C = np.array([[[1.0, 0, 0, 0], [0, 1.0, 0, 0]]])
    V = noise_sigma**2 * np.eye(2)
    x, P = np.zeros((1, 4)), np.eye(4)[None] * 10.0
    for _ in range(500):
        x, P = kalman.predict(x, P, F, U)
        S = kalman.innovation_covariance(P, C, V)
        gain = P @ np.swapaxes(C, -1, -2) @ np.linalg.inv(S)
        x, P = kalman.update(x, P, np.zeros((1, 2)), C, V)
    lam = acceleration_sigma * dt**2 / noise_sigma
    root = np.sqrt(lam**2 + 8 * lam)
    alpha = -(lam**2 + 8 * lam - (lam + 4) * root) / 8
    beta = (lam**2 + 4 * lam - lam * root) / 4
    np.testing.assert_allclose(gain[0, 0, 0], alpha, rtol=1e-9)
    np.testing.assert_allclose(gain[0, 2, 0] * dt, beta, rtol=1e-9)


def test_joseph_update_keeps_covariance_symmetric_positive_definite_under_huge_gain():
    P = np.diag([100.0, 100.0, 10.0, 10.0])[None]
    C = np.array([[[5000.0, 10.0, 0, 0], [-20.0, 4000.0, 0, 0]]])
    _, P_plus = kalman.update(np.zeros((1, 4)), P, np.ones((1, 2)), C, 0.25 * np.eye(2))
    np.testing.assert_allclose(P_plus, np.swapaxes(P_plus, -1, -2))
    assert np.all(np.linalg.eigvalsh(P_plus) > 0)


def test_tracks_ahead_walk_on_at_their_velocity_and_grow_as_white_acceleration_makes_them():
    """From a known state, after 0.5 s at 1.5 m/s^2: mean x + v t; position variance sigma^2 t^4 / 4,
    velocity variance sigma^2 t^2, their covariance sigma^2 t^3 / 2."""
    tracks = Tracks(np.array([7]), np.array([[1.0, 2.0, 1.0, -0.5]]), np.zeros((1, 4, 4)), np.ones(1), np.ones(1, int))
    ahead = tracks_ahead(tracks, 0.5, 1.5)
    np.testing.assert_allclose(ahead.mean, [[1.5, 1.75, 1.0, -0.5]])
    variance = 1.5**2 * np.array([[0.5**4 / 4, 0.5**3 / 2], [0.5**3 / 2, 0.5**2]])
    np.testing.assert_allclose(ahead.covariance[0][np.ix_([0, 2], [0, 2])], variance)
    np.testing.assert_allclose(ahead.covariance[0][0, 1], 0.0)
    assert ahead.ids[0] == 7 and np.array_equal(tracks.mean, [[1.0, 2.0, 1.0, -0.5]])


@pytest.mark.parametrize("velocity_time_constant_s", [0.5, 5.0])
def test_a_decaying_velocity_composes_over_time_and_carries_a_walker_tau_v_at_most(velocity_time_constant_s):
    """F(dt1) F(dt2) = F(dt1 + dt2); a walker at v for ever is predicted ``tau v`` on; an infinite time
    constant is the constant-velocity model."""
    F_short, _ = kalman.constant_velocity_model(0.2, 1.5, velocity_time_constant_s)
    F_long, _ = kalman.constant_velocity_model(0.6, 1.5, velocity_time_constant_s)
    np.testing.assert_allclose(F_short @ F_short @ F_short, F_long, atol=1e-12)
    F_ever, _ = kalman.constant_velocity_model(1e4, 1.5, velocity_time_constant_s)
    np.testing.assert_allclose(
        F_ever @ [1.0, 2.0, 1.2, -0.5],
        [1.0 + 1.2 * velocity_time_constant_s, 2.0 - 0.5 * velocity_time_constant_s, 0.0, 0.0],
        atol=1e-9,
    )
    for model in (kalman.constant_velocity_model(0.2, 1.5, np.inf), kalman.constant_velocity_model(0.2, 1.5)):
        np.testing.assert_array_equal(model[0], np.array([[1, 0, 0.2, 0], [0, 1, 0, 0.2], [0, 0, 1, 0], [0, 0, 0, 1]]))
