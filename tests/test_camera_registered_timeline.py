"""The timeline of a camera placed by its pictures, its moves without AbsoluteMove and its sweep's poses."""

import numpy as np
import pytest

from ptztrack.camera.onvif_spaces import CameraSpaces, MoveTimes
from ptztrack.camera.reference_sweep import continuous_move, relative_translation, sweep_poses
from ptztrack.camera.registered_timeline import RegisteredTimeline
from ptztrack.geometry.ptz import PTZCamera

MOVES = MoveTimes(pan=(0.2, 1 / 90), tilt=(0.2, 1 / 90), zoom=(0.2, 1 / 3))
SD = np.array([0.1, 0.1, 0.02])
HERE, THERE = np.array([50.0, 15.0, 2.0]), np.array([59.0, 15.0, 2.0])
SPACES = CameraSpaces(pan_deg=(-90.0, 90.0), tilt_deg=(45.0, -45.0), zoom_curve=((0.0, 1.0), (0.5, 2.0), (1.0, 8.0)))


def _still_at(pose, times_s, timeline=None) -> RegisteredTimeline:
    timeline = timeline or RegisteredTimeline(MOVES, capture_time_sd_s=0.02)
    for time_s in times_s:
        timeline.registered(time_s, pose, SD)
    return timeline


def test_a_picture_is_placed_only_by_its_own_registration_with_the_registrations_sd_added():
    timeline = _still_at(HERE, [10.0, 10.04])
    at = timeline.at(10.04)
    np.testing.assert_allclose(at.pose, HERE)
    np.testing.assert_allclose(at.sd, SD)  # standing still: the registration's sd alone
    assert timeline.at(10.02) is None and timeline.at(10.08) is None  # pictures that did not register


def test_a_registered_pose_that_jumps_is_moving_and_a_picture_at_rest_after_the_landing_is_settled():
    timeline = _still_at(HERE, [10.0, 10.04])
    assert not timeline.moving() and timeline.settled(10.04)
    timeline.sent(10.05, THERE)  # 9 degrees: lands 0.2 + 0.1 s later
    assert timeline.moving() and not timeline.ready(10.1)
    assert timeline.registered(10.2, HERE + [3.0, 0, 0], SD)  # moving: it jumped, and before the landing
    assert timeline.registered(10.4, THERE, SD)  # moving: it jumped from the last one
    assert not timeline.ready(10.41) and not timeline.settled(10.4)
    assert not timeline.registered(10.44, THERE + [0.05, 0, 0], SD)  # within the noise
    assert timeline.ready(10.45) and timeline.settled(10.44)
    np.testing.assert_allclose(timeline.current(), THERE + [0.05, 0, 0])


def test_pictures_that_show_the_camera_where_a_move_left_it_are_moving_until_one_shows_the_move():
    """A stream later than its calibrated delay shows the camera still where it was after the move's
    landing: those pictures are moving, not settled, until one shows the move (or a second has passed)."""
    timeline = _still_at(HERE, [10.0])
    timeline.sent(10.05, THERE)  # lands at 10.35
    assert timeline.registered(10.4, HERE, SD) and timeline.registered(10.44, HERE, SD)
    assert not timeline.ready(10.45) and not timeline.settled(10.44)
    assert timeline.registered(10.48, THERE, SD)  # it moved
    assert not timeline.registered(10.52, THERE, SD) and timeline.settled(10.52) and timeline.ready(10.53)
    timeline.sent(10.6, HERE)  # lands at 10.9; shown by no picture
    assert timeline.registered(11.8, THERE, SD) and not timeline.registered(11.95, THERE, SD)


def test_a_move_starts_from_its_target_when_no_picture_registered_after_it():
    timeline = _still_at(HERE, [10.0])
    np.testing.assert_allclose(timeline.current(), HERE)
    timeline.sent(10.05, THERE)
    assert not timeline.ready(10.2) and timeline.ready(10.4)  # no picture since: once it could have landed
    np.testing.assert_allclose(timeline.current(), THERE)


def test_pictures_that_do_not_register_are_never_placed_but_after_a_blind_second_the_moves_go_on():
    timeline = _still_at(HERE, [10.0])
    timeline.sent(10.05, THERE)  # lands at 10.35
    assert not timeline.dead_reckoned(11.0) and timeline.at(11.0) is None  # skipped
    assert timeline.dead_reckoned(11.4)
    assert timeline.at(11.4) is None  # the picture is not used,
    assert timeline.settled(11.4)  # but the camera stands where its moves took it: the policy may choose
    np.testing.assert_allclose(timeline.current(), THERE)  # but the next move starts where this one went
    assert timeline.ready(11.45)
    # Its sd, the registration's and 5 % of the 9 deg pan since, is what the next picture is compared with:
    # a pan 1.5 deg off is within 3 such sds (0.56 deg each) and at rest, 2 deg off is moving.
    for pan_off_deg, moving in ((1.5, False), (2.0, True)):
        timeline = _still_at(HERE, [10.0])
        timeline.sent(10.05, THERE)
        assert timeline.dead_reckoned(11.4)
        assert timeline.registered(11.5, np.add(THERE, [pan_off_deg, 0.0, 0.0]), SD) == moving


def test_a_relative_move_is_the_difference_of_the_normalised_poses_and_a_continuous_one_ends_all_axes_together():
    np.testing.assert_allclose(relative_translation(SPACES, HERE, THERE), [0.1, 0.0, 0.0])
    # Tilt's degrees fall from -1 to +1: looking 9 degrees lower is -0.2; zoom 2 to 5 is half the curve's top.
    np.testing.assert_allclose(relative_translation(SPACES, HERE, [50.0, 24.0, 5.0]), [0.0, -0.2, 0.25])
    velocity, duration_s = continuous_move(SPACES, MOVES, HERE, [41.0, 19.5, 3.0])
    # Pan 9 deg at 90 deg/s is the slowest axis (0.1 s): tilt runs at half speed, zoom (1/3 s) at a third.
    assert duration_s == pytest.approx(1 / 3)
    np.testing.assert_allclose(velocity, [-0.3, -0.15, 1.0])


def test_the_sweep_covers_the_action_grid_more_densely_at_longer_zooms():
    camera = PTZCamera((0.0, 0.0, 5.0), 160, 120, 236.0)
    grid = np.array([[pan, tilt, zoom] for pan in (43.0, 71.0) for tilt in (7.0, 27.0) for zoom in (1.0, 4.0)])
    known = np.array([57.0, 17.0, 1.0])
    poses = sweep_poses(camera, grid, known)
    zooms = np.unique(poses[:, 2])
    np.testing.assert_allclose(zooms, [1.0, 2**0.5, 2.0, 2**1.5, 4.0])
    assert not np.any(np.all(poses == known, axis=1))
    counts = [np.sum(poses[:, 2] == zoom) for zoom in zooms]
    assert counts == sorted(counts) and counts[0] < counts[-1]
    np.testing.assert_allclose(
        [poses[:, 0].min(), poses[:, 0].max(), poses[:, 1].min(), poses[:, 1].max()], [43, 71, 7, 27]
    )
    # Neighbours within SWEEP_STEP_FRACTION of their view apart: at zoom 4 the view is 9.5 x 7.2 degrees.
    at_four = poses[poses[:, 2] == 4.0]
    assert np.diff(np.unique(at_four[:, 0])).max() <= 0.5 * 9.5
    assert np.diff(np.unique(at_four[:, 1])).max() <= 0.5 * 7.2
