"""People cut out of a recording with a background model, and pasted into other images."""

import numpy as np
import pytest

from ptztrack.geometry.calibration import aimed_pinhole
from ptztrack.scene.cutouts import Cutout, cut_people, isolated_boxes, paste_people

SIZE_PX = (160, 120)
FRAMES = 12


def walking_block(frames: int = FRAMES):
    """A textured background and a dark 12 x 40 px 'person' walking right 4 px a frame (the median of the
    frames is the background); their boxes, 20 x 44 px, as an annotator draws them around a person."""
    rng = np.random.default_rng(0)
    background = rng.integers(120, 200, (SIZE_PX[1], SIZE_PX[0], 3)).astype(np.uint8)
    images, boxes = [], []
    for frame in range(frames):
        image = background.copy()
        left = 30 + 4 * frame
        image[50:90, left : left + 12] = 20
        images.append(image)
        boxes.append([left - 4, 48, 20, 44])
    return images, np.array(boxes, dtype=float)


def test_a_person_alone_is_cut_out_as_one_walk_with_their_matte():
    images, boxes = walking_block()
    (track,) = cut_people(enumerate(images), FRAMES, np.arange(FRAMES), np.full(FRAMES, 7), boxes, min_height_px=30)
    assert track.person_id == 7 and track.moving_right and len(track.cutouts) == FRAMES
    cutout = track.cutouts[0]
    left, top = int(cutout.feet_px[0] - 6), int(cutout.feet_px[1] - 42)  # the block's corner in the cut
    assert cutout.alpha[top + 2 : top + 38, left + 2 : left + 10].min() > 0.9
    assert cutout.alpha[:, : left - 2].max() < 0.1 and cutout.alpha[:, left + 14 :].max() < 0.1
    assert cutout.height_px == 44.0


def test_people_too_short_too_close_to_another_or_cut_by_the_border_are_not_cut():
    boxes = np.array([[10, 10, 10, 40], [20, 12, 10, 40], [100, 10, 10, 40], [150, 10, 10, 40], [60, 70, 5, 20]])
    frames = np.zeros(5, dtype=int)
    usable = isolated_boxes(frames, boxes, SIZE_PX, min_height_px=30)
    # The first two meet within their margins; the fourth's margin leaves the image; the fifth is short.
    assert usable.tolist() == [False, False, True, False, False]
    assert isolated_boxes(np.array([0, 1, 0, 0, 0]), boxes, SIZE_PX, 30).tolist() == [True, True, True, False, False]


def test_a_pasted_person_stands_on_the_box_at_its_height_far_ones_first():
    camera = aimed_pinhole((0.0, -10.0, 3.0), (0.0, 0.0), 200.0, SIZE_PX)

    def block(colour):
        patch = np.zeros((44, 20, 3), np.uint8)
        patch[2:42, 4:16] = colour
        alpha = np.zeros((44, 20), np.float32)
        alpha[2:42, 4:16] = 1.0
        return Cutout(patch, alpha, feet_px=np.array([10.0, 42.0]), height_px=40.0)

    red, blue = block((0, 0, 255)), block((255, 0, 0))
    background = np.full((SIZE_PX[1], SIZE_PX[0], 3), 128, np.uint8)
    near, far = [70.0, 30.0, 12.0, 80.0], [74.0, 10.0, 6.0, 40.0]  # the far one behind the near one, taller
    image = paste_people(background, camera, [near, far], [[0.0, -1.0], [0.0, 5.0]], [red, blue], [False, True])
    rows, columns = np.nonzero(image[..., 2] > 200)
    # Scaled twice (40 to 80 px), its feet on the box's bottom centre (76, 110): rows 30-109, 24 px wide.
    assert abs(rows.min() - 30) <= 1 and abs(rows.max() - 109) <= 1
    assert (columns.min() + columns.max() + 1) / 2 == pytest.approx(76, abs=1) and abs(np.ptp(columns) + 1 - 24) <= 2
    # The far one shows only where the near one does not cover it: above its head.
    blue_rows, _ = np.nonzero(image[..., 0] > 200)
    assert len(blue_rows) and blue_rows.max() < 31
    nothing = paste_people(background, camera, [[500.0, 30.0, 12.0, 80.0]], [[0.0, 0.0]], [red], [False])
    assert (nothing == background).all()  # outside the image
