from pathlib import Path

import numpy as np

from ptztrack.builders.episode import run_episode
from ptztrack.builders.recording import pets_scenario
from ptztrack.builders.world import build_world
from ptztrack.camera.live_view import recorded_to_live, view_lens
from ptztrack.evaluate.metrics import episode_metrics
from ptztrack.geometry.ptz import apply_homography, ground_to_image

EXCERPT = Path(__file__).parent / "data" / "pets_s2l1_excerpt"


def test_a_scenario_file_names_its_recording_relative_to_itself(tmp_path, excerpt_scenario):
    scenario = excerpt_scenario(tmp_path)
    assert Path(scenario.recording.ground_truth).resolve() == (EXCERPT / "gt_mot15.txt").resolve()
    world = build_world(scenario, np.random.default_rng(0))
    assert world.grid.size == 140
    assert world.truth.positions_m.shape[0] == 15


def test_the_ideal_detector_reports_annotated_feet_where_the_virtual_camera_sees_them(tmp_path, excerpt_scenario):
    world = build_world(excerpt_scenario(tmp_path), np.random.default_rng(0))
    wide = int(np.argmin(np.abs(world.grid.axis_indices - [3, 2, 0]).sum(axis=1)))
    pose = world.grid.poses[wide]
    found = world.detector.detect(world.backend, 0, pose, np.random.default_rng(0))
    present = np.flatnonzero(~np.isnan(world.truth.positions_m[0, :, 0]))
    assert len(found) >= 0.7 * len(present)
    expected = apply_homography(ground_to_image(world.camera, pose), world.truth.positions_m[0, found.person_index])
    # the annotations sit about 2 px from the calibrated feet in the 768 px frame: 0.5 px at 160 px
    assert np.median(np.linalg.norm(found.feet_px - expected, axis=1)) < 1.0
    narrow = np.flatnonzero(world.grid.axis_indices[:, 2] == 3)
    views = [world.detector.detect(world.backend, 0, world.grid.poses[a], np.random.default_rng(0)) for a in narrow]
    zoomed = max(views, key=len)
    assert 0 < len(zoomed) < len(found)
    assert np.mean(zoomed.height_px) > 2.5 * np.mean(found.height_px)


def test_the_built_in_pets_scenario_runs_from_the_package_data():
    scenario = pets_scenario(frames=40)
    metrics = episode_metrics(run_episode(scenario, "fix", 0))
    assert metrics["mota"] > 0.6
    assert 10 < metrics["height_px"] < 30


def test_a_camera_with_a_live_view_shows_the_annotated_people_through_its_lens(tmp_path, excerpt_scenario):
    scenario = excerpt_scenario(tmp_path, camera={"image_size_px": (160, 120), "live_view": {}})
    world = build_world(scenario, np.random.default_rng(0))
    backend = world.backend
    pose = world.grid.poses[int(np.argmin(np.abs(world.grid.axis_indices - [3, 2, 0]).sum(axis=1)))]
    lens = view_lens(backend.live, backend.virtual, pose)
    # The principal point is 10 px off at most in the registered 640 px image: 2.5 px at 160 px.
    assert 0 < np.hypot(*lens.principal_offset_px) <= 2.5 and lens.k1 == -0.15
    annotated = backend.scene.annotations.select(backend.scene.annotations.frame == 0).feet_px
    seen = backend.people(0, pose)
    np.testing.assert_allclose(seen.feet_px, recorded_to_live(backend.virtual, annotated, pose, backend.live))
    assert np.abs(seen.feet_px - backend.virtual.recorded_to_virtual(annotated, pose)).max() > 0.5
    assert len(world.detector.detect(backend, 0, pose, np.random.default_rng(0))) >= 0.7 * seen.in_view.sum()
