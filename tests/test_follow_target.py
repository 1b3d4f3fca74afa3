"""The follow camera's tracker: a target source's box reported as one smoothed ground track."""

from dataclasses import dataclass, field

import numpy as np
import pytest

from ptztrack.follow.target import TargetEstimate, TargetTracker, box_corners_carried
from ptztrack.geometry.ptz import PTZCamera, look_at, projection_matrix, rotation_homography

CAMERA = PTZCamera((0.0, 0.0, 7.0), 640, 480, 800.0)
POSE = look_at(CAMERA, [0.0, 15.0], 2.0)
IMAGE = np.zeros((480, 640, 3), np.uint8)
PERSON_HEIGHT_M = 1.75


def centre_px(position_m, pose=POSE) -> np.ndarray:
    """Where the middle of a person standing at ``position_m`` appears."""
    homogeneous = projection_matrix(CAMERA, pose) @ np.r_[position_m, PERSON_HEIGHT_M / 2, 1.0]
    return homogeneous[:2] / homogeneous[2]


def box_around(position_m, pose=POSE, height_px=100.0) -> np.ndarray:
    centre = centre_px(position_m, pose)
    return np.r_[centre - [0.2 * height_px, height_px / 2], 0.4 * height_px, height_px]


@dataclass
class ScriptedSource:
    """A target source that reports the boxes it is given, one per step (None: lost)."""

    boxes: list
    homographies: list = field(default_factory=list)
    standing_heights: list = field(default_factory=list)
    started_on: np.ndarray | None = None

    def start(self, image_bgr, box_px):
        self.started_on = np.asarray(box_px)
        return TargetEstimate(self.started_on, False, np.eye(2))

    def step(self, image_bgr, homography, standing_height_px):
        self.homographies.append(homography)
        self.standing_heights.append(standing_height_px)
        box = self.boxes.pop(0)
        lost = box is None
        return TargetEstimate(self.started_on if lost else box, lost, np.eye(2))


def tracker(source, smoothing=0.5, initial_pose=POSE) -> TargetTracker:
    return TargetTracker(
        CAMERA, source, box_around([0.0, 15.0], initial_pose), initial_pose, PERSON_HEIGHT_M, smoothing, 0.1
    )


def test_the_track_lies_under_the_middle_of_the_box_and_starts_from_the_initial_box():
    source = ScriptedSource([])
    follower = tracker(source, smoothing=0.0)
    before = follower.predict()
    np.testing.assert_allclose(before.mean[0], [0.0, 15.0, 0.0, 0.0], atol=1e-9)
    assert before.hits[0] == 0
    update = follower.update(None, POSE, lambda: IMAGE)
    np.testing.assert_allclose(update.tracks.mean[0, :2], [0.0, 15.0], atol=1e-9)
    np.testing.assert_array_equal(update.track_ids, [0])
    assert follower.wants_detections(0) is False
    # The measurement recorded is the box: its feet and height.
    box = box_around([0.0, 15.0])
    np.testing.assert_allclose(update.measurements.feet_px, [[box[0] + box[2] / 2, box[1] + box[3]]])


def test_the_initial_box_is_carried_into_the_first_view_and_the_camera_motion_handed_to_the_source():
    start, first, second = POSE, POSE + [2.0, -1.0, 0.5], POSE + [3.0, -1.0, 0.5]
    source = ScriptedSource([box_around([0.0, 15.0], second)])
    follower = tracker(source, initial_pose=start)
    follower.update(None, first, lambda: IMAGE)
    expected = box_corners_carried(box_around([0.0, 15.0], start), rotation_homography(CAMERA, start, first))
    np.testing.assert_allclose(source.started_on, expected)
    follower.update(None, second, lambda: IMAGE)
    np.testing.assert_allclose(source.homographies[0], rotation_homography(CAMERA, first, second))
    # The calibration handed over is the new view's: the projected person standing at (0, 15) m.
    feet, head = (projection_matrix(CAMERA, second) @ [0.0, 15.0, z, 1.0] for z in (0.0, PERSON_HEIGHT_M))
    feet_px, head_px = feet[:2] / feet[2], head[:2] / head[2]
    np.testing.assert_allclose(source.standing_heights[0](feet_px[None]), [np.hypot(*(head_px - feet_px))])


def test_the_output_filter_learns_a_walkers_velocity_and_the_prediction_leads_by_it():
    velocity_m_s = np.array([1.0, 0.5])
    positions = [np.array([0.0, 15.0]) + velocity_m_s * 0.1 * (k + 1) for k in range(60)]
    follower = tracker(ScriptedSource([box_around(p) for p in positions]))
    follower.update(None, POSE, lambda: IMAGE)
    for _ in positions:
        follower.update(None, POSE, lambda: IMAGE)
    mean = follower.reported().mean[0]
    np.testing.assert_allclose(mean[2:], velocity_m_s, atol=1e-3)
    np.testing.assert_allclose(mean[:2], positions[-1], atol=1e-3)
    np.testing.assert_allclose(follower.predict().mean[0, :2], positions[-1] + 0.1 * velocity_m_s, atol=1e-3)


def test_a_lost_target_is_held_still_and_found_again_where_the_source_finds_it():
    boxes = [box_around([0.5, 15.0]), None, None, box_around([2.0, 16.0])]
    follower = tracker(ScriptedSource(boxes))
    follower.update(None, POSE, lambda: IMAGE)
    follower.update(None, POSE, lambda: IMAGE)
    before = follower.reported().mean[0].copy()
    for missed in (1, 2):
        update = follower.update(None, POSE, lambda: IMAGE)
        assert follower.missed_steps == missed and update.tracks.existence[0] == 0 and len(update.track_ids) == 0
        np.testing.assert_allclose(update.tracks.mean[0], np.r_[before[:2], 0.0, 0.0])
        np.testing.assert_allclose(follower.predict().mean[0], np.r_[before[:2], 0.0, 0.0])
    found = follower.update(None, POSE, lambda: IMAGE)
    assert follower.missed_steps == 0 and found.tracks.existence[0] == 1
    np.testing.assert_allclose(found.tracks.mean[0], [2.0, 16.0, 0.0, 0.0], atol=1e-9)


def test_a_camera_without_images_is_refused():
    with pytest.raises(RuntimeError, match="renders images"):
        tracker(ScriptedSource([])).update(None, POSE, lambda: None)
