import numpy as np

from ptztrack.geometry.calibration import project_pinhole
from ptztrack.occupancy.feet import fitted_feet_variances, localized_by_feet, nearest_feet_m, recording_feet_m
from ptztrack.occupancy.lpom import Modes
from ptztrack.occupancy.multiview import CameraView, MultiViewRecording
from ptztrack.occupancy.parameters import PomParameters
from ptztrack.occupancy.pom import PomDetector
from ptztrack.occupancy.pom_rectangles import person_box_px
from ptztrack.occupancy.room import RoomLayout, room_cameras

LAYOUT = RoomLayout(image_size_px=(320, 240), focal_px=156.0)
CAMERAS = room_cameras(LAYOUT)


def box_with_feet_at(camera, point_m, size_px=(20.0, 60.0), score=0.9) -> list[float]:
    """A box (left, top, width, height, score) whose bottom centre is the image of the ground point."""
    u, v = project_pinhole(camera, 1000.0 * np.array([[point_m[0], point_m[1], 0.0]]))[0]
    width_px, height_px = size_px
    return [u - width_px / 2, v - height_px, width_px, height_px, score]


def recording_with_boxes(boxes, truth_m) -> MultiViewRecording:
    views = tuple(
        CameraView(f"camera_{index + 1}", camera, LAYOUT.image_size_px, None, boxes[index])
        for index, camera in enumerate(CAMERAS)
    )
    return MultiViewRecording("room", views, len(truth_m), 15.0, np.array([[0, 0], [5, 6]]), None)


def test_a_candidate_moves_to_the_inverse_variance_weighted_mean_of_the_feet_within_the_gate():
    modes = Modes(np.array([[1.0, 1.0], [4.0, 4.0]]), np.stack([0.3 * np.eye(2)] * 2), np.array([0.9, 0.6]))
    feet_m = [
        np.array([[1.2, 1.0], [4.0, 6.0]]),  # the nearer is 0.2 m from the first candidate
        np.array([[0.9, 1.3]]),
        np.array([[2.1, 1.0]]),  # 1.1 m away: beyond the 1 m gate
        np.array([[1.0, 1.1]]),  # a view left out (infinite variance)
    ]
    variances_m2 = np.array([0.01, 0.04, 0.01, np.inf])
    moved = localized_by_feet(modes, feet_m, variances_m2, gate_m=1.0)
    # Weights 100 and 25: ((120 + 22.5) / 125, (100 + 32.5) / 125).
    np.testing.assert_allclose(moved.position_m[0], [1.14, 1.06], rtol=1e-12)
    np.testing.assert_allclose(moved.covariance_m2[0], np.eye(2) / 125.0, rtol=1e-12)
    # Nothing within the gate of the second: its own position and spread stay.
    np.testing.assert_array_equal(moved.position_m[1], [4.0, 4.0])
    np.testing.assert_array_equal(moved.covariance_m2[1], 0.3 * np.eye(2))
    np.testing.assert_array_equal(moved.strength, modes.strength)
    nearest = nearest_feet_m(modes.position_m, feet_m, 1.0)
    assert np.isnan(nearest[0, 2]).all() and np.isnan(nearest[1]).all()


def test_a_views_feet_variance_is_half_the_mean_squared_distance_to_the_annotated_people():
    frames = 12
    # Two people 2 m apart, walking along x.
    truth_m = np.stack([np.array([[1.0 + 0.1 * frame, 2.0], [1.0 + 0.1 * frame, 4.0]]) for frame in range(frames)])
    offsets_m = {0: lambda frame: (0.1 if frame % 2 else -0.1, 0.0), 1: lambda frame: (0.0, 0.3)}
    offsets_m[2] = lambda frame: (1.5, 0.0)  # beyond the gate: never matched
    boxes = []
    for index, camera in enumerate(CAMERAS):
        per_frame = []
        for frame in range(frames):
            found = [
                box_with_feet_at(camera, person + np.array(offsets_m.get(index, offsets_m[0])(frame)))
                for person in truth_m[frame]
            ]
            found.append(box_with_feet_at(camera, truth_m[frame, 0], score=0.2))  # below the score: not a box
            per_frame.append(np.array(found))
        # View 3 sees the people in 8 frames only: 16 matches, fewer than a fit needs.
        boxes.append(per_frame if index != 3 else per_frame[:8] + [np.zeros((0, 5))] * 4)
    recording = recording_with_boxes(boxes, truth_m)
    feet_m = recording_feet_m(recording, 0, min_box_score=0.5)
    assert [len(feet) for feet in feet_m] == [2, 2, 2, 2]
    variances = fitted_feet_variances(recording, truth_m, range(frames), gate_m=1.0, min_box_score=0.5)
    np.testing.assert_allclose(variances[:2], [0.005, 0.045], rtol=1e-6)
    assert np.isinf(variances[2]) and np.isinf(variances[3])


def test_pom_candidates_localized_by_the_feet_land_on_them():
    truth_m = np.array([[[2.13, 3.41]], [[2.38, 2.77]]])
    boxes = []
    for camera in CAMERAS:
        per_frame = []
        for frame in range(2):
            # The model person's box, moved so that its feet are the person's to the pixel's fraction.
            left, top, right, bottom = person_box_px(camera, truth_m[frame], 1.75, 0.5)[0]
            per_frame.append(np.array([box_with_feet_at(camera, truth_m[frame, 0], (right - left, bottom - top))]))
        boxes.append(per_frame)
    recording = recording_with_boxes(boxes, truth_m)
    cells = PomDetector(recording, PomParameters())
    feet = cells.with_feet_variances(np.full(4, 0.01))
    for frame in range(2):
        _, by_cell = cells.detect(frame)
        _, by_feet = feet.detect(frame)
        by_cell = by_cell.select(by_cell.strength >= 0.5)
        by_feet = by_feet.select(by_feet.strength >= 0.5)
        assert len(by_cell) == len(by_feet) == 1
        np.testing.assert_allclose(by_feet.position_m[0], truth_m[frame, 0], atol=1e-6)
        np.testing.assert_allclose(by_feet.covariance_m2[0], np.eye(2) * 0.01 / 4, rtol=1e-9)
        # The cells are a quarter of a metre: their candidate is near the person, not on them.
        assert 1e-3 < np.linalg.norm(by_cell.position_m[0] - truth_m[frame, 0]) < 0.25
