from pathlib import Path

import numpy as np
import pytest

from ptztrack.camera.virtual import virtual_ptz
from ptztrack.config import ScenarioError, scenario_from_dict
from ptztrack.detect.hog import HogPeopleDetector, feet_and_height_px
from ptztrack.geometry.calibration import load_pinhole
from ptztrack.geometry.ptz import apply_homography, ground_to_image
from ptztrack.scene.pets import DatasetError, RecordedVideo, load_mot_ground_truth, read_video

EXCERPT = Path(__file__).parent / "data" / "pets_s2l1_excerpt"


def test_feet_sit_one_eighth_of_the_box_above_its_bottom_and_the_person_is_three_quarters_of_it():
    feet, height = feet_and_height_px([[10.0, 20.0, 16.0, 32.0]])
    np.testing.assert_allclose(feet, [[18.0, 48.0]])
    np.testing.assert_allclose(height, [24.0])


def test_hog_finds_the_people_of_a_zoomed_virtual_view_at_their_annotated_feet():
    virtual, whole_frame = virtual_ptz(load_pinhole(EXCERPT / "pinhole.json"))
    pose = whole_frame * [1, 1, 2]
    frame = 10
    view = virtual.render(read_video(EXCERPT / "View_001.avi")[frame], pose)
    boxes, scores = HogPeopleDetector().boxes(view)
    assert len(boxes) >= 1 and np.all(scores > 0)
    truth = load_mot_ground_truth(EXCERPT / "gt_mot15.txt")
    annotated = apply_homography(ground_to_image(virtual.camera, pose), truth.ground_m[truth.frame == frame])
    feet, _ = feet_and_height_px(boxes)
    nearest_px = np.linalg.norm(feet[:, None] - annotated[None], axis=-1).min(axis=1)
    assert np.sum(nearest_px < 4.0) >= 1


def test_hog_finds_nobody_in_an_empty_image():
    boxes, scores = HogPeopleDetector().boxes(np.full((120, 160, 3), 128, np.uint8))
    assert boxes.shape == (0, 4) and scores.shape == (0,)


def test_recorded_video_reads_forwards_and_reopens_to_go_back():
    frames = read_video(EXCERPT / "View_001.avi")
    video = RecordedVideo(EXCERPT / "View_001.avi", (768, 576))
    np.testing.assert_array_equal(video.frame(4), frames[4])
    np.testing.assert_array_equal(video.frame(10), frames[10])
    np.testing.assert_array_equal(video.frame(2), frames[2])
    with pytest.raises(DatasetError, match="ends before frame 40"):
        video.frame(40)
    with pytest.raises(DatasetError, match="frames are 768x576 px, expected 640x480"):
        RecordedVideo(EXCERPT / "View_001.avi", (640, 480)).frame(0)


def test_hog_needs_a_recording_with_video():
    with pytest.raises(ScenarioError, match="'hog' needs a recording with a video"):
        scenario_from_dict({"detector": {"kind": "hog"}})
