"""A dataset file's view as a scenario: the built-in PETS one, and a recording of another size and pace."""

import json
import logging
import math
import shutil
from pathlib import Path

import numpy as np
import pytest

from bad_input_files import video_bytes
from ptztrack.builders.episode import run_episode
from ptztrack.builders.recording import (
    FOLLOW_PROTOCOL,
    TABLES_PROTOCOL,
    dataset_scenario,
    frame_step,
    pets_follow_scenario,
    pets_scenario,
)
from ptztrack.builders.world import build_world
from ptztrack.config import PETS_DATASET_FILE, ScenarioError, load_dataset, pets_dataset
from ptztrack.geometry.calibration import load_pinhole, project_pinhole
from ptztrack.scene.pets import DatasetError

EXCERPT = Path(__file__).parent / "data" / "pets_s2l1_excerpt"


@pytest.mark.parametrize(
    "frame_rate_hz, step_rate_hz, step",
    [(10, 5, 2), (12.5, 5, 2), (15, 5, 3), (7, 5, 1), (2, 5, 1), (25, 5, 5), (17.5, 5, 3), (10, None, 1)],
)
def test_the_frame_step_is_the_whole_number_of_frames_nearest_a_step(frame_rate_hz, step_rate_hz, step):
    """Nearest in duration; 2.5 and 3.5 frames a step are ties, taken to the shorter step."""
    assert frame_step(frame_rate_hz, step_rate_hz) == step


def test_the_built_in_pets_scenario_is_its_dataset_files_first_view_under_the_tables_protocol():
    scenario = pets_scenario("hog")
    assert scenario == dataset_scenario(
        pets_dataset(), None, TABLES_PROTOCOL, PETS_DATASET_FILE, **{"detector.kind": "hog"}
    )
    recording = scenario.recording
    assert recording is not None and recording.name == "PETS 2009 S2.L1 View_001" and recording.view == "View_001"
    # The paper's protocol on S2.L1: every 2nd of its 795 frames (10 fps) at 5 Hz, a 160 x 120 view.
    assert (recording.frame_step, scenario.frame_rate_hz, scenario.frames) == (2, 5.0, 398)
    assert scenario.camera.image_size_px == (160, 120) and recording.recorded_size_px == (768, 576)
    assert scenario.pose_feedback.image_size_px == (640, 480) and scenario.actions.zoom == (1.0, 2.0, 3.0, 4.0)
    assert Path(str(recording.detections)).name == "View_001_det.txt.gz"
    follow = pets_follow_scenario("csrt")
    assert (follow.recording.frame_step, follow.frame_rate_hz, follow.frames) == (1, 10.0, 795)
    assert follow.camera.image_size_px == (640, 480) and follow.tracker.kind == "csrt"


def _recording(directory: Path, size_px: tuple[int, int], frame_rate_hz: float) -> Path:
    """A dataset file of one view: the excerpt's calibration with K scaled to ``size_px`` (the same
    field of view), a grey video of 30 frames of that size, the excerpt's ground truth with its boxes
    scaled, at ``frame_rate_hz``."""
    scale = size_px[0] / 768
    views = json.loads((EXCERPT / "pinhole.json").read_text())
    views["View_001"]["K"] = (np.diag([scale, scale, 1.0]) @ np.asarray(views["View_001"]["K"])).tolist()
    (directory / "c.json").write_text(json.dumps(views))
    (directory / "v.avi").write_bytes(video_bytes(30, size_px, directory))
    rows = np.loadtxt(EXCERPT / "gt_mot15.txt", delimiter=",")
    rows[:, 2:6] *= scale
    np.savetxt(directory / "gt.txt", rows, delimiter=",", fmt="%.6g")
    path = directory / "d.yaml"
    path.write_text(
        f"name: wide\nframe_rate_hz: {frame_rate_hz}\narea_m: [[-20, -17], [8, 9]]\nground_truth: gt.txt\n"
        f"views:\n  - {{name: cam, calibration: c.json, calibration_view: View_001, "
        f"image_size_px: [{size_px[0]}, {size_px[1]}], video: v.avi}}\n"
    )
    return path


def test_a_recording_of_another_size_and_pace_sets_the_view_and_the_step_and_warns_of_the_rate(tmp_path, caplog):
    path = _recording(tmp_path, (1024, 576), 12.5)
    with caplog.at_level(logging.WARNING):
        scenario = dataset_scenario(load_dataset(path), dataset_file=path)
    assert [record.getMessage() for record in caplog.records] == [
        f"{path}: its 12.5 fps give steps of 6.25 Hz (every 2 frames), not the protocol's 5 Hz; the tracker "
        "predicts 0.16 s a step"
    ]
    recording = scenario.recording
    assert recording is not None and recording.recorded_size_px == (1024, 576)
    # 160 px wide at the recording's 16:9, a step every 2 of its 30 annotated frames at 6.25 Hz.
    assert scenario.camera.image_size_px == (160, 90) and scenario.pose_feedback.image_size_px == (640, 360)
    # Zooms up to where the 160 px view reads the 1024 px recording at its own resolution: 6.
    assert scenario.actions.zoom == (1.0, 2.0, 3.0, 4.0, 5.0, 6.0)
    assert (recording.frame_step, scenario.frame_rate_hz, scenario.frames) == (2, 6.25, 15)
    world = build_world(scenario, np.random.default_rng(0))
    # The virtual camera's whole-frame view at zoom 1 has the recording's field of view at 160 px.
    assert world.camera.f_min_px == pytest.approx(
        np.mean(load_pinhole(tmp_path / "c.json").K.diagonal()[:2]) * 160 / 1024
    )
    # The annotated people land where the scaled calibration puts them: the ideal detector sees them.
    episode = run_episode(scenario, "fix", 0)
    assert sum(len(found) for found in episode.detections) > 0
    follow = dataset_scenario(load_dataset(path), "cam", FOLLOW_PROTOCOL, path)
    assert (follow.recording.frame_step, follow.frame_rate_hz, follow.frames) == (1, 12.5, 30)
    assert follow.camera.image_size_px == (640, 360)


def test_a_step_rate_the_recording_gives_is_not_warned_of(tmp_path, caplog):
    path = _recording(tmp_path, (768, 576), 15.0)
    with caplog.at_level(logging.WARNING):
        scenario = dataset_scenario(load_dataset(path))
    assert caplog.records == [] and scenario.recording.frame_step == 3 and scenario.frame_rate_hz == 5.0
    assert scenario.frames == math.ceil(30 / 3)


def test_the_recordings_checks_come_before_any_work(tmp_path):
    path = _recording(tmp_path, (768, 576), 10.0)
    shutil.copy(tmp_path / "gt.txt", tmp_path / "gt_late.txt")
    with open(tmp_path / "gt.txt", "a") as rows:
        rows.write("31,1,10,10,5,10,1,-4,-7,0\n")
    with pytest.raises(DatasetError, match=r"gt.txt: line \d+: frame 31 is beyond the 30 frames of"):
        dataset_scenario(load_dataset(path))
    with pytest.raises(ScenarioError, match="no view 'other' \\(views: cam\\)"):
        dataset_scenario(load_dataset(path), "other")


def test_the_dataset_views_own_boxes_drive_the_camera_and_land_on_the_people():
    """View_001's shipped boxes through the ``detections`` detector: at the whole-frame view, each box's feet
    land on an annotated person's projected feet (most within 2 px of the 160 px view)."""
    scenario = pets_scenario("detections", frames=5)
    world = build_world(scenario, np.random.default_rng(0))
    pose = world.grid.poses[world.start_action]
    calibration = load_pinhole(scenario.recording.calibration, "View_001")
    annotations = world.backend.scene.annotations
    distances = []
    for step in range(5):
        found = world.detector.detect(world.backend, step, pose, np.random.default_rng(0))
        people = annotations.select(annotations.frame == world.backend.scene.video_frame[step])
        feet_px = world.backend.virtual.recorded_to_virtual(
            project_pinhole(calibration, np.c_[people.ground_m * 1000, np.zeros(len(people.frame))]), pose
        )
        distances += [np.linalg.norm(feet_px - feet, axis=1).min() for feet in found.feet_px]
    assert len(distances) >= 10 and np.median(distances) < 2.0
