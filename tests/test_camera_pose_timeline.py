"""A live camera's pose at any moment, from its GetStatus samples and its move-time model, and its
newest picture handed between threads."""

import threading

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from ptztrack.camera.onvif_spaces import MoveTimes
from ptztrack.camera.pose_timeline import PoseTimeline
from ptztrack.camera.stream import LatestFrame, on_frame_clock

MOVE_TIMES = MoveTimes((0.0, 1 / 90), (0.0, 1 / 90), (0.0, 1 / 3))  # 90 deg/s, 90 deg/s, 3 zoom/s


@given(st.floats(0.0, 1.0), st.floats(-50.0, 50.0), st.floats(1.0, 4.0))
def test_between_two_samples_the_pose_is_interpolated_and_uncertain_by_its_speed_times_the_timing(
    fraction, pan_deg, zoom
):
    timeline = PoseTimeline(MOVE_TIMES, capture_time_sd_s=0.02)
    start, end = np.array([pan_deg, -10.0, zoom]), np.array([pan_deg + 9.0, -10.0, zoom])
    timeline.sample(100.0, start, moving=True)
    timeline.sample(100.1, end, moving=True)
    at = timeline.at(100.0 + 0.1 * fraction)
    np.testing.assert_allclose(at.pose, start + fraction * (end - start), atol=1e-9)
    np.testing.assert_allclose(at.sd, [90.0 * 0.02, 0.0, 0.0], atol=1e-9)


def test_a_camera_standing_still_is_exactly_where_it_stands():
    timeline = PoseTimeline(MOVE_TIMES)
    pose = np.array([10.0, -5.0, 2.0])
    timeline.sample(1.0, pose, moving=False)
    timeline.sample(1.04, pose, moving=False)
    assert timeline.at(0.5) is None  # before the first sample nobody knows
    for time_s in (1.02, 1.5):
        np.testing.assert_array_equal(timeline.at(time_s).pose, pose)
        np.testing.assert_array_equal(timeline.at(time_s).sd, 0.0)
    assert not timeline.moving()


def test_past_the_last_sample_the_camera_heads_for_its_target_at_its_speeds_and_stops_there():
    timeline = PoseTimeline(MOVE_TIMES, capture_time_sd_s=0.0)
    timeline.sample(10.0, np.array([0.0, 0.0, 1.0]), moving=False)
    timeline.sent(10.0, np.array([9.0, -4.5, 4.0]))
    assert timeline.moving()
    halfway = timeline.at(10.05)  # 4.5 deg of pan and tilt, 0.15 of zoom
    np.testing.assert_allclose(halfway.pose, [4.5, -4.5, 1.15])
    # Uncertain by what the axes cover in the time since the sample, spread evenly: v t / sqrt(3), at most the move.
    np.testing.assert_allclose(halfway.sd, [90 * 0.05 / np.sqrt(3)] * 2 + [3 * 0.05 / np.sqrt(3)])
    np.testing.assert_allclose(timeline.at(20.0).pose, [9.0, -4.5, 4.0])
    timeline.sample(10.2, np.array([9.0, -4.5, 1.6]), moving=True)
    timeline.sample(11.2, np.array([9.0, -4.5, 4.0]), moving=False)
    assert not timeline.moving()


def test_a_picture_shows_the_camera_settled_only_at_rest_and_once_its_move_could_have_landed():
    timeline = PoseTimeline(MOVE_TIMES)
    assert not timeline.settled(1.0)  # nothing is known yet
    timeline.sample(10.0, np.array([0.0, 0.0, 1.0]), moving=False)
    assert timeline.settled(10.0)
    timeline.sent(10.0, np.array([9.0, 0.0, 1.0]))  # 9 deg at 90 deg/s: it lands at 10.1
    for time_s, pan_deg, moving in ((10.04, 3.6, True), (10.08, 7.2, True), (10.12, 9.0, False), (10.16, 9.0, False)):
        timeline.sample(time_s, np.array([pan_deg, 0.0, 1.0]), moving)
    assert not timeline.settled(10.06) and timeline.settled(10.14)
    # A status that lags the command: still, where the camera was, before the move could have landed.
    timeline.sent(20.0, np.array([0.0, 0.0, 1.0]))
    for time_s in (20.02, 20.04, 20.2, 20.24):
        timeline.sample(time_s, np.array([9.0, 0.0, 1.0]), moving=False)
    assert not timeline.settled(20.03) and timeline.settled(20.22)


def test_the_newest_picture_is_handed_over_once_and_a_wait_ends_with_nothing():
    latest = LatestFrame()
    assert latest.newer(0, timeout_s=0.01) is None
    for number in range(3):
        latest.put(np.full((2, 2, 3), number, np.uint8), time_s=float(number))
    frame = latest.newer(0, timeout_s=0.01)
    assert frame.number == 3 and frame.time_s == 2.0 and frame.image[0, 0, 0] == 2
    assert latest.newer(frame.number, timeout_s=0.01) is None
    threading.Timer(0.05, latest.put, (np.zeros((2, 2, 3), np.uint8), 9.0)).start()
    assert latest.newer(frame.number, timeout_s=2.0).time_s == pytest.approx(9.0)


@given(st.floats(0.02, 0.2), st.floats(0.0, 0.3), st.integers(0, 2**32 - 1))
def test_pictures_arriving_unevenly_are_put_back_on_the_frame_clock_they_were_taken_on(period_s, jitter, seed):
    """A camera takes pictures ``period_s`` apart; they arrive late by up to ``jitter`` of that: the newest
    lands on its tick plus the mean lateness (a constant the calibrated delay takes up), off it by less
    than 0.4 of the most a picture is late (4.9 standard deviations of the line's end)."""
    rng = np.random.default_rng(seed)
    numbers = np.arange(50)
    taken_s = 1.7e9 + period_s * numbers
    late_s = rng.uniform(0.0, jitter * period_s, len(numbers))
    fitted_s = on_frame_clock(numbers, taken_s + late_s)
    assert abs(fitted_s - taken_s[-1] - jitter * period_s / 2) <= 0.4 * jitter * period_s + 1e-6


def test_pictures_off_any_clock_and_too_few_pictures_keep_their_own_times():
    rng = np.random.default_rng(0)
    snapshots_s = 1.7e9 + np.cumsum(rng.uniform(0.05, 0.5, 20))
    assert on_frame_clock(np.arange(20), snapshots_s) == snapshots_s[-1]
    assert on_frame_clock([3, 4], [10.0, 10.07]) == 10.07
