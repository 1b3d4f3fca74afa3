import json
from dataclasses import replace
from pathlib import Path

import cv2
import numpy as np
import pytest

from ptztrack.cli import main
from ptztrack.config import dataset_from_dict
from ptztrack.experiments.occupancy import format_occupancy_table
from ptztrack.geometry.calibration import project_pinhole
from ptztrack.occupancy.evaluation import (
    PooledDetectors,
    detection_metrics,
    fitted_prior,
    fitted_selection,
    fitted_variant_selection,
    halves,
    merged_scores,
    track_on_ground,
)
from ptztrack.occupancy.lpom import Modes
from ptztrack.occupancy.room import RoomLayout, RoomRenderer, room_truth
from test_track_ground import PARAMETERS as GROUND_TRACKER

PETS = Path(__file__).resolve().parents[1] / "src" / "ptztrack" / "data" / "pets2009_s2l1"
NAN = np.nan


def test_detection_metrics_count_matches_within_the_radius_one_to_one():
    truth = np.array([[[0.0, 0.0], [3.0, 0.0], [NAN, NAN]], [[0.0, 0.0], [NAN, NAN], [NAN, NAN]]])
    found = [np.array([[0.1, 0.0], [0.0, 0.2], [3.6, 0.0]]), np.zeros((0, 2))]
    metrics = detection_metrics(truth, found)
    # Frame 0: (0,0) matched at 0.1 m, the other detection near it is a false positive, (3,0) is 0.6 m
    # from its detection: a miss and a false positive. Frame 1: a miss.
    assert (metrics["matches"], metrics["false_positives"], metrics["misses"], metrics["objects"]) == (1, 2, 2, 3)
    assert metrics["moda"] == pytest.approx(1 - 4 / 3)
    assert metrics["modp"] == pytest.approx(1 - 0.1 / 0.5)
    assert metrics["precision"] == pytest.approx(1 / 3) and metrics["recall"] == pytest.approx(1 / 3)
    assert metrics["error_m"] == pytest.approx(0.1)


def test_poms_prior_is_the_mean_share_of_occupied_cells_in_the_fitting_frames():
    truth = np.full((4, 3, 2), np.nan)
    truth[0, :2] = truth[1, :1] = truth[2, :3] = 1.0  # 2, 1, 3 and 0 people: 1.5 a frame
    assert fitted_prior(truth, cells=100) == pytest.approx(0.015)
    # Nobody at all: one person over the frames, not a prior of 0 (no cell could ever be occupied).
    assert fitted_prior(np.full((4, 3, 2), np.nan), cells=100) == pytest.approx(0.25 / 100)


def test_a_figure_without_a_value_is_shown_as_n_a_never_nan():
    """No match makes MODP and the mean error undefined; the clustering row has no tracking figures."""
    nothing_matched = detection_metrics(np.array([[[0.0, 0.0]]]), [np.array([[9.0, 9.0]])])
    rows = [
        {"method": "lpom", "dataset": "d", **nothing_matched, "mota": -1.0, "motp_m": NAN, "idf1": 0.0},
        {"method": "clustering", "dataset": "d", **nothing_matched},
    ]
    table = format_occupancy_table("d", rows)
    lpom, clustering = table.splitlines()[2:4]
    assert lpom.split() == ["lpom", "-100.0%", "n/a", "0.0%", "0.0%", "n/a", "-100.0%", "n/a", "0.0%"]
    assert clustering.split() == ["clustering", "-100.0%", "n/a", "0.0%", "0.0%", "n/a"]
    assert "nan" not in table


def test_each_half_is_scored_with_the_threshold_fitted_on_the_other():
    truth = np.zeros((4, 1, 2))
    positions = [np.array([[0.0, 0.0], [2.0, 2.0]])] * 4
    # First half: the ghost is weaker than the person; second half: stronger. Fitting on the second half
    # keeps everything up to its person's 0.3 (and the first half's ghost at 0.2 is kept too).
    scores = [np.array([0.9, 0.2]), np.array([0.9, 0.2]), np.array([0.3, 0.5]), np.array([0.3, 0.5])]
    kept, fitted, recall = fitted_selection(truth, [scores] * 2, [positions] * 2, (0.1, 0.25, 0.4, 0.6))
    assert fitted == [0.1, 0.25]
    np.testing.assert_array_equal(recall, [1.0, 1.0, 1.0, 1.0])  # each half's threshold finds the person
    assert [k.tolist() for k in kept] == [[True, True], [True, True], [True, True], [True, True]]
    assert [(scored.tolist(), fitting.tolist()) for scored, fitting in halves(5)] == [
        ([0, 1], [2, 3, 4]),
        ([2, 3, 4], [0, 1]),
    ]


def test_a_mode_is_kept_unless_too_few_views_see_it_or_a_kept_stronger_one_is_within_the_radius():
    # Strongest first: b is 0.6 m from a; c is 0.6 m from b (suppressed) and 1.2 m from a.
    modes = Modes(np.array([[0.0, 0.0], [0.6, 0.0], [1.2, 0.0]]), np.zeros((3, 2, 2)), np.array([0.9, 0.8, 0.7]))
    np.testing.assert_array_equal(merged_scores(modes, 0.5), [0.9, 0.8, 0.7])
    np.testing.assert_array_equal(merged_scores(modes, 1.0), [0.9, -np.inf, 0.7])
    np.testing.assert_array_equal(merged_scores(modes, 1.5), [0.9, -np.inf, -np.inf])
    assert len(merged_scores(Modes.empty(), 1.0)) == 0
    # a needs 3 views and has 2: dropped, so it suppresses nobody and b is kept.
    seen = Modes(modes.position_m, modes.covariance_m2, modes.strength, np.array([2, 3, 5]))
    np.testing.assert_array_equal(merged_scores(seen, 1.0, min_views=3), [-np.inf, 0.8, -np.inf])
    np.testing.assert_array_equal(merged_scores(seen, 1.0, min_views=2), [0.9, -np.inf, 0.7])


def test_the_merging_radius_and_threshold_are_fitted_together_on_the_other_half():
    """Two frames per half. In the first half one person is lit twice (0.6 m apart), in the second two
    people stand 0.6 m apart: merging over 1 m is best on the first half and so scores the second
    (losing a person), keeping both is best on the second and so scores the first (a false positive)."""
    one = np.array([[[0.0, 0.0], [NAN, NAN]]] * 2)
    two = np.array([[[0.0, 0.0], [0.6, 0.0]]] * 2)
    truth = np.concatenate([one, two])
    modes = Modes(np.array([[0.0, 0.0], [0.6, 0.0]]), np.zeros((2, 2, 2)), np.array([0.9, 0.8]))
    variants = [[[merged_scores(modes, radius_m)] * 4] * 2 for radius_m in (0.375, 1.0)]
    kept, fitted, recall = fitted_variant_selection(truth, variants, [[modes.position_m] * 4] * 2, (0.1, 0.5))
    assert fitted == [(0, 0.1), (1, 0.1)]
    assert [k.tolist() for k in kept] == [[True, True]] * 2 + [[True, False]] * 2
    np.testing.assert_array_equal(recall, [1.0, 1.0, 1.0, 1.0])


def test_pooled_settings_are_tagged_and_each_merges_only_among_its_own_modes():
    """Two settings' modes pooled: the first's map, every mode tagged with its setting; merging over 1 m
    for setting 1 keeps its own mode 0.6 m from setting 0's stronger one and drops setting 0's."""

    class Fixed:
        def __init__(self, occupancy, modes):
            self.found = occupancy, modes

        def detect(self, frame):
            return self.found

    wide = Modes(np.array([[0.0, 0.0]]), np.zeros((1, 2, 2)), np.array([0.9]), np.array([4]))
    narrow = Modes(np.array([[0.6, 0.0], [3.0, 0.0]]), np.zeros((2, 2, 2)), np.array([0.8, 0.7]), np.array([4, 2]))
    occupancy, pooled = PooledDetectors([Fixed(np.ones((2, 2)), wide), Fixed(np.zeros((2, 2)), narrow)]).detect(0)
    np.testing.assert_array_equal(occupancy, np.ones((2, 2)))
    np.testing.assert_array_equal(pooled.variant, [0, 1, 1])
    np.testing.assert_array_equal(pooled.views, [4, 4, 2])
    np.testing.assert_array_equal(merged_scores(pooled, 1.0, variant=1), [-np.inf, 0.8, 0.7])
    np.testing.assert_array_equal(merged_scores(pooled, 1.0, min_views=3, variant=1), [-np.inf, 0.8, -np.inf])
    np.testing.assert_array_equal(merged_scores(pooled, 1.0, variant=0), [0.9, -np.inf, -np.inf])


def write_room_dataset(directory: Path, frames: int = 8, seed: int = 5) -> Path:
    """A small synthetic room in the generic format: image folders, a pinhole JSON, ground truth, and one
    view given only by boxes (the truth's, projected)."""
    layout = RoomLayout(image_size_px=(320, 240), focal_px=156.0)
    truth = room_truth(layout, 1, frames, seed)
    renderer = RoomRenderer(layout, truth, seed)
    calibrations = {}
    for view, camera in enumerate(renderer.cameras):
        name = f"camera_{view + 1}"
        calibrations[name] = {
            "K": camera.K.tolist(),
            "dist": camera.dist.tolist(),
            "R": camera.R.tolist(),
            "t": camera.t.tolist(),
        }
        (directory / name).mkdir()
        for frame in range(frames):
            cv2.imwrite(str(directory / name / f"{frame:04d}.png"), renderer.image(view, frame))
    (directory / "cameras.json").write_text(json.dumps(calibrations))
    x, y = truth.positions_m[:, 0].T
    rows = [f"{f + 1},1,-1,-1,-1,-1,1,{float(x[f])!r},{float(y[f])!r},0" for f in range(frames)]
    (directory / "gt.txt").write_text("\n".join(rows) + "\n")
    feet = project_pinhole(renderer.cameras[0], np.stack([x, y, 0 * x], -1) * 1000)
    head = project_pinhole(renderer.cameras[0], np.stack([x, y, 0 * x + truth.heights_m[0]], -1) * 1000)
    height = feet[:, 1] - head[:, 1]
    boxes = [
        f"{f + 1},-1,{feet[f, 0] - 0.15 * height[f]},{head[f, 1]},{0.3 * height[f]},{height[f]},0.9,-1,-1,-1"
        for f in range(frames)
    ]
    (directory / "boxes.txt").write_text("\n".join(boxes) + "\n")
    views = "".join(f"  - {{name: camera_{v}, calibration: cameras.json, images: camera_{v}}}\n" for v in (1, 2, 3, 4))
    views += "  - {name: boxes, calibration: cameras.json, calibration_view: camera_1, detections: boxes.txt}\n"
    path = directory / "room.yaml"
    path.write_text(
        f"name: small-room\nframe_rate_hz: 15\narea_m: [[0, 0], [5, 6]]\nground_truth: gt.txt\nviews:\n{views}"
        "occupancy: {cell_m: 0.1, kernel_sigma_m: 0.15}\n"
    )
    return path


def test_a_dataset_in_the_generic_format_runs_and_writes_its_outputs(tmp_path, capsys):
    path = write_room_dataset(tmp_path)
    out, rows_path = tmp_path / "out", tmp_path / "rows.json"
    assert (
        main(["experiment", "occupancy", str(path), "--json", str(rows_path), "--out", str(out), "--images-every", "4"])
        == 0
    )
    rows = json.loads(rows_path.read_text())
    # Its boxes-only view has no image size, which POM's rectangles need.
    assert [row["method"] for row in rows] == ["lpom", "lpom-foreground", "clustering"]
    for row in rows:
        assert {"moda", "modp", "precision", "recall", "error_m"} <= set(row) and row["views"] == 5
    assert {"mota", "motp_m", "idf1"} <= set(rows[0])
    assert rows[0]["recall"] > 0.5
    written = out / "small-room"
    assert {p.name for p in written.iterdir()} >= {
        "metrics.json",
        "detections.csv",
        "tracks.csv",
        "maps",
        "occupancy.mp4",
    }
    assert sorted(p.name for p in (written / "maps").iterdir()) == ["frame_00000.png", "frame_00004.png"]
    assert "lpom" in capsys.readouterr().out


def test_a_malformed_dataset_file_exits_2_with_one_line_naming_file_and_field(tmp_path, capfd):
    path = tmp_path / "bad.yaml"
    path.write_text("frame_rate_hz: 10\nviews: [\n")
    assert main(["experiment", "occupancy", str(path)]) == 2  # the command itself: no traceback
    stderr = capfd.readouterr().err
    lines = stderr.strip().splitlines()
    assert "Traceback" not in stderr and len(lines) == 1, stderr
    line = lines[0]
    assert str(path) in line and "not valid YAML" in line, line
    area = "frame_rate_hz: 10\narea_m: [[0, 0], [1, 1]]\n"
    for text, expected in (
        (area + "views: [{name: a, video: v.avi, calibration: c.xml}]\nviewz: 1\n", "viewz: unknown key"),
        (area + "views: []\n", "views: List should have at least 1 item"),
        (area + "views: [{name: a, video: v.avi}]\n", "views.0.calibration: Field required"),
        (
            area + "views: [{name: a, calibration: c.xml}]\n",
            "views.0: a view needs video, images or detections",
        ),
    ):
        path.write_text(text)
        assert main(["experiment", "occupancy", str(path)]) == 2
        lines = capfd.readouterr().err.strip().splitlines()
        assert len(lines) == 1 and str(path) in lines[0] and expected in lines[0], lines


def test_a_missing_view_exits_2_naming_the_file(tmp_path, capsys):
    path = write_room_dataset(tmp_path, frames=2)
    path.write_text(path.read_text().replace("calibration_view: camera_1", "calibration_view: camera_9"))
    assert main(["experiment", "occupancy", str(path)]) == 2
    line = capsys.readouterr().err.strip()
    assert "cameras.json" in line and "no view 'camera_9'" in line
    path.write_text(path.read_text().replace("images: camera_2", "images: camera_22"))
    assert main(["experiment", "occupancy", str(path)]) == 2
    assert "camera_22: no such image folder" in capsys.readouterr().err


def test_a_calibration_of_the_wrong_size_exits_2_naming_file_and_field(tmp_path, capsys):
    path = tmp_path / "pets.yaml"
    path.write_text(
        "frame_rate_hz: 10\narea_m: [[-20, -17], [8, 8]]\nviews:\n"
        f"  - {{name: View_001, calibration: {PETS / 'View_001.xml'}, image_size_px: [720, 576], "
        f"detections: {PETS / 'View_001_det.txt.gz'}}}\n"
    )
    assert main(["experiment", "occupancy", str(path)]) == 2
    line = capsys.readouterr().err.strip()
    assert "View_001.xml" in line and "views.0.image_size_px" in line and "768x576" in line
    room = write_room_dataset(tmp_path / "room", frames=2) if (tmp_path / "room").mkdir() is None else None
    assert room is not None
    room.write_text(room.read_text().replace("images: camera_3}", "images: camera_3, image_size_px: [640, 480]}"))
    assert main(["experiment", "occupancy", str(room)]) == 2
    line = capsys.readouterr().err.strip()
    assert "cameras.json" in line and "views.2" in line and "640x480" in line and "320x240" in line


@pytest.mark.slow
def test_the_synthetic_room_meets_the_papers_accuracy(tmp_path):
    """Acceptance: mean position error <= 0.08 m with 1 and with 3 people, MODA >= 90 %, over the first
    100 frames of each sequence (the detector-and-clustering baseline misses the error bound there)."""
    rows_path = tmp_path / "room.json"
    command = ["experiment", "occupancy", "synthetic-room", "--frames", "100", "--methods", "--json", str(rows_path)]
    assert main(command) == 0
    rows = json.loads(rows_path.read_text())
    lpom = {row["people"]: row for row in rows if row["method"] == "lpom"}
    assert sorted(lpom) == [1, 3] and {row["people"] for row in rows if row["method"] == "clustering"} == {1, 3}
    for row in lpom.values():
        assert row["error_m"] <= 0.08 and row["moda"] >= 0.9, row


@pytest.mark.slow
def test_pets_runs_with_seven_views(tmp_path):
    rows_path = tmp_path / "pets.json"
    assert main(["experiment", "occupancy", "pets", "--frames", "20", "--json", str(rows_path)]) == 0
    rows = json.loads(rows_path.read_text())
    assert [row["method"] for row in rows] == ["lpom", "lpom-foreground", "pom", "clustering"]
    assert all(row["views"] == 7 and row["frames"] == 20 for row in rows) and "mota" in rows[0]
    # POM's person width, radius and views are fitted on each half, from the choices.
    pom = rows[2]
    assert len(pom["fitted_width_m"]) == 2 and set(pom["fitted_width_m"]) <= {0.5, 0.4, 0.3}
    # View_001 has video and boxes: its mask is fitted too. The six views with boxes alone have their
    # rectangles scaled to their boxes; View_001's only where its boxes make its mask.
    assert len(pom["fitted_masks"]) == 2 and set(pom["fitted_masks"]) <= {"silhouettes", "boxes"}
    for masks, scales in zip(pom["fitted_masks"], pom["fitted_box_scales"], strict=True):
        assert np.shape(scales) == (7, 2) and not np.allclose(scales[1:], 1.0)
        assert np.allclose(scales[0], 1.0) == (masks == "silhouettes")
    assert len(pom["fitted_merge_radius_m"]) == 2 and len(pom["fitted_min_views"]) == 2
    # Every view has boxes: the candidates are localized by their feet, each view's spread fitted per half.
    assert np.shape(pom["fitted_feet_sd_m"]) == (2, 7)
    assert all(sd is None or 0 < sd < 1.0 for half in pom["fitted_feet_sd_m"] for sd in half)
    assert any(sd is not None for half in pom["fitted_feet_sd_m"] for sd in half)


def test_a_partial_tracker_section_keeps_the_occupancy_trackers_confirmation():
    data = {
        "frame_rate_hz": 10,
        "area_m": [[0, 0], [1, 1]],
        "views": [{"name": "a", "calibration": "c.xml", "video": "v"}],
    }
    assert dataset_from_dict(data).tracker.confirmation_hits == 2
    assert dataset_from_dict({**data, "tracker": {"gate_probability": 0.95}}).tracker.confirmation_hits == 2
    assert dataset_from_dict({**data, "tracker": {"confirmation_hits": 1}}).tracker.confirmation_hits == 1


def test_a_track_beside_another_keeps_its_existence_through_misses_that_a_lone_track_dies_of():
    """Two people 0.3 m apart (closer than the map's 0.5 m separation) and one 3 m away are seen for
    two frames, then the map finds only the first: the lone one's misses delete it (recall 0.9: 0.99
    falls to 0.908, 0.497, then 0.090, below 0.1), the one beside the first, which cannot have a mode
    of its own, lives on."""
    people_m = np.array([[0.0, 0.0], [0.3, 0.0], [3.0, 0.0]])
    covariance = np.broadcast_to(0.01 * np.eye(2), (3, 2, 2))
    seen = Modes(people_m, covariance, np.ones(3))
    first = Modes(people_m[:1], covariance[:1], np.ones(1))
    frames = [seen, seen, first, first, first]
    reported = track_on_ground(frames, np.full(5, 0.9), 0.5, 10.0, replace(GROUND_TRACKER, acceleration_sigma_m_s2=0.5))
    assert [sorted(tracks.ids.tolist()) for tracks in reported] == [[0, 1, 2]] * 4 + [[0, 1]]
