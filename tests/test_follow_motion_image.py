"""The motion history image, with the camera's own motion taken out by the homography of its poses."""

from pathlib import Path

import numpy as np
import pytest

from ptztrack.camera.virtual import virtual_ptz
from ptztrack.follow.motion_image import first_motion_image, motion_image_of, next_motion_image, non_motion_fraction
from ptztrack.geometry.calibration import load_pinhole
from ptztrack.geometry.ptz import rotation_homography

EXCERPT = Path(__file__).parent / "data" / "pets_s2l1_excerpt"


@pytest.fixture(scope="module")
def still_scene(excerpt_frames):
    """A static scene (one recorded frame) and the virtual camera that turns and zooms over it."""
    frame = excerpt_frames[0]
    virtual, whole_frame_pose = virtual_ptz(load_pinhole(EXCERPT / "pinhole.json"), image_size_px=(320, 240))
    return frame, virtual, whole_frame_pose


def test_a_static_scene_seen_by_a_turning_zooming_camera_leaves_the_motion_image_nearly_empty(still_scene):
    frame, virtual, start = still_scene
    poses = [start + [-3.0, 1.0, 0.4], start + [-1.0, 0.0, 0.6], start + [1.5, -1.5, 1.0], start + [3.0, -1.0, 1.3]]
    motion = first_motion_image(virtual.render(frame, poses[0]), scale=0.5)
    uncompensated = motion
    for previous, pose in zip(poses, poses[1:], strict=False):
        view = virtual.render(frame, pose)
        motion = next_motion_image(motion, view, rotation_homography(virtual.camera, previous, pose))
        uncompensated = next_motion_image(uncompensated, view, np.eye(3))
        assert motion.known.mean() > 0.5
        # What resampling the view at another zoom leaves: scattered pixels of fine, contrasted detail.
        assert (motion.history[motion.known] == 1).mean() < 0.01
        # Without the compensation the same views are full of apparent motion.
        assert (uncompensated.history[uncompensated.known] == 1).mean() > 0.1


def test_a_moving_square_moves_and_its_trail_fades():
    rng = np.random.default_rng(0)
    background = rng.integers(90, 110, (120, 160, 3), dtype=np.uint8)

    def frame(left):
        image = background.copy()
        image[40:60, left : left + 20] = 230
        return image

    motion = first_motion_image(frame(20), scale=1.0)
    assert not motion.known.any() and not motion.history.any()
    motion = next_motion_image(motion, frame(40), np.eye(3), threshold=15.0, decay=0.5)
    assert motion.history[50, 45] == 1.0  # the square's new place
    assert motion.history[50, 25] == 1.0  # the background it uncovered
    assert motion.history[90, 100] == 0.0  # the still background
    motion = next_motion_image(motion, frame(40), np.eye(3), threshold=15.0, decay=0.5)
    assert motion.history[50, 45] == 0.5  # nothing changed since: half faded


def test_non_motion_fraction_counts_known_pixels_under_all_patches():
    history = np.zeros((10, 10), np.float32)
    history[0:4, 0:5] = 1.0  # 20 moving pixels
    known = np.ones((10, 10), bool)
    known[:, 8:] = False
    motion = motion_image_of(history, known, np.zeros((10, 10), np.float32), 1.0)
    # Two patches: rows 0-3 x cols 0-9 (32 known, 20 moving) and rows 5-6 x cols 0-1 (4 known, none moving).
    boxes = np.array([[0.0, 0.0, 10.0, 4.0], [0.0, 5.0, 2.0, 2.0]])
    assert non_motion_fraction(motion, boxes) == pytest.approx(1 - 20 / 36)
    assert non_motion_fraction(motion, np.array([[8.0, 0.0, 2.0, 10.0]])) == 1.0  # nothing known
    assert non_motion_fraction(motion, boxes).shape == ()
    assert non_motion_fraction(motion, np.stack([boxes] * 3)).shape == (3,)
