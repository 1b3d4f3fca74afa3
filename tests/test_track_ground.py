import dataclasses

import numpy as np
import pytest

from ptztrack.track.kalman import constant_velocity_model
from ptztrack.track.lifecycle import start_ground_tracks
from ptztrack.track.parameters import TrackerParameters
from ptztrack.track.tracker import predict_tracks, update_tracks_on_ground
from ptztrack.types import Tracks

PARAMETERS = TrackerParameters(report_position_sigma_m=2.0)
R = 0.01 * np.eye(2)
# The map finds a person who is there half the time: a miss takes existence r to r / (2 - r).
DETECTABLE = 0.5


def two_tracks() -> Tracks:
    return start_ground_tracks(np.array([[0.0, 0.0], [5.0, 0.0]]), np.stack([R, R]), 0.9, first_id=7)


def test_a_measurement_updates_the_track_it_gates_with_the_kalman_gain_of_its_covariance():
    tracks = two_tracks()
    update = update_tracks_on_ground(tracks, [[0.1, -0.05]], [R], PARAMETERS, DETECTABLE)
    updated = update.tracks
    # Equal position covariances: the update lands halfway, and the variance halves.
    np.testing.assert_allclose(updated.mean[0, :2], [0.05, -0.025])
    np.testing.assert_allclose(updated.covariance[0, :2, :2], R / 2)
    np.testing.assert_array_equal(update.track_ids, [7])
    np.testing.assert_array_equal(update.measurement_index, [0])
    assert updated.hits.tolist() == [2, 1]
    np.testing.assert_allclose(updated.existence, [0.99, 1 / 3])  # detected; missed at birth's 0.5


def test_a_measurement_outside_every_gate_starts_a_track_with_its_covariance():
    update = update_tracks_on_ground(two_tracks(), [[2.5, 3.0]], [2 * R], PARAMETERS, DETECTABLE)
    assert update.tracks.ids.tolist() == [7, 8, 9]
    np.testing.assert_allclose(update.tracks.mean[2], [2.5, 3.0, 0, 0])
    np.testing.assert_allclose(update.tracks.covariance[2, :2, :2], 2 * R)
    np.testing.assert_allclose(update.tracks.covariance[2, 2:, 2:], 0.81 * np.eye(2))
    assert update.track_ids.tolist() == [9] and update.measurement_index.tolist() == [0]


def test_each_measurement_goes_to_one_track_by_the_hungarian_assignment():
    tracks = start_ground_tracks(np.array([[0.0, 0.0], [0.3, 0.0]]), np.stack([R, R]) * 4, 0.9, first_id=0)
    update = update_tracks_on_ground(tracks, [[0.32, 0.0], [0.02, 0.0]], [R, R], PARAMETERS, DETECTABLE)
    assert dict(zip(update.track_ids.tolist(), update.measurement_index.tolist(), strict=True)) == {0: 1, 1: 0}


def test_tracks_without_measurements_lose_existence_by_bayes_rule_and_die_below_the_threshold():
    F, U = constant_velocity_model(0.1, 1.5)
    tracks = two_tracks()
    for existence in (1 / 3, 1 / 5, 1 / 9):  # r / (2 - r) from 0.5; 1 / 17 is below 0.1
        tracks = update_tracks_on_ground(
            predict_tracks(tracks, F, U), np.zeros((0, 2)), [], PARAMETERS, DETECTABLE
        ).tracks
        np.testing.assert_allclose(tracks.existence, [existence, existence])
    tracks = update_tracks_on_ground(predict_tracks(tracks, F, U), np.zeros((0, 2)), [], PARAMETERS, DETECTABLE).tracks
    assert len(tracks) == 0 and tracks.next_id == 9


def test_the_ground_path_follows_a_walker_from_noisy_positions():
    F, U = constant_velocity_model(0.1, 1.5)
    rng = np.random.default_rng(0)
    tracks = Tracks.empty()
    for step in range(30):
        truth = np.array([0.1 * step, 1.0])
        tracks = predict_tracks(tracks, F, U)
        measured = truth + rng.normal(0, 0.05, 2)
        tracks = update_tracks_on_ground(tracks, [measured], [0.0025 * np.eye(2)], PARAMETERS, DETECTABLE).tracks
    assert tracks.ids.tolist() == [0]
    np.testing.assert_allclose(tracks.mean[0, :2], [2.9, 1.0], atol=0.1)
    np.testing.assert_allclose(tracks.mean[0, 2:], [1.0, 0.0], atol=0.35)


def test_the_ground_path_refuses_the_cjpdaf():
    with pytest.raises(ValueError, match="Hungarian"):
        update_tracks_on_ground(
            two_tracks(), [[0.0, 0.0]], [R], dataclasses.replace(PARAMETERS, association="cjpdaf"), DETECTABLE
        )
