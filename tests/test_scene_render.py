"""The renderer's boxes and stage: a person's box stands on their projected feet, the stage holds the cameras."""

import numpy as np
import pytest

from ptztrack.geometry.calibration import aimed_pinhole, camera_centre_m, project_pinhole
from ptztrack.scene.render import person_boxes, stage_around

CAMERA = aimed_pinhole((12.5, 0.0, 6.0), (12.5, 9.0), 400.0, (960, 540))


def test_a_box_stands_on_the_feet_and_reaches_the_head():
    positions_m = np.array([[12.5, 9.0], [3.0, 15.0], [20.0, 4.0]])
    heights_m, widths_m = np.array([1.8, 1.6, 1.7]), np.array([0.5, 0.6, 0.4])
    boxes, seen = person_boxes(CAMERA, (960, 540), positions_m, heights_m, widths_m)
    assert seen.all()
    feet_px = project_pinhole(CAMERA, 1000.0 * np.c_[positions_m, np.zeros(3)])
    head_px = project_pinhole(CAMERA, 1000.0 * np.c_[positions_m, heights_m])
    assert boxes[:, 0] + boxes[:, 2] / 2 == pytest.approx(feet_px[:, 0])
    assert boxes[:, 1] + boxes[:, 3] == pytest.approx(feet_px[:, 1])
    assert boxes[:, 1] == pytest.approx(head_px[:, 1])
    # At the image's centre, the width is the person's width at their distance.
    distance_m = np.linalg.norm(np.array([12.5, 9.0, 0.0]) - camera_centre_m(CAMERA))
    assert boxes[0, 2] == pytest.approx(400.0 * 0.5 / distance_m, rel=1e-3)


def test_people_behind_or_beside_the_camera_have_no_box_and_feet_outside_are_not_seen():
    positions_m = np.array([[12.5, -5.0], [-30.0, 1.0], [12.5, 1.5]])  # behind; far off to the side; below it
    boxes, seen = person_boxes(CAMERA, (960, 540), positions_m, np.full(3, 1.7), np.full(3, 0.5))
    assert np.isnan(boxes[0]).all() and not seen[0]
    assert not seen[1] and not seen[2]
    assert np.isfinite(boxes[2]).all()  # in front of the camera: its box, though its feet are below the image


def test_the_stage_holds_the_area_and_every_camera_with_its_margin():
    other = aimed_pinhole((-4.0, 30.0, 20.0), (12.5, 9.0), 400.0, (960, 540))
    stage = stage_around(((0.0, 0.0), (25.0, 18.0)), [CAMERA, other], margin_m=5.0, height_m=15.0)
    assert np.array(stage.bounds_m) == pytest.approx(np.array([[-9.0, -5.0], [30.0, 35.0]]))
    assert stage.height_m == 25.0  # the highest camera, 20 m, plus the margin
