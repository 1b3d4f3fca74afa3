"""The follow controller: framing pose, pursuit with speed and acceleration limits, holding still."""

import numpy as np
import pytest

from ptztrack.follow.controller import FollowPolicy, FramingParameters, framing_pose
from ptztrack.follow.parameters import FollowParameters
from ptztrack.geometry.ptz import PTZCamera, look_at, project_people, projection_matrix
from ptztrack.types import DecisionContext, Tracks

CAMERA = PTZCamera((0.0, 0.0, 7.0), 640, 480, 400.0)
PARAMETERS = FramingParameters(
    follow=FollowParameters(
        target_height_px=150.0,
        max_speed_deg_s=30.0,
        max_acceleration_deg_s2=30.0,
        max_zoom_speed=0.7,
        max_zoom_acceleration=0.7,
        zoom_range=(1.0, 8.0),
    ),
    target_point_px=np.array([200.0, 300.0]),
    person_height_m=1.75,
    person_width_m=0.5,
    step_s=0.1,
)


def track_at(position_m, velocity_m_s=(0.0, 0.0), lost=False) -> Tracks:
    return Tracks(
        np.array([0]),
        np.r_[position_m, velocity_m_s][None],
        np.eye(4)[None] * 0.01,
        np.array([0.0 if lost else 1.0]),
        np.array([1]),
    )


def context(step, tracks, pose) -> DecisionContext:
    return DecisionContext(step, 0, np.array([0]), tracks, np.random.default_rng(0), np.asarray(pose, dtype=float))


def test_the_framing_pose_shows_the_persons_middle_at_the_target_point_and_height():
    position_m = np.array([3.0, 15.0])
    start = look_at(CAMERA, position_m, 1.0)
    pose = framing_pose(CAMERA, position_m, start, PARAMETERS)
    middle = projection_matrix(CAMERA, pose) @ np.r_[position_m, 0.875, 1.0]
    np.testing.assert_allclose(middle[:2] / middle[2], PARAMETERS.target_point_px, atol=1e-6)
    person = project_people(CAMERA, pose, position_m[None], 1.75, 0.5)
    assert person.height_px[0] == pytest.approx(150.0, rel=1e-4)


def test_the_framing_pose_does_not_zoom_the_person_out_of_the_current_view():
    position_m = np.array([3.0, 15.0])
    aside = look_at(CAMERA, position_m, 1.0) + [18.0, 0.0, 0.0]  # the person near the image's left edge
    pose = framing_pose(CAMERA, position_m, aside, PARAMETERS)
    box = project_people(CAMERA, np.r_[aside[:2], pose[2]], position_m[None], 1.75, 0.5).box_px[0]
    assert pose[2] < 3.0
    assert box[0] >= -1e-6 and box[2] <= 640 + 1e-6


def test_the_camera_settles_on_a_still_person_within_its_speed_and_acceleration_limits():
    position_m = np.array([3.0, 15.0])
    policy = FollowPolicy(CAMERA, PARAMETERS)
    pose = look_at(CAMERA, position_m + [4.0, 0.0], 1.0)
    poses = [pose]
    for step in range(80):
        pose = policy.choose(context(step, track_at(position_m), pose))
        poses.append(pose)
    poses = np.array(poses)
    wanted = framing_pose(CAMERA, position_m, poses[-1], PARAMETERS)
    np.testing.assert_allclose(poses[-1], wanted, atol=1e-3)
    speed_deg_s = np.abs(np.diff(poses[:, :2], axis=0)) / PARAMETERS.step_s
    assert speed_deg_s.max() <= 30.0 + 1e-9
    second_difference = np.abs(np.diff(poses[:, :2], n=2, axis=0))
    assert second_difference.max() <= 30.0 * 0.1**2 + 1e-9
    assert np.all(np.abs(np.diff(np.log(poses[:, 2]), n=2)) <= 0.7 * 0.1**2 + 1e-9)


def test_the_camera_keeps_up_with_a_walker_without_lag():
    policy = FollowPolicy(CAMERA, PARAMETERS)
    velocity_m_s = np.array([1.2, -0.4])
    position_m = np.array([-4.0, 14.0])
    pose = framing_pose(CAMERA, position_m, look_at(CAMERA, position_m, 1.0), PARAMETERS)
    for step in range(60):
        position_m = position_m + 0.1 * velocity_m_s
        pose = policy.choose(context(step, track_at(position_m, velocity_m_s), pose))
    middle = projection_matrix(CAMERA, pose) @ np.r_[position_m, 0.875, 1.0]
    assert np.hypot(*(middle[:2] / middle[2] - PARAMETERS.target_point_px)) < 2.0


def test_without_a_track_or_with_a_held_one_the_camera_comes_to_rest():
    policy = FollowPolicy(CAMERA, PARAMETERS, velocity=np.array([20.0, -10.0, 0.5]))
    pose = np.array([10.0, 20.0, 2.0])
    for step in range(20):
        pose = policy.choose(context(step, Tracks.empty(), pose))
    np.testing.assert_allclose(policy.velocity, 0.0, atol=1e-12)
    held = track_at([3.0, 15.0], lost=True)  # a lost track holds its last position, no velocity
    for step in range(80):
        pose = policy.choose(context(step, held, pose))
    np.testing.assert_allclose(pose, framing_pose(CAMERA, [3.0, 15.0], pose, PARAMETERS), atol=1e-3)
