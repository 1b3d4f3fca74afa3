import math
from dataclasses import replace

import numpy as np
import pytest
from hypothesis import assume, given, settings
from hypothesis import strategies as st
from scipy.stats import chi2

from ptztrack.geometry.ptz import PTZCamera, apply_homography, feet_jacobian, ground_to_image, look_at
from ptztrack.track import kalman
from ptztrack.track.association import associate, student_t_gate
from ptztrack.track.evidence import birth_exposure
from ptztrack.track.kalman import constant_velocity_model
from ptztrack.track.lifecycle import existence_after_detection, existence_after_miss, start_ground_tracks, start_tracks
from ptztrack.track.observation import gate_in_front, observation_matrix
from ptztrack.track.parameters import TrackerParameters
from ptztrack.track.pixel_noise import innovation_likelihood, student_t_noise
from ptztrack.track.sensor_bias import PixelBias
from ptztrack.track.tracker import EkfTracker, predict_tracks, update_own_tracks, update_tracks
from ptztrack.types import Detections, Tracks

CAMERA = PTZCamera((7.5, -4.0, 7.0), 640, 480, 400.0)
POSE = look_at(CAMERA, [7.5, 6.0], 1.0)
V = 4.0 * np.eye(2)
ACCELERATION_SIGMA_M_S2 = TrackerParameters.acceleration_sigma_m_s2


def parameters(**fields) -> TrackerParameters:
    """The defaults with these fields, where people never leave (uncertainty deletes nobody) unless a
    ``max_position_sigma_m`` is given."""
    return replace(TrackerParameters(max_position_sigma_m=math.inf), **fields)


CONFIG = parameters()


def feet_px(ground_xy, pose=POSE):
    return apply_homography(ground_to_image(CAMERA, pose), np.asarray(ground_xy, dtype=float))


def test_observation_matrix_is_the_feet_jacobian_with_zero_velocity_columns():
    mean = np.array([[6.0, 5.0, 1.0, -1.0], [9.0, 8.0, 0.0, 0.5]])
    C = observation_matrix(CAMERA, POSE, mean)
    np.testing.assert_array_equal(C[:, :, 2:], 0.0)
    np.testing.assert_allclose(C[:, :, :2], feet_jacobian(CAMERA, POSE, mean[:, :2]))


def test_a_new_track_starts_at_the_ground_point_with_the_pixel_noise_carried_to_the_ground():
    ground = np.array([[5.0, 6.0], [10.0, 9.0]])
    tracks = start_tracks(feet_px(ground), CAMERA, POSE, V, CONFIG.initial_speed_sigma_m_s, first_id=7)
    np.testing.assert_allclose(tracks.mean[:, :2], ground, atol=1e-9)
    np.testing.assert_array_equal(tracks.ids, [7, 8])
    assert tracks.next_id == 9
    J = feet_jacobian(CAMERA, POSE, ground)
    np.testing.assert_allclose(J @ tracks.covariance[:, :2, :2] @ np.swapaxes(J, -1, -2), np.stack([V, V]), atol=1e-9)
    np.testing.assert_allclose(tracks.covariance[:, 2, 2], CONFIG.initial_speed_sigma_m_s**2)


def test_pixels_above_the_horizon_start_no_track():
    pose = np.array([0.0, 5.0, 1.0])
    tracks = start_tracks(
        np.array([[320.0, 10.0], [320.0, 400.0]]), CAMERA, pose, V, CONFIG.initial_speed_sigma_m_s, first_id=0
    )
    assert len(tracks) == 1


def assert_tracks_follow_walkers(start, velocity, steps: int, config: TrackerParameters) -> None:
    """Walkers from ``start`` (2, 2) at ``velocity`` (2, 2) m/s, detected every step: the tracks keep ids 0
    and 1 throughout and end on the walkers' positions and velocities."""
    dt = 0.2
    F, U = constant_velocity_model(dt, ACCELERATION_SIGMA_M_S2)
    tracks = Tracks.empty()
    for step in range(steps):
        truth = start + velocity * step * dt
        tracks = update_tracks(predict_tracks(tracks, F, U), feet_px(truth), CAMERA, POSE, V, config).tracks
        order = np.argsort(tracks.ids)
        np.testing.assert_array_equal(tracks.ids[order], [0, 1])
    np.testing.assert_allclose(tracks.mean[order, :2], truth, atol=0.02)
    np.testing.assert_allclose(tracks.mean[order, 2:], velocity, atol=0.05)


def test_tracks_follow_walkers_and_keep_their_ids():
    assert_tracks_follow_walkers(np.array([[4.0, 4.0], [11.0, 10.0]]), np.array([[1.0, 0.5], [-0.8, -0.6]]), 30, CONFIG)


def test_the_tracker_predicts_by_any_time_and_by_its_step_by_default():
    """Two predictions of 0.1 s move a walker as one of 0.2 s (its own step), and its spread grows with
    the time as the constant-velocity model's closed form says."""
    tracks = start_tracks(feet_px([[5.0, 5.0]]), CAMERA, POSE, V, CONFIG.initial_speed_sigma_m_s, first_id=0)
    tracks = replace(tracks, mean=np.array([[5.0, 5.0, 1.0, -0.5]]))
    halves = EkfTracker(CAMERA, 0.2, V, CONFIG, lambda *a: np.ones(len(a[0])), tracks)
    whole = EkfTracker(CAMERA, 0.2, V, CONFIG, lambda *a: np.ones(len(a[0])), tracks)
    halves.predict(0.1)
    halves.predict(0.1)
    whole.predict()
    np.testing.assert_allclose(halves.tracks.mean, whole.tracks.mean)
    np.testing.assert_allclose(whole.tracks.mean, [[5.2, 4.9, 1.0, -0.5]])
    F, U = constant_velocity_model(0.7, ACCELERATION_SIGMA_M_S2)
    later = EkfTracker(CAMERA, 0.2, V, CONFIG, lambda *a: np.ones(len(a[0])), tracks)
    np.testing.assert_allclose(later.predict(0.7).covariance[0], F @ tracks.covariance[0] @ F.T + U)


def test_two_misses_half_a_step_apart_weigh_as_one_miss_a_step_apart():
    """Pictures 0.1 s apart with a 0.2 s step are half a look each: two misses multiply the existence odds
    by (1 - q)^(1/2) twice, as one miss a step apart does by 1 - q; a first picture is a whole look."""
    q = 0.8
    tracks = replace(detected_track(CONFIG)[0], existence=np.array([0.9]))
    halves = EkfTracker(CAMERA, 0.2, V, CONFIG, lambda *a: np.full(len(a[0]), q), tracks)
    whole = EkfTracker(CAMERA, 0.2, V, CONFIG, lambda *a: np.full(len(a[0]), q), tracks)
    halves.unseen_s = whole.unseen_s = 0.0  # each camera's last picture was taken just now
    for tracker, dt_s in ((halves, 0.1), (halves, 0.1), (whole, 0.2)):
        tracker.predict(dt_s)
        tracker.update(Detections.empty(), POSE, None)
    odds = 0.9 / 0.1 * (1 - q)
    np.testing.assert_allclose(whole.tracks.existence, [odds / (1 + odds)])
    np.testing.assert_allclose(halves.tracks.existence, whole.tracks.existence)
    first = EkfTracker(CAMERA, 0.2, V, CONFIG, lambda *a: np.full(len(a[0]), q), tracks)
    first.update(Detections.empty(), POSE, None)
    np.testing.assert_allclose(first.tracks.existence, whole.tracks.existence)


def test_a_picture_a_fraction_of_a_step_after_the_last_is_measured_with_the_noise_over_that_fraction():
    """A detection 0.05 s after the camera's last picture, with a 0.2 s step, updates the track as
    :func:`update_tracks` does with 4 V; one a step or more after, with V."""
    tracks, _, _ = detected_track(CONFIG)
    seen = Detections(feet_px([[7.6, 6.1]]), np.array([100.0]), np.array([-1]))
    for dt_s, noise in ((0.05, 4.0 * V), (0.2, V), (0.5, V)):
        tracker = EkfTracker(CAMERA, 0.2, V, CONFIG, lambda *a: np.ones(len(a[0])), tracks)
        tracker.unseen_s = 0.0
        expected = update_tracks(tracker.predict(dt_s), seen.feet_px, CAMERA, POSE, noise, CONFIG, np.ones(1))
        tracker.update(seen, POSE, None)
        np.testing.assert_allclose(tracker.tracks.covariance, expected.tracks.covariance)
        np.testing.assert_allclose(tracker.tracks.mean, expected.tracks.mean)


def test_hungarian_assignment_ignores_detection_order_and_gates_outliers():
    F, U = constant_velocity_model(0.2, ACCELERATION_SIGMA_M_S2)
    tracks = start_tracks(
        feet_px([[5.0, 5.0], [9.0, 7.0]]), CAMERA, POSE, V, CONFIG.initial_speed_sigma_m_s, first_id=0
    )
    detections = feet_px([[9.0, 7.0], [14.0, 1.0], [5.0, 5.0]])
    updated = update_tracks(predict_tracks(tracks, F, U), detections, CAMERA, POSE, V, CONFIG).tracks
    np.testing.assert_array_equal(updated.ids, [0, 1, 2])
    np.testing.assert_allclose(updated.mean[:, :2], [[5.0, 5.0], [9.0, 7.0], [14.0, 1.0]], atol=1e-6)
    # The two detected tracks are as alive as detection makes them; the new one is a coin toss.
    np.testing.assert_array_equal(updated.existence, [0.99, 0.99, 0.5])


def test_a_miss_lowers_existence_by_bayes_rule_as_much_as_the_person_was_detectable():
    # r (1 - q) / (1 - r q): 0.99 * 0.1 / (1 - 0.891) for q = 0.9; unchanged for q = 0; 0 for q = 1.
    np.testing.assert_allclose(
        existence_after_miss([0.99, 0.99, 0.5, 0.5], [0.9, 0.0, 1.0, 0.5]), [0.099 / 0.109, 0.99, 0.0, 0.25 / 0.75]
    )


def detected_track(config):
    """One track at (7.5, 6) detected twice: existence ``existence_when_detected``."""
    F, U = constant_velocity_model(0.2, ACCELERATION_SIGMA_M_S2)
    tracks = start_tracks(feet_px([[7.5, 6.0]]), CAMERA, POSE, V, config.initial_speed_sigma_m_s, 0)
    return update_tracks(predict_tracks(tracks, F, U), feet_px([[7.5, 6.0]]), CAMERA, POSE, V, config).tracks, F, U


def test_a_person_out_of_view_is_never_forgotten_and_one_missed_in_view_soon_is():
    """Where people never leave, a track the camera does not look at lives on however uncertain it
    grows; missed where the detector would have found the person with probability 0.9, it goes at
    the third miss (0.99 -> 0.908 -> 0.497 -> 0.090, below 0.1)."""
    config = parameters()
    tracks, F, U = detected_track(config)
    looking_away = np.array([60.0, 40.0, 4.0])
    for _ in range(50):
        tracks = update_tracks(predict_tracks(tracks, F, U), np.zeros((0, 2)), CAMERA, looking_away, V, config).tracks
    assert len(tracks) == 1 and tracks.existence[0] == 0.99 and tracks.position_sigma_m[0] > 5.0
    tracks, F, U = detected_track(config)
    lengths = []
    for _ in range(3):
        predicted = predict_tracks(tracks, F, U)
        tracks = update_tracks(predicted, np.zeros((0, 2)), CAMERA, POSE, V, config, np.array([0.9])).tracks
        lengths.append(len(tracks))
    assert lengths == [1, 1, 0]


def test_uncertainty_deletes_a_track_only_below_a_finite_bound():
    leaving, staying = parameters(max_position_sigma_m=1.0), parameters()
    lifetimes = []
    for config in (leaving, staying):
        tracks, F, U = detected_track(config)
        looking_away = np.array([60.0, 40.0, 4.0])
        alive = 0
        while len(tracks) and alive < 30:
            predicted = predict_tracks(tracks, F, U)
            tracks = update_tracks(predicted, np.zeros((0, 2)), CAMERA, looking_away, V, config).tracks
            alive += len(tracks)
        lifetimes.append(alive)
    # position sd 0.9 m/s * t (the velocity's spread after two detections) passes 1 m after about a second
    assert 3 <= lifetimes[0] <= 7 and lifetimes[1] == 30


def test_with_confirmation_a_one_off_detection_is_never_reported_and_dies_at_its_first_miss():
    F, U = constant_velocity_model(0.2, ACCELERATION_SIGMA_M_S2)
    config = parameters(confirmation_hits=2)
    person, false_positive = [7.5, 6.0], [10.0, 9.0]
    tracks = update_tracks(Tracks.empty(), feet_px([person, false_positive]), CAMERA, POSE, V, config).tracks
    assert len(tracks) == 2 and len(tracks.confirmed(config.confirmation_hits)) == 0
    tracks = update_tracks(predict_tracks(tracks, F, U), feet_px([person]), CAMERA, POSE, V, config).tracks
    np.testing.assert_array_equal(tracks.ids, [0])
    np.testing.assert_array_equal(tracks.hits, [2])
    np.testing.assert_array_equal(tracks.confirmed(config.confirmation_hits).ids, [0])
    # Once detected twice, a track survives a miss where the detector would have found it nine times in ten.
    predicted = predict_tracks(tracks, F, U)
    tracks = update_tracks(predicted, np.zeros((0, 2)), CAMERA, POSE, V, config, np.array([0.9])).tracks
    np.testing.assert_array_equal(tracks.confirmed(config.confirmation_hits).ids, [0])


def test_a_track_measured_by_its_own_template_is_updated_without_becoming_more_or_less_alive():
    tracks = start_tracks(
        feet_px(np.array([[7.0, 6.0], [9.0, 7.0]])), CAMERA, POSE, V, CONFIG.initial_speed_sigma_m_s, 0
    )
    # track 1 missed where the detector would have found it half the time
    tracks = update_tracks(
        tracks, feet_px(np.array([[7.0, 6.0]])), CAMERA, POSE, V, CONFIG, np.array([1.0, 0.5])
    ).tracks
    moved = feet_px(np.array([[9.1, 7.0]]))
    updated = update_own_tracks(tracks, [1], moved, CAMERA, POSE, V, CONFIG.max_position_sigma_m)
    np.testing.assert_array_equal(updated.ids, tracks.ids)
    np.testing.assert_array_equal(updated.hits, tracks.hits)
    np.testing.assert_array_equal(updated.existence, tracks.existence)
    # Track 0 had no measurement; track 1 moved towards it, with the Kalman gain of its own covariance.
    np.testing.assert_array_equal(updated.mean[0], tracks.mean[0])
    C = observation_matrix(CAMERA, POSE, tracks.mean[1:])
    expected, expected_covariance = kalman.update(
        tracks.mean[1:], tracks.covariance[1:], moved - feet_px(tracks.mean[1:, :2]), C, V
    )
    np.testing.assert_allclose(updated.mean[1:], expected)
    np.testing.assert_allclose(updated.covariance[1:], expected_covariance)
    assert updated.mean[1, 0] > tracks.mean[1, 0]


def test_a_measurement_of_a_dead_track_is_refused():
    tracks = start_tracks(feet_px(np.array([[7.0, 6.0]])), CAMERA, POSE, V, CONFIG.initial_speed_sigma_m_s, 0)
    with pytest.raises(ValueError, match=r"measurements of tracks \[5\], which are not alive"):
        update_own_tracks(tracks, [5], feet_px(np.array([[7.0, 6.0]])), CAMERA, POSE, V, CONFIG.max_position_sigma_m)


def test_the_innovation_likelihood_is_the_gaussian_density():
    from scipy.stats import multivariate_normal

    S = np.array([[[4.0, 1.0], [1.0, 3.0]], [[9.0, 0.0], [0.0, 1.0]]])
    innovation = np.array([[1.0, -2.0], [3.0, 0.5]])
    expected = [multivariate_normal(np.zeros(2), S[k]).pdf(innovation[k]) for k in range(2)]
    np.testing.assert_allclose(innovation_likelihood(innovation, S), expected, rtol=1e-12)


def test_the_student_t_innovation_likelihood_is_scipys_density():
    from scipy.stats import multivariate_t

    S = np.array([[[4.0, 1.0], [1.0, 3.0]], [[9.0, 0.0], [0.0, 1.0]]])
    innovation = np.array([[1.0, -2.0], [30.0, 0.5]])
    expected = [multivariate_t(np.zeros(2), S[k], df=4).pdf(innovation[k]) for k in range(2)]
    np.testing.assert_allclose(innovation_likelihood(innovation, S, 4.0), expected, rtol=1e-12)


def test_the_student_t_gate_holds_its_probability_of_student_t_innovations():
    from scipy.stats import chi2, multivariate_t

    assert student_t_gate(0.99, math.inf) == 0.99
    innovation = multivariate_t(np.zeros(2), np.eye(2), df=4).rvs(400_000, random_state=np.random.default_rng(0))
    inside = np.mean(np.sum(innovation**2, axis=1) <= chi2.ppf(student_t_gate(0.99, 4.0), df=2))
    assert inside == pytest.approx(0.99, abs=0.001)


def test_a_far_detection_updates_by_the_student_t_weight():
    # d2 = 5^2 for an innovation of 5 sigma along x of S = I: the noise grows by (4 + 25) / (4 + 2).
    inflated = student_t_noise(V, np.array([[5.0, 0.0]]), np.eye(2)[None], 4.0)
    np.testing.assert_allclose(inflated, [V * 29 / 6])
    assert student_t_noise(V, np.array([[5.0, 0.0]]), np.eye(2)[None], math.inf) is V


def track_and_far_detection(config):
    """A sure track at (7.5, 6) and a detection 5 sigma of its innovation away, along the image's rows."""
    tracks, F, U = detected_track(config)
    predicted = predict_tracks(tracks, F, U)
    C = observation_matrix(CAMERA, POSE, predicted.mean)
    S = kalman.innovation_covariance(predicted.covariance, C, V)[0]
    return predicted, feet_px([[7.5, 6.0]]) + [5 * np.sqrt(S[0, 0]), 0.0], S


def test_student_t_noise_keeps_a_far_detection_on_its_track_and_moves_it_less():
    gaussian, student = parameters(), parameters(noise_dof=4.0)
    predicted, far, _ = track_and_far_detection(gaussian)
    # Gaussian noise: 5 sigma is outside the gate, so the detection starts a track of its own (and the
    # sure track, missed where it was surely detectable, goes).
    assert 0 not in update_tracks(predicted, far, CAMERA, POSE, V, gaussian).tracks.ids
    predicted, far, S = track_and_far_detection(student)
    updated = update_tracks(predicted, far, CAMERA, POSE, V, student).tracks
    np.testing.assert_array_equal(updated.ids, [0])
    C = observation_matrix(CAMERA, POSE, predicted.mean)
    innovation = far - feet_px(predicted.mean[:, :2])
    d2 = innovation[0] @ np.linalg.solve(S, innovation[0])
    expected, _ = kalman.update(predicted.mean, predicted.covariance, innovation, C, V * (4 + d2) / 6)
    np.testing.assert_allclose(updated.mean, expected)
    moved_gaussian, _ = kalman.update(predicted.mean, predicted.covariance, innovation, C, V)
    assert np.linalg.norm(updated.mean[0, :2] - predicted.mean[0, :2]) < np.linalg.norm(
        moved_gaussian[0, :2] - predicted.mean[0, :2]
    )


@pytest.mark.parametrize("birth, tracks_after", [("unassigned", 2), ("outside_gates", 1)])
def test_a_second_detection_in_a_tracks_gate_starts_a_track_only_when_births_are_unassigned(birth, tracks_after):
    config = parameters(birth=birth)
    tracks, F, U = detected_track(config)
    predicted = predict_tracks(tracks, F, U)
    detections = feet_px([[7.5, 6.0], [7.55, 6.0]])
    assert len(update_tracks(predicted, detections, CAMERA, POSE, V, config).tracks) == tracks_after


def test_the_birth_exposure_is_the_share_of_the_image_outside_every_surviving_tracks_gate():
    """With births only outside the gates, a detection at a point the exposure counts as gated starts no
    track and one it counts as open starts one; the exposure is the whole image without tracks, and for
    births wherever a detection is unassigned."""
    config = parameters(birth="outside_gates")
    tracks, F, U = detected_track(config)
    predicted = predict_tracks(tracks, F, U)
    # Not looked at: the track survives the step.
    update = update_tracks(predicted, np.zeros((0, 2)), CAMERA, POSE, V, config, detectable=np.zeros(1))
    exposure = birth_exposure(predicted, update, CAMERA, POSE, V, config)
    C = observation_matrix(CAMERA, POSE, predicted.mean)
    S = kalman.innovation_covariance(predicted.covariance, C, V)[0]
    gate_d2 = chi2.ppf(config.gate_probability, df=2)
    ellipse_px2 = math.pi * gate_d2 * math.sqrt(np.linalg.det(S))
    assert exposure == pytest.approx(1 - ellipse_px2 / (CAMERA.image_width_px * CAMERA.image_height_px), abs=2e-4)
    centre = feet_px(predicted.mean[:, :2])[0]
    # A Cholesky column of S is one Mahalanobis unit from the prediction.
    unit = np.linalg.cholesky(S)[:, 0]
    for scale, tracks_after in ((0.9, 1), (1.1, 2)):
        detection = centre + scale * math.sqrt(gate_d2) * unit
        after = update_tracks(predicted, detection[None], CAMERA, POSE, V, config, detectable=np.zeros(1))
        assert len(after.tracks) == tracks_after
    empty = update_tracks(Tracks.empty(), np.zeros((0, 2)), CAMERA, POSE, V, config)
    assert birth_exposure(Tracks.empty(), empty, CAMERA, POSE, V, config) == 1.0
    assert birth_exposure(predicted, update, CAMERA, POSE, V, parameters()) == 1.0


def test_a_camera_with_a_bias_learns_it_from_a_sure_track_and_takes_it_off_its_detections():
    config = parameters(noise_dof=4.0)
    tracks, F, U = detected_track(config)
    tracker = EkfTracker(CAMERA, 0.2, V, config, lambda mean, cov, pose: np.ones(len(mean)), tracks)
    tracker.bias = PixelBias.centred(V)
    predicted = tracker.predict()
    shift = np.array([3.0, -2.0])
    C = observation_matrix(CAMERA, POSE, predicted.mean)
    S = kalman.innovation_covariance(predicted.covariance, C, V)[0]
    innovation = feet_px(predicted.mean[:, :2])[0] + shift - feet_px(predicted.mean[:, :2])[0]
    weight = 6 / (4 + innovation @ np.linalg.solve(S, innovation))
    tracker.update(Detections(feet_px([[7.5, 6.0]]) + shift, np.array([80.0]), np.array([-1])), POSE, None)
    expected = np.linalg.solve(np.linalg.inv(V) + weight * np.linalg.inv(S), weight * np.linalg.solve(S, innovation))
    np.testing.assert_allclose(tracker.bias.estimate(), expected)
    # The next detection at the same place is taken as the shifted feet minus that bias.
    before = tracker.predict()
    corrected = feet_px([[7.5, 6.0]]) + shift - expected
    tracker.update(Detections(feet_px([[7.5, 6.0]]) + shift, np.array([80.0]), np.array([-1])), POSE, None)
    alone = update_tracks(before, corrected, CAMERA, POSE, V, config)
    np.testing.assert_allclose(tracker.tracks.mean, alone.tracks.mean)


def test_a_detection_raises_existence_by_its_likelihood_against_the_clutter():
    # Worked by hand: ratio 1 - q + q g / kappa = 0.2 + 0.8 x 40 = 32.2; r' = 0.5 x 32.2 / (0.5 + 16.1).
    assert existence_after_detection([0.5], [0.8], [0.04], 0.001, 0.99)[0] == pytest.approx(16.1 / 16.6)
    # A detection that is likelier clutter than this person lowers the existence.
    assert existence_after_detection([0.5], [0.8], [1e-5], 0.001, 0.99)[0] == pytest.approx(0.104 / 0.604)
    # Never above the cap; with no clutter at all, the cap.
    assert existence_after_detection([0.98], [1.0], [1.0], 1e-9, 0.99)[0] == 0.99
    assert existence_after_detection([0.3], [0.5], [0.01], 0.0, 0.99)[0] == 0.99
    # Where the detector could not have found the person (q = 0) the detection says nothing.
    assert existence_after_detection([0.3], [0.0], [0.04], 0.001, 0.99)[0] == pytest.approx(0.3)


def test_the_tracker_reports_only_tracks_sure_enough_to_exist():
    fields = {"existence_at_birth": 0.4, "existence_to_report": 0.5}
    params = parameters(**fields)
    start = feet_px([[7.5, 6.0]])
    first = update_tracks(Tracks.empty(), start, CAMERA, POSE, V, params, np.zeros(0)).tracks
    assert first.existence[0] == pytest.approx(0.4)
    tracker = EkfTracker(CAMERA, 0.2, V, params, lambda *a: np.ones(len(a[0])))
    tracker.tracks = first
    assert len(tracker.reported()) == 0
    fixed = EkfTracker(
        CAMERA,
        0.2,
        V,
        parameters(**fields, existence_update="fixed"),
        lambda *a: np.ones(len(a[0])),
    )
    fixed.tracks = first
    assert len(fixed.reported()) == 1
    tracker.predict()
    tracker.update(Detections(start, np.array([np.nan]), np.array([-1])), POSE, None)
    assert len(tracker.reported()) == 1 and tracker.tracks.existence[0] == pytest.approx(0.99)


@settings(max_examples=60, deadline=None)
@given(
    x_m=st.floats(-20.0, 35.0),
    y_m=st.floats(-12.0, 30.0),
    sigma_x_m=st.floats(0.05, 20.0),
    sigma_y_m=st.floats(0.05, 20.0),
    rho=st.floats(-0.95, 0.95),
    pan_deg=st.floats(-90.0, 90.0),
    gate_probability=st.floats(0.5, 0.999),
)
def test_a_gate_lies_in_front_exactly_when_every_point_of_its_ellipse_does(
    x_m, y_m, sigma_x_m, sigma_y_m, rho, pan_deg, gate_probability
):
    """The depth along the optical axis over the gate's ellipse, sampled on its boundary, has its least
    value where :func:`gate_in_front` puts it, so the gate is in front exactly when the whole ellipse is."""
    pose = POSE + np.array([pan_deg, 0.0, 0.0])
    covariance = np.zeros((1, 4, 4))
    covariance[0, :2, :2] = [
        [sigma_x_m**2, rho * sigma_x_m * sigma_y_m],
        [rho * sigma_x_m * sigma_y_m, sigma_y_m**2],
    ]
    mean = np.array([[x_m, y_m, 0.0, 0.0]])
    angle = np.linspace(0.0, 2 * np.pi, 4001)
    boundary = (
        mean[0, :2]
        + math.sqrt(chi2.ppf(gate_probability, df=2))
        * (np.linalg.cholesky(covariance[0, :2, :2]) @ np.stack([np.cos(angle), np.sin(angle)])).T
    )
    h = ground_to_image(CAMERA, pose)[2]
    least_depth = np.min(boundary @ h[:2] + h[2])
    assume(abs(least_depth) > 1e-3 * np.linalg.norm(h[:2]) * max(sigma_x_m, sigma_y_m))
    assert gate_in_front(CAMERA, pose, mean, covariance, gate_probability)[0] == (least_depth > 0)


@pytest.mark.parametrize("sigma_m, paired", [(2.0, True), (15.0, False)])
def test_a_detection_is_paired_only_with_a_track_whose_gate_lies_in_front_of_the_camera(sigma_m, paired):
    """A track 10 m in front of the camera, 15 m uncertain: its gate reaches behind the camera, its feet
    pixel's linearised innovation covariance is huge, and the pixel gate would hold a detection 20 px
    from its predicted feet; that detection starts a track of its own and leaves the uncertain one as
    it was (the detector is taken not to have seen it, so that it survives the step). The same track 2 m
    uncertain is updated by it."""
    tracks = start_ground_tracks(np.array([[7.5, 6.0]]), sigma_m**2 * np.eye(2)[None], 0.9, first_id=0)
    detection = feet_px([[7.5, 6.0]]) + [[20.0, 0.0]]
    C = observation_matrix(CAMERA, POSE, tracks.mean)
    S = kalman.innovation_covariance(tracks.covariance, C, V)[0]
    innovation = detection[0] - feet_px([[7.5, 6.0]])[0]
    assert innovation @ np.linalg.solve(S, innovation) < chi2.ppf(CONFIG.gate_probability, df=2)
    assert gate_in_front(CAMERA, POSE, tracks.mean, tracks.covariance, CONFIG.gate_probability)[0] == paired
    updated = update_tracks(tracks, detection, CAMERA, POSE, V, CONFIG, detectable=np.zeros(1)).tracks
    assert len(updated) == (1 if paired else 2)
    if not paired:
        np.testing.assert_array_equal(updated.covariance[0], tracks.covariance[0])
        np.testing.assert_array_equal(updated.mean[0], tracks.mean[0])


def test_the_likelihood_cost_gives_a_detection_to_the_sure_track_and_the_mahalanobis_cost_to_the_uncertain():
    """A detection 4 px from a sure track (S = 4 I px^2) and 26 px from an uncertain one (S = 2500 I): squared
    Mahalanobis distances 4 and 0.27, negative log-likelihoods 4 + log 16 = 6.8 and 0.27 + log 2500^2 = 15.9."""
    predicted_px = np.array([[300.0, 240.0], [330.0, 240.0]])
    S = np.stack([4.0 * np.eye(2), 2500.0 * np.eye(2)])
    detection_px = np.array([[304.0, 240.0]])
    pairable = np.array([True, True])
    by_distance = associate(predicted_px, pairable, S, detection_px, 0.99, "mahalanobis")
    by_likelihood = associate(predicted_px, pairable, S, detection_px, 0.99, "likelihood")
    assert by_distance[0].tolist() == [1] and by_likelihood[0].tolist() == [0]
