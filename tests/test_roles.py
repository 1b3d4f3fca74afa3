"""A researcher's own policy, detector and camera backend, written here and run by ptztrack unchanged."""

import json
import os
import subprocess
import sys
import textwrap

import cv2
import numpy as np
import pytest

import ptztrack
from overhead import overhead_scenario
from ptztrack import registry
from ptztrack.builders.episode import run_episode
from ptztrack.cli import main
from ptztrack.config import ScenarioError, scenario_from_dict
from ptztrack.evaluate.metrics import episode_metrics
from ptztrack.experiments.cells import cell_metrics
from ptztrack.experiments.ptz_tables import summarise, synthetic_cells
from ptztrack.geometry.ptz import look_at, project_people
from ptztrack.loop.executors import execute_cells
from ptztrack.types import DecisionContext, Detections

# The drawn-blob detector is about roles, not the scene: the overhead camera of the hand-worked tests.
SCENARIO = overhead_scenario({"frames": 25})
BACKGROUND, PERSON = 200, 40  # grey levels


class DrawnCamera:
    """A camera backend that draws the true people as dark boxes on a grey image, and knows nothing else."""

    def __init__(self, camera, truth):
        self.camera, self.truth = camera, truth

    def image(self, step, pose):
        image = np.full((self.camera.image_height_px, self.camera.image_width_px, 3), BACKGROUND, np.uint8)
        present = self.truth.present[step]
        people = project_people(
            self.camera, pose, self.truth.positions_m[step, present], self.truth.heights_m[present], 0.5
        )
        for (left, top, right, bottom), in_front in zip(people.box_px, people.in_front, strict=True):
            if in_front:
                corners = np.clip(np.round([left, top, right, bottom]), -10_000, 10_000).astype(int)
                cv2.rectangle(image, tuple(corners[:2]), tuple(corners[2:]), (PERSON,) * 3, cv2.FILLED)
        return image

    def people(self, step, pose):
        return None


def drawn_camera(scenario, scene):
    return DrawnCamera(scene.camera, scene.truth)


class DarkBlobDetector:
    """Finds dark blobs wholly inside the image; a blob's feet are the middle of its bottom edge."""

    name = "dark blobs"

    def detect(self, camera, step, pose, rng, believed_pose=None):
        image = camera.image(step, pose)
        dark = (image[..., 0] < (BACKGROUND + PERSON) // 2).astype(np.uint8)
        count, _, stats, _ = cv2.connectedComponentsWithStats(dark)
        left, top, width, height, area = stats[1:count].T
        height_px, width_px = image.shape[:2]
        whole = (left > 0) & (top > 0) & (left + width < width_px) & (top + height < height_px) & (height >= 8)
        feet = np.stack([left + width / 2, top + height], axis=-1)[whole].astype(float)
        return Detections(feet, height[whole].astype(float), np.full(whole.sum(), -1), area[whole].astype(float))


class CentreOfTracks:
    """Looks, at zoom 1, at the reachable view nearest to the middle of the tracks (or stays)."""

    def __init__(self, camera, grid):
        self.camera, self.grid = camera, grid

    def choose(self, context: DecisionContext) -> int:
        if len(context.tracks) == 0:
            return context.current_action
        wanted = look_at(self.camera, context.tracks.mean[:, :2].mean(axis=0), 1.0)
        poses = self.grid.poses[context.reachable]
        return int(context.reachable[np.argmin(np.abs(poses - wanted).sum(axis=1))])


def centre_of_tracks(scenario, world):
    return CentreOfTracks(world.camera, world.grid)


def test_a_policy_detector_and_camera_of_ones_own_run_in_an_episode():
    episode = run_episode(SCENARIO, centre_of_tracks, 4, camera=drawn_camera, detector=DarkBlobDetector())
    metrics = episode_metrics(episode)
    # The drawn people are found where they stand: most are tracked, a few metres at most apart...
    assert metrics["mota"] > 0.5 and metrics["motp_m"] < 0.5
    # ...by this detector (its scores are blob areas) ...
    scores = np.concatenate([detections.score for detections in episode.detections])
    assert len(scores) > 50 and np.all(scores >= 8)
    # ...and the policy only ever looks at zoom 1.
    assert np.all(episode.poses[:, 2] == 1.0)


class Stay:
    def choose(self, context):
        return context.current_action


def test_they_run_in_the_synthetic_experiment_beside_the_papers_strategies():
    strategies = ["fix", centre_of_tracks, Stay()]
    cells = synthetic_cells(SCENARIO, 2, strategies, camera=drawn_camera, detector=DarkBlobDetector())
    rows = execute_cells(cells, cell_metrics, "serial")
    table = {row["label"]: row for row in summarise(rows)}
    assert list(table) == ["fix", "centre_of_tracks", "Stay"]
    assert all(row["zoom"] == 1.0 for row in table.values())
    assert all(row["mota"] > 0.3 for row in rows)
    # Staying at the start, which is fix's view, is fix.
    assert table["Stay"]["mota"] == table["fix"]["mota"]


def test_a_registered_policy_is_a_name_for_the_command_line(capsys):
    registry.register("policies", "stay-here", lambda scenario, world: Stay())
    try:
        assert main(["run", "--policy", "stay-here", "--frames", "5", "--detector", "ideal"]) == 0
        assert "policy stay-here" in capsys.readouterr().out
        with pytest.raises(ValueError, match="taken"):
            registry.register("policies", "stay-here", lambda scenario, world: Stay())
    finally:
        registry.unregister("policies", "stay-here")
    assert "stay-here" not in registry.names("policies")


@pytest.mark.slow
def test_another_package_adds_a_policy_and_a_detector_through_entry_points(tmp_path):
    (tmp_path / "other_package.py").write_text(
        textwrap.dedent(
            """
            from ptztrack.builders.factories import ideal_detector

            class Stay:
                def choose(self, context):
                    return context.current_action

            def make_stay(scenario, world):
                return Stay()

            def make_detector(scenario, scene):
                assert scenario.detector.options == {"sharpness": 3}
                return ideal_detector(scenario, scene)
            """
        )
    )
    dist_info = tmp_path / "other_package-1.0.dist-info"
    dist_info.mkdir()
    (dist_info / "METADATA").write_text("Metadata-Version: 2.1\nName: other-package\nVersion: 1.0\n")
    (dist_info / "entry_points.txt").write_text(
        "[ptztrack.policies]\nstay = other_package:make_stay\n\n"
        "[ptztrack.detectors]\nother = other_package:make_detector\n"
    )
    (tmp_path / "scenario.yaml").write_text("frames: 6\ndetector: {kind: other, options: {sharpness: 3}}\n")
    environment = {**os.environ, "PYTHONPATH": str(tmp_path)}
    command = [sys.executable, "-m", "ptztrack.cli", "run", "--policy", "stay", "--scenario", "scenario.yaml"]
    result = subprocess.run(command, capture_output=True, text=True, cwd=tmp_path, env=environment)
    assert result.returncode == 0, result.stderr
    assert "policy stay, detector other" in result.stdout


def test_an_unknown_name_is_one_clear_error_naming_the_choices():
    with pytest.raises(
        ScenarioError, match=r"detector.kind: expected one of ideal, realistic, hog, detections \(got 'blob'\)"
    ):
        scenario_from_dict({"detector": {"kind": "blob"}})
    with pytest.raises(registry.UnknownName, match="unknown policy 'greedy'; expected one of fix, patrol"):
        run_episode(SCENARIO, "greedy", 0)


def test_the_flat_api_names_what_a_user_needs():
    assert ptztrack.__version__
    for name in ("run_episode", "scenario_from_dict", "Policy", "Detector", "CameraBackend", "Tracker", "register"):
        assert name in ptztrack.__all__
        assert getattr(ptztrack, name) is not None
    with pytest.raises(AttributeError):
        ptztrack.no_such_thing  # noqa: B018


def test_experiment_subcommands_take_only_their_own_flags(capfd):
    with pytest.raises(SystemExit) as exited:  # argparse's exit, status 2 (tests/test_bad_inputs.py: in a process)
        main(["experiment", "synthetic", "--views", "3"])
    assert exited.value.code == 2
    stderr = capfd.readouterr().err
    assert stderr.count("\n") == 1 and "unrecognized arguments: --views 3" in stderr


@pytest.mark.slow
def test_a_run_can_be_rescored_from_its_files_with_motmetrics_alone(tmp_path):
    """tracks_mot.txt and truth_mot.txt, read back and scored by motmetrics with the 1 m ground gate,
    give the run's metrics.json; steps.csv and detections.csv give its zoom and detections."""
    import motmetrics as mm

    assert main(["run", "--policy", "intg", "--frames", "30", "--seed", "3", "--out", str(tmp_path)]) == 0
    expected = json.loads((tmp_path / "metrics.json").read_text())
    tracks = np.loadtxt(tmp_path / "tracks_mot.txt", delimiter=",", ndmin=2)
    truth = np.loadtxt(tmp_path / "truth_mot.txt", delimiter=",", ndmin=2)
    steps = np.genfromtxt(tmp_path / "steps.csv", delimiter=",", names=True)
    accumulator = mm.MOTAccumulator(auto_id=True)
    for frame in range(1, len(steps) + 1):
        people, hypotheses = truth[truth[:, 0] == frame], tracks[tracks[:, 0] == frame]
        distance_m = np.linalg.norm(people[:, None, 7:9] - hypotheses[None, :, 7:9], axis=-1)
        distance_m[distance_m > 1.0] = np.nan
        accumulator.update(people[:, 1].astype(int), hypotheses[:, 1].astype(int), distance_m)
    scored = mm.metrics.create().compute(
        accumulator, metrics=["mota", "motp", "idf1", "num_switches", "num_false_positives", "num_misses"]
    )
    assert scored["mota"].iloc[0] == expected["mota"]
    assert scored["motp"].iloc[0] == expected["motp_m"]
    assert scored["idf1"].iloc[0] == expected["idf1"]
    assert scored["num_switches"].iloc[0] == expected["switches"]
    assert scored["num_false_positives"].iloc[0] == expected["false_positives"]
    assert scored["num_misses"].iloc[0] == expected["misses"]
    assert steps["zoom"].mean() == pytest.approx(expected["zoom"], rel=1e-6)
    detections = np.genfromtxt(tmp_path / "detections.csv", delimiter=",", names=True)
    assert len(detections) == expected["detections"]
    assert detections["height_px"].mean() == pytest.approx(expected["height_px"], abs=1e-3)


class Sweep:
    """Commands the camera continuously: half a degree of pan more every step, off the action grid."""

    def choose(self, context):
        return context.current_pose + [0.5, 0.0, 0.0]


def test_a_policy_may_command_poses_off_the_grid():
    episode = run_episode(SCENARIO, Sweep(), 0)
    assert np.all(episode.actions == -1)
    np.testing.assert_allclose(np.diff(episode.commanded[:, 0]), 0.5)
    np.testing.assert_array_equal(episode.poses, episode.commanded)


def test_a_pose_that_is_not_a_pose_is_refused():
    class Broken:
        def choose(self, context):
            return [1.0, np.nan, 1.0]

    with pytest.raises(ValueError, match="expected \\(pan_deg, tilt_deg, zoom\\), all finite"):
        run_episode(SCENARIO, Broken(), 0)
