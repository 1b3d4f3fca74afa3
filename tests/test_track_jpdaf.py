from dataclasses import replace

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.stats import chi2, multivariate_normal

from ptztrack.track import jpdaf, kalman
from ptztrack.track.association import gated_innovations
from ptztrack.track.kalman import constant_velocity_model
from ptztrack.track.lifecycle import start_tracks
from ptztrack.track.observation import observation_matrix, predicted_feet_px
from ptztrack.track.tracker import predict_tracks, update_tracks
from ptztrack.types import Tracks
from test_track_tracker import (
    ACCELERATION_SIGMA_M_S2,
    CAMERA,
    POSE,
    V,
    assert_tracks_follow_walkers,
    feet_px,
    parameters,
)

CJPDAF = parameters(association="cjpdaf")
GATE = chi2.ppf(CJPDAF.gate_probability, df=2)


def step_inputs(mean, covariance, feet):
    """What update_tracks computes before associating: innovations, distances, gate, S and C."""
    predicted_px, in_front = predicted_feet_px(CAMERA, POSE, mean)
    C = observation_matrix(CAMERA, POSE, mean)
    S = kalman.innovation_covariance(covariance, C, V)
    innovation, distance2, allowed = gated_innovations(predicted_px, in_front, S, feet, CJPDAF.gate_probability)
    return innovation, distance2, allowed, S, C


def a_track(ground_xy=(7.0, 6.0), velocity=(0.8, -0.4)):
    """One predicted track: started at ``ground_xy`` with ``velocity`` and predicted one step."""
    F, U = constant_velocity_model(0.2, ACCELERATION_SIGMA_M_S2)
    tracks = start_tracks(feet_px([ground_xy]), CAMERA, POSE, V, CJPDAF.initial_speed_sigma_m_s, first_id=0)
    mean = tracks.mean.copy()
    mean[:, 2:] = velocity
    return kalman.predict(mean, tracks.covariance, F, U)


def pixel_space_betas(predicted_px, feet, clutter, sigma_px=2.0):
    """Betas of tracks predicted at ``predicted_px`` with isotropic innovation covariances."""
    predicted_px = np.asarray(predicted_px, dtype=float)
    S = np.broadcast_to(sigma_px**2 * np.eye(2), (len(predicted_px), 2, 2))
    in_front = np.ones(len(predicted_px), dtype=bool)
    _, distance2, allowed = gated_innovations(predicted_px, in_front, S, np.asarray(feet, float), 0.99)
    p = jpdaf.likelihoods(distance2, S, allowed)
    beta, beta_0 = jpdaf.association_probabilities(p, clutter)
    return p, beta, beta_0


def test_one_track_and_one_measurement_give_beta_p_over_p_plus_c():
    mean, covariance = a_track()
    feet = feet_px([[7.3, 6.1]])
    innovation, distance2, allowed, S, _ = step_inputs(mean, covariance, feet)
    assert allowed.all()
    p = jpdaf.likelihoods(distance2, S, allowed)
    predicted = predicted_feet_px(CAMERA, POSE, mean)[0][0]
    assert p[0, 0] == pytest.approx(multivariate_normal(predicted, S[0]).pdf(feet[0]), rel=1e-12)
    clutter = 0.3 * p[0, 0]
    beta, beta_0 = jpdaf.association_probabilities(p, clutter)
    assert beta[0, 0] == p[0, 0] / (p[0, 0] + clutter)
    assert beta_0[0] == pytest.approx(clutter / (p[0, 0] + clutter), rel=1e-12)


def test_as_c_goes_to_0_one_track_and_one_measurement_get_the_kalman_update():
    mean, covariance = a_track()
    feet = feet_px([[7.4, 5.8]])
    innovation, distance2, allowed, S, C = step_inputs(mean, covariance, feet)
    kalman_mean, kalman_covariance = kalman.update(mean, covariance, innovation[:, 0], C, V)
    deviations = []
    for clutter in (0.0, 1e-18, 1e-8, 1e-7, 1e-6):
        new_mean, new_covariance, detected = jpdaf.cjpdaf_step(
            mean, covariance, innovation, distance2, allowed, S, C, V, clutter
        )
        assert detected.all()
        deviations.append(np.abs(new_covariance - kalman_covariance).max())
        if clutter < 1e-15:
            np.testing.assert_allclose(new_mean, kalman_mean, rtol=0, atol=1e-12)
            np.testing.assert_allclose(new_covariance, kalman_covariance, rtol=0, atol=1e-12)
    # Away from 0 the update leaves the Kalman one in proportion to C (beta_0 = C / (p + C)).
    np.testing.assert_allclose(deviations[3] / deviations[2], 10.0, rtol=1e-3)
    np.testing.assert_allclose(deviations[4] / deviations[2], 100.0, rtol=1e-2)


def test_with_c_0_the_tracker_step_equals_the_hungarian_one_for_a_lone_person():
    F, U = constant_velocity_model(0.2, ACCELERATION_SIGMA_M_S2)
    hungarian = parameters()
    tracks = {"hungarian": None, "cjpdaf": None}
    for name, config in (("hungarian", hungarian), ("cjpdaf", replace(CJPDAF, clutter_density_per_px2=0))):
        state = Tracks.empty()
        for step in range(8):
            state = update_tracks(
                predict_tracks(state, F, U), feet_px([[5.0 + 0.2 * step, 6.0]]), CAMERA, POSE, V, config
            ).tracks
        tracks[name] = state
    np.testing.assert_array_equal(tracks["cjpdaf"].ids, tracks["hungarian"].ids)
    np.testing.assert_array_equal(tracks["cjpdaf"].hits, tracks["hungarian"].hits)
    np.testing.assert_allclose(tracks["cjpdaf"].mean, tracks["hungarian"].mean, rtol=0, atol=1e-12)
    np.testing.assert_allclose(tracks["cjpdaf"].covariance, tracks["hungarian"].covariance, rtol=0, atol=1e-12)


def test_two_tracks_equidistant_from_one_measurement_share_it_equally_and_each_gets_less_than_a_lone_track():
    clutter = 1e-3
    p, beta, beta_0 = pixel_space_betas([[100.0, 100.0], [110.0, 100.0]], [[105.0, 100.0]], clutter)
    assert beta[0, 0] == beta[1, 0] > 0
    _, lone_beta, _ = pixel_space_betas([[100.0, 100.0]], [[105.0, 100.0]], clutter)
    assert beta[0, 0] < lone_beta[0, 0]
    # Equation 6: S_k = p, S_i = 2p, so beta = p / (2p + C), against p / (p + C) alone.
    assert beta[0, 0] == pytest.approx(p[0, 0] / (2 * p[0, 0] + clutter), rel=1e-12)
    assert lone_beta[0, 0] == pytest.approx(p[0, 0] / (p[0, 0] + clutter), rel=1e-12)
    np.testing.assert_allclose(beta_0, 1 - beta[:, 0])


def test_a_measurement_where_two_gates_overlap_weighs_less_than_one_in_a_single_gate():
    # Gates of radius 2 px x 3.03 around x = 100 and x = 112; both measurements are 6 px from track 0,
    # the first also 6 px from track 1, the second 18 px from it.
    p, beta, _ = pixel_space_betas([[100.0, 100.0], [112.0, 100.0]], [[106.0, 100.0], [94.0, 100.0]], 1e-4)
    np.testing.assert_array_equal(p > 0, [[True, True], [True, False]])
    assert p[0, 0] == p[0, 1]
    assert beta[0, 0] < beta[0, 1]
    q = p[0, 0]
    assert beta[0, 0] == pytest.approx(q / (3 * q + 1e-4), rel=1e-12)
    assert beta[0, 1] == pytest.approx(q / (2 * q + 1e-4), rel=1e-12)


def test_no_measurement_in_the_gate_leaves_the_prediction_exactly():
    mean, covariance = a_track()
    innovation, distance2, allowed, S, C = step_inputs(mean, covariance, feet_px([[13.0, 11.0]]))
    assert not allowed.any()
    new_mean, new_covariance, detected = jpdaf.cjpdaf_step(
        mean, covariance, innovation, distance2, allowed, S, C, V, 1e-5
    )
    np.testing.assert_array_equal(new_mean, mean)
    np.testing.assert_array_equal(new_covariance, covariance)
    assert not detected.any()


def mixture_moments(mean, covariance, innovation, beta, beta_0, C):
    """Mean and covariance of the mixture {prediction: beta_0, Kalman update with measurement i: beta_i}, by a loop."""
    K = covariance @ C.T @ np.linalg.inv(C @ covariance @ C.T + V)
    posterior = (np.eye(4) - K @ C) @ covariance
    components = [(beta_0, mean, covariance)] + [
        (b, mean + K @ nu, posterior) for b, nu in zip(beta, innovation, strict=True)
    ]
    total = sum(weight for weight, _, _ in components)
    centre = sum(weight * m for weight, m, _ in components) / total
    spread = sum(weight * (P + np.outer(m - centre, m - centre)) for weight, m, P in components) / total
    return centre, spread


unit = st.floats(-1.0, 1.0)


@settings(max_examples=150, deadline=None)
@given(
    position=st.tuples(st.floats(4.0, 11.0), st.floats(3.0, 10.0)),
    velocity=st.tuples(st.floats(-1.5, 1.5), st.floats(-1.5, 1.5)),
    root=st.lists(st.floats(-0.4, 0.4), min_size=16, max_size=16),
    offsets=st.tuples(unit, unit, unit, unit),
    clutter_exponent=st.floats(-7.0, -3.0),
)
def test_the_pda_covariance_is_the_mixture_covariance_grows_with_a_second_measurement_and_stays_spd(
    position, velocity, root, offsets, clutter_exponent
):
    L = np.array(root).reshape(4, 4)
    covariance = (L @ L.T + 1e-3 * np.eye(4))[None]
    mean = np.array([[*position, *velocity]])
    predicted_px = predicted_feet_px(CAMERA, POSE, mean)[0]
    C = observation_matrix(CAMERA, POSE, mean)
    S = kalman.innovation_covariance(covariance, C, V)
    # Two measurements inside the gate: Mahalanobis radius at most 2.9 (9.21 is the 99 % gate's square).
    z = 2.9 * np.array(offsets).reshape(2, 2) / np.sqrt(2)
    feet = predicted_px[0] + z @ np.linalg.cholesky(S[0]).T
    innovation, distance2, allowed, _, _ = step_inputs(mean, covariance, feet)
    assert allowed.all()

    clutter = 10.0**clutter_exponent
    beta, beta_0 = jpdaf.association_probabilities(jpdaf.likelihoods(distance2, S, allowed), clutter)
    new_mean, two = jpdaf.pda_update(mean, covariance, innovation, beta, beta_0, C, V)
    centre, spread = mixture_moments(mean[0], covariance[0], innovation[0], beta[0], beta_0[0], C[0])
    scale = np.abs(covariance).max()
    np.testing.assert_allclose(new_mean[0], centre, rtol=0, atol=1e-9)
    np.testing.assert_allclose(two[0], spread, rtol=0, atol=1e-9 * scale)
    np.testing.assert_array_equal(two, np.swapaxes(two, -1, -2))
    assert np.linalg.eigvalsh(two[0])[0] > 0

    # With C -> 0 the second measurement adds the spread beta_1 beta_2 K d d^T K^T, d = nu_1 - nu_2, to P.
    beta, beta_0 = jpdaf.association_probabilities(jpdaf.likelihoods(distance2, S, allowed), 0.0)
    _, two = jpdaf.pda_update(mean, covariance, innovation, beta, beta_0, C, V)
    b1, b0 = jpdaf.association_probabilities(jpdaf.likelihoods(distance2[:, :1], S, allowed[:, :1]), 0.0)
    _, one = jpdaf.pda_update(mean, covariance, innovation[:, :1], b1, b0, C, V)
    K = kalman.gain(covariance, C, V)[0]
    d = K @ (innovation[0, 0] - innovation[0, 1])
    np.testing.assert_allclose(two[0] - one[0], beta[0, 0] * beta[0, 1] * np.outer(d, d), rtol=0, atol=1e-9 * scale)
    assert np.linalg.eigvalsh(two[0] - one[0])[0] > -1e-9 * scale
    # Equal measurements (d = 0) leave the traces equal, up to rounding.
    assert np.trace(two[0]) >= np.trace(one[0]) - 1e-12 * scale


def test_a_lone_measurement_in_two_gates_keeps_only_the_likelier_track_alive_and_starts_none():
    F, U = constant_velocity_model(0.2, ACCELERATION_SIGMA_M_S2)
    config = replace(CJPDAF, clutter_density_per_px2=1e-6)
    tracks = start_tracks(
        feet_px([[7.0, 6.0], [7.3, 6.0]]), CAMERA, POSE, V, config.initial_speed_sigma_m_s, first_id=0
    )
    # One measurement near both tracks, nearer track 0; another far from both. Track 1 counts as
    # missed, where it was detectable with probability 1/2: 0.5 * 0.5 / (1 - 0.25) = 1/3.
    updated = update_tracks(
        predict_tracks(tracks, F, U), feet_px([[7.1, 6.0], [12.0, 9.0]]), CAMERA, POSE, V, config, np.full(2, 0.5)
    ).tracks
    np.testing.assert_array_equal(updated.ids, [0, 1, 2])
    np.testing.assert_allclose(updated.existence, [0.99, 1 / 3, 0.5])
    np.testing.assert_array_equal(updated.hits, [2, 1, 1])
    # Both tracks moved part of the way towards the shared measurement.
    assert 7.0 < updated.mean[0, 0] < 7.1 < updated.mean[1, 0] < 7.3
    np.testing.assert_allclose(updated.mean[2, :2], [12.0, 9.0], atol=1e-9)


def test_two_people_each_detected_keep_both_tracks_alive_even_inside_each_others_gates():
    F, U = constant_velocity_model(0.2, ACCELERATION_SIGMA_M_S2)
    tracks = start_tracks(
        feet_px([[7.0, 6.0], [7.3, 6.0]]), CAMERA, POSE, V, CJPDAF.initial_speed_sigma_m_s, first_id=0
    )
    updated = update_tracks(
        predict_tracks(tracks, F, U), feet_px([[7.0, 6.0], [7.3, 6.0]]), CAMERA, POSE, V, CJPDAF
    ).tracks
    np.testing.assert_array_equal(updated.ids, [0, 1])
    np.testing.assert_array_equal(updated.existence, [0.99, 0.99])
    np.testing.assert_array_equal(updated.hits, [2, 2])


def test_a_measurement_only_in_the_gate_of_a_track_that_dies_starts_a_new_one():
    F, U = constant_velocity_model(0.2, ACCELERATION_SIGMA_M_S2)
    tracks = predict_tracks(
        start_tracks(feet_px([[7.5, 6.0]]), CAMERA, POSE, V, CJPDAF.initial_speed_sigma_m_s, first_id=0), F, U
    )
    feet = feet_px([[7.7, 6.1]])
    _, distance2, allowed, S, _ = step_inputs(tracks.mean, tracks.covariance, feet)
    p = jpdaf.likelihoods(distance2, S, allowed)[0, 0]
    assert p > 0
    # C = 3p: beta = 1/4, so the unconfirmed track misses and dies, and the measurement is nobody's.
    config = replace(CJPDAF, confirmation_hits=2, clutter_density_per_px2=3 * p)
    updated = update_tracks(tracks, feet, CAMERA, POSE, V, config).tracks
    np.testing.assert_array_equal(updated.ids, [1])
    np.testing.assert_allclose(updated.mean[0, :2], [7.7, 6.1], atol=1e-9)


def test_a_track_out_of_view_keeps_its_existence_and_one_missed_in_view_loses_it():
    F, U = constant_velocity_model(0.2, ACCELERATION_SIGMA_M_S2)
    tracks = start_tracks(feet_px([[7.5, 6.0]]), CAMERA, POSE, V, CJPDAF.initial_speed_sigma_m_s, first_id=0)
    looking_away = np.array([60.0, 40.0, 4.0])
    for _ in range(3):
        tracks = update_tracks(predict_tracks(tracks, F, U), np.zeros((0, 2)), CAMERA, looking_away, V, CJPDAF).tracks
    assert len(tracks) == 1 and tracks.existence[0] == 0.5
    lengths = []
    for _ in range(4):
        predicted = predict_tracks(tracks, F, U)
        detectable = np.where(predicted.ids == 0, 0.5, 1.0)
        tracks = update_tracks(predicted, feet_px([[2.0, 12.0]]), CAMERA, POSE, V, CJPDAF, detectable).tracks
        lengths.append(sorted(tracks.ids.tolist()))
    # Track 0, missed where it was detectable half the time: 0.5 -> 1/3 -> 1/5 -> 1/9 -> 1/17, deleted
    # below 0.1. The far detection starts a track of its own (it is in nobody's gate), then keeps it alive.
    assert lengths == [[0, 1], [0, 1], [0, 1], [1]]


@pytest.mark.parametrize("association", ["cjpdaf", "hungarian"])
def test_tracks_follow_two_crossing_walkers_and_keep_their_ids(association):
    # Both walkers reach (7.5, 6.5) at step 15, on paths crossing at right angles.
    start = np.array([[4.5, 3.5], [10.5, 3.5]])
    velocity = np.array([[1.0, 1.0], [-1.0, 1.0]])
    assert_tracks_follow_walkers(start, velocity, 31, parameters(association=association))
