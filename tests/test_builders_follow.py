"""The follow camera built from a scenario, run on the PETS test excerpt, and its command line."""

import json
from pathlib import Path

import numpy as np
import pytest

from ptztrack.builders.follow import framing_parameters, initial_box, target_scenario
from ptztrack.builders.recording import pets_follow_scenario
from ptztrack.cli import main
from ptztrack.config import ScenarioError, scenario_from_dict
from ptztrack.experiments.follow import FollowCell, follow_row, follow_run
from ptztrack.geometry.ptz import project_people

EXCERPT = Path(__file__).parent / "data" / "pets_s2l1_excerpt"
FILES = {"video": EXCERPT / "View_001.avi", "ground_truth": EXCERPT / "gt_mot15.txt"}
FILES["calibration"] = EXCERPT / "pinhole.json"
RECORDING_ARGUMENTS = ["--video", str(FILES["video"]), "--gt", str(FILES["ground_truth"])]
RECORDING_ARGUMENTS += ["--calibration", str(FILES["calibration"])]


def excerpt_scenario(tracker="particle", frames=8, **overrides):
    recording = {f"recording.{key}": str(path) for key, path in FILES.items()}
    return pets_follow_scenario(tracker, frames=frames, **recording, **overrides)


def test_a_person_narrows_the_steps_and_the_camera_starts_framing_them():
    scenario = target_scenario(excerpt_scenario(frames=795), 11)
    assert scenario.follow.target_id == 11
    assert scenario.recording.frame_range == (16, 30) and scenario.frames == 14  # person 11: frames 16-29
    shorter = target_scenario(excerpt_scenario(frames=5), 11)
    assert shorter.frames == 5
    cell = FollowCell(excerpt_scenario("csrt", frames=1), "csrt", 9)
    narrowed, world, _ = follow_run(cell)
    box_px, start_pose = initial_box(narrowed, world)
    parameters = framing_parameters(narrowed, world.camera)
    # The start pose frames person 9 as the controller wants: middle at (x*, y*), 160 px tall.
    np.testing.assert_allclose(box_px[:2] + box_px[2:] / 2, parameters.target_point_px, atol=8.0)
    first_m = world.truth.positions_m[0, np.searchsorted(world.backend.scene.person_id, 9)]
    person = project_people(world.camera, start_pose, first_m[None], 1.75, 0.5)
    assert person.height_px[0] == pytest.approx(160.0, rel=1e-6)


def test_an_unknown_person_is_one_line_naming_the_file_and_the_people():
    with pytest.raises(ScenarioError, match=r"gt_mot15.txt: no person 99 \(the people are 9, 11, 12, 15, 19\)"):
        target_scenario(excerpt_scenario(), 99)


@pytest.mark.parametrize(
    "follow, message",
    [
        ({"patches": [[0.5, 0.0, 0.6, 0.2]]}, "patch 0 [0.5, 0.0, 0.6, 0.2] reaches outside the box"),
        ({"loss_fraction": 0.7}, "adapt_fraction (0.6) must be above loss_fraction (0.7)"),
        ({"zoom_range": [4, 2]}, "zoom_range must be [lowest, highest]"),
        ({"particles": 0}, "follow.particles: Input should be greater than or equal to 1"),
    ],
)
def test_bad_follow_sections_are_one_line_naming_the_field(follow, message):
    with pytest.raises(ScenarioError, match=message.replace("[", r"\[").replace("(", r"\(").replace(")", r"\)")):
        scenario_from_dict({"follow": follow})


def test_a_target_point_outside_the_image_is_refused():
    scenario = excerpt_scenario(**{"follow.target_point_px": (700, 10)})
    with pytest.raises(ScenarioError, match=r"follow.target_point_px: \[700.0, 10.0\] lies outside the 640 x 480"):
        target_scenario(scenario, 9)


@pytest.mark.parametrize("tracker", ["particle", "csrt", "mil"])
def test_each_tracker_follows_a_person_of_the_excerpt(tracker):
    narrowed, world, episode = follow_run(FollowCell(excerpt_scenario(tracker), tracker, 9))
    row = follow_row(narrowed, world, episode)
    assert row["tracker"] == tracker and row["steps"] == row["annotated_steps"] == 8
    assert row["in_view_fraction"] == 1.0 and row["target_point_error"] < 0.05
    assert row["lost_steps"] == 0 and row["ground_error_m"] < 1.0
    assert row["jitter_deg"] <= 30.0 * 0.1**2  # the acceleration limit


def test_the_particle_filters_run_is_fixed_by_its_seed():
    def commanded(seed):
        return follow_run(FollowCell(excerpt_scenario(frames=6), "particle", 9, seed))[2].commanded

    np.testing.assert_array_equal(commanded(0), commanded(0))
    assert not np.array_equal(commanded(0), commanded(1))


def test_follow_writes_the_episode_video_and_metrics(tmp_path, capsys):
    out = tmp_path / "follow"
    assert main(["follow", "--target", "19", "--frames", "6", "--out", str(out), *RECORDING_ARGUMENTS]) == 0
    assert "in_view_fraction" in capsys.readouterr().out
    metrics = json.loads((out / "metrics.json").read_text())
    assert {"in_view_fraction", "target_point_error", "losses", "jitter_deg", "height_sd_ratio"} <= set(metrics)
    assert (out / "episode.mp4").stat().st_size > 0


def test_following_an_unknown_person_exits_2_with_one_line(tmp_path, capsys):
    assert main(["follow", "--target", "99", "--out", str(tmp_path / "x"), *RECORDING_ARGUMENTS]) == 2
    error = capsys.readouterr().err
    assert error.count("\n") == 1 and error.startswith("ptztrack: error: ") and "no person 99" in error
    assert not (tmp_path / "x").exists()


@pytest.mark.slow
def test_the_follow_experiment_writes_closed_loop_and_one_pass_rows(tmp_path, capsys):
    path = tmp_path / "follow.json"
    arguments = ["experiment", "follow", "--targets", "9", "19", "--otb-tracks", "1", "--executor", "serial"]
    assert main([*arguments, "--json", str(path), *RECORDING_ARGUMENTS]) == 0
    assert "One-pass (OTB)" in capsys.readouterr().out
    document = json.loads(path.read_text())
    assert [row["tracker"] for row in document["closed_loop"]] == ["particle", "csrt", "mil"]
    for row in document["closed_loop"]:
        keys = {"in_view_fraction", "target_point_error", "losses", "recoveries", "jitter_deg", "height_sd_ratio"}
        assert keys <= set(row) and row["people"] == 2
    assert [row["tracker"] for row in document["otb"]] == ["particle", "csrt", "mil"]
    assert all({"success_auc", "precision_20px", "fps"} <= set(row) for row in document["otb"])
