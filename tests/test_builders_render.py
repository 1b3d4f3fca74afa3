"""A scenario rendered into a dataset: the files read back as a dataset, the truth and the boxes agree with
the calibration, the same seed writes the same bytes, and nothing is ever half-written."""

import json

import cv2
import numpy as np
import pytest

from ptztrack.builders.render import render_dataset, rendered_truth, rendered_views
from ptztrack.config import ScenarioError, load_dataset, scenario_from_dict
from ptztrack.files import InputError
from ptztrack.geometry.calibration import load_pinhole, project_pinhole
from ptztrack.scene.pets import load_mot_ground_truth

SMALL = {
    "area_m": [10.0, 8.0],
    "frames": 10,
    "frame_rate_hz": 12.5,
    "people": {"count": 2},
    "camera": {"position_m": [5.0, -2.0, 4.0], "image_size_px": [320, 180], "f_min_px": 200.0},
}
SEED = 3


@pytest.fixture(scope="module")
def small():
    return scenario_from_dict(SMALL)


@pytest.fixture(scope="module")
def rendered(small, tmp_path_factory):
    """The small scenario rendered once: the dataset file's path."""
    return render_dataset(small, tmp_path_factory.mktemp("a") / "small", SEED)


def test_the_dataset_file_reads_back_and_names_every_file_beside_it(rendered):
    dataset = load_dataset(rendered)
    assert dataset.frame_rate_hz == 12.5 and dataset.frames == 10
    assert dataset.area_m == ((0.0, 0.0), (10.0, 8.0))
    (view,) = dataset.views
    assert view.name == "camera_1" and view.calibration_view == "camera_1" and view.image_size_px == (320, 180)
    assert view.video == str(rendered.parent / "camera_1.avi")
    assert view.ground_truth == dataset.ground_truth == str(rendered.parent / "gt_camera_1.txt")
    assert sorted(path.name for path in rendered.parent.iterdir()) == [
        "calibration.json",
        "camera_1.avi",
        "dataset.yaml",
        "gt_camera_1.txt",
    ]


def test_the_video_has_every_frame_at_the_image_size(rendered):
    capture = cv2.VideoCapture(str(rendered.parent / "camera_1.avi"))
    frames = []
    while (read := capture.read())[0]:
        frames.append(read[1])
    assert len(frames) == 10 and frames[0].shape == (180, 320, 3)
    assert capture.get(cv2.CAP_PROP_FPS) == pytest.approx(12.5)


def test_the_ground_truth_is_the_truth_and_its_boxes_stand_on_the_calibrated_feet(small, rendered):
    truth = rendered_truth(small, SEED)
    annotations = load_mot_ground_truth(rendered.parent / "gt_camera_1.txt")
    calibration = load_pinhole(rendered.parent / "calibration.json", "camera_1")
    # Every person is in view here, every frame.
    assert len(annotations.frame) == truth.positions_m.shape[0] * truth.positions_m.shape[1]
    expected_m = truth.positions_m[annotations.frame, annotations.person_id - 1]
    assert annotations.ground_m == pytest.approx(expected_m, abs=1e-6)
    ground_mm = 1000.0 * np.c_[annotations.ground_m, np.zeros(len(annotations.frame))]
    assert np.abs(annotations.feet_px - project_pinhole(calibration, ground_mm)).max() < 0.01
    heads_mm = ground_mm + np.c_[np.zeros((len(ground_mm), 2)), 1000.0 * truth.heights_m[annotations.person_id - 1]]
    head_v = project_pinhole(calibration, heads_mm)[:, 1]
    assert annotations.box_px[:, 1] == pytest.approx(head_v, abs=0.01)
    # The boxes are about as wide as the people: width / height = width_m / height_m, roughly.
    ratio = annotations.box_px[:, 2] / annotations.box_px[:, 3]
    assert ratio == pytest.approx(0.62 / truth.heights_m[annotations.person_id - 1], rel=0.15)


def test_the_people_are_drawn_inside_their_boxes(rendered):
    annotations = load_mot_ground_truth(rendered.parent / "gt_camera_1.txt")
    capture = cv2.VideoCapture(str(rendered.parent / "camera_1.avi"))
    ok, first = capture.read()
    assert ok
    for left, top, width, height in annotations.box_px[annotations.frame == 0]:
        inside = first[int(top) : int(top + height), int(left) : int(left + width)].astype(float)
        beside = first[int(top) : int(top + height), int(left + width) + 2 : int(left + 2 * width)].astype(float)
        assert np.abs(inside - beside.mean(axis=(0, 1))).mean() > np.abs(beside - beside.mean(axis=(0, 1))).mean()


def test_the_same_seed_writes_the_same_bytes_and_another_seed_other_ones(small, rendered, tmp_path):
    (tmp_path / "same").mkdir()
    (tmp_path / "other").mkdir()
    again = render_dataset(small, tmp_path / "same" / "small", SEED)
    for path in rendered.parent.iterdir():
        assert (again.parent / path.name).read_bytes() == path.read_bytes(), path.name
    other = render_dataset(small, tmp_path / "other" / "small", SEED + 1)
    for name in ("camera_1.avi", "gt_camera_1.txt"):
        assert (other.parent / name).read_bytes() != (rendered.parent / name).read_bytes()
    assert (other.parent / "calibration.json").read_bytes() == (rendered.parent / "calibration.json").read_bytes()


def test_a_folder_that_is_not_empty_is_refused_and_left_as_it_was(small, tmp_path):
    folder = tmp_path / "taken"
    folder.mkdir()
    (folder / "notes.txt").write_text("mine")
    with pytest.raises(InputError, match="not empty"):
        render_dataset(small, folder, SEED)
    assert [path.name for path in folder.iterdir()] == ["notes.txt"]
    assert (folder / "notes.txt").read_text() == "mine"
    assert [path.name for path in tmp_path.iterdir()] == ["taken"]  # no temporary folder left beside it
    render_dataset(small, folder, SEED, overwrite=True)
    assert sorted(path.name for path in folder.iterdir())[0] == "calibration.json"


def test_a_failure_leaves_no_folder(small, tmp_path, monkeypatch):
    def fail(*args, **kwargs):
        raise RuntimeError("disk full")

    monkeypatch.setattr("ptztrack.builders.render._ground_truth_rows", fail)
    with pytest.raises(RuntimeError, match="disk full"):
        render_dataset(small, tmp_path / "out", SEED)
    assert list(tmp_path.iterdir()) == []


def test_every_camera_of_a_network_is_a_view_with_its_own_image_and_boxes(tmp_path):
    scenario = scenario_from_dict(
        {
            **SMALL,
            "frames": 3,
            "cameras": [
                {"position_m": [5.0, -2.0, 4.0]},
                {"position_m": [12.0, 4.0, 3.0], "image_size_px": [240, 160], "f_min_px": 150.0},
            ],
        }
    )
    views = rendered_views(scenario)
    assert [view.name for view in views] == ["camera_1", "camera_2"]
    assert [view.image_size_px for view in views] == [(320, 180), (240, 160)]
    assert views[1].calibration.K[0, 0] == 150.0
    path = render_dataset(scenario, tmp_path / "two", 0)
    dataset = load_dataset(path)
    assert [view.name for view in dataset.views] == ["camera_1", "camera_2"]
    assert dataset.ground_truth == dataset.views[0].ground_truth
    calibrations = json.loads((path.parent / "calibration.json").read_text())
    assert sorted(calibrations) == ["camera_1", "camera_2"]
    for view in views:
        annotations = load_mot_ground_truth(path.parent / f"gt_{view.name}.txt")
        ground_mm = 1000.0 * np.c_[annotations.ground_m, np.zeros(len(annotations.frame))]
        assert np.abs(annotations.feet_px - project_pinhole(view.calibration, ground_mm)).max() < 0.01
        width_px, height_px = view.image_size_px
        assert np.all((annotations.feet_px >= 0) & (annotations.feet_px <= [width_px, height_px]))


def test_a_scenario_with_a_recording_is_refused(tmp_path, excerpt_scenario):
    with pytest.raises(ScenarioError, match="render takes a scenario without one"):
        render_dataset(excerpt_scenario(tmp_path), tmp_path / "out", 0)
    assert not (tmp_path / "out").exists()


def test_an_unknown_look_is_refused(small, tmp_path):
    with pytest.raises(ValueError, match="cones, pets-cutouts"):
        render_dataset(small, tmp_path / "out", 0, people_look="statues")


@pytest.mark.slow
def test_pets_pedestrians_can_stand_in_for_the_cones(small, rendered, tmp_path):
    path = render_dataset(small, tmp_path / "small", SEED, people_look="pets-cutouts")
    assert (path.parent / "gt_camera_1.txt").read_bytes() == (rendered.parent / "gt_camera_1.txt").read_bytes()
    cones, cutouts = (
        cv2.VideoCapture(str(folder / "camera_1.avi")).read()[1] for folder in (rendered.parent, path.parent)
    )
    annotations = load_mot_ground_truth(path.parent / "gt_camera_1.txt")
    outside = np.ones(cones.shape[:2], dtype=bool)
    for left, top, width, height in annotations.box_px[annotations.frame == 0]:
        outside[max(int(top) - 2, 0) : int(top + height) + 3, max(int(left) - 2, 0) : int(left + width) + 3] = False
        person = cutouts[int(top) : int(top + height), int(left) : int(left + width)].astype(float)
        assert np.abs(person - cones[int(top) : int(top + height), int(left) : int(left + width)]).mean() > 10
    # Around the people the two renders are the same scene (up to the video's compression).
    assert np.abs(cutouts[outside].astype(float) - cones[outside]).mean() < 3
