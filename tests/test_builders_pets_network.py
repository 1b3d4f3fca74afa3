import json

import numpy as np
import pytest

from ptztrack.builders.episode import run_episode
from ptztrack.builders.network import belief_of_cameras
from ptztrack.builders.pets_network import PUBLISHED_RECALL, pets_network_world, published_views
from ptztrack.builders.recording import pets_scenario
from ptztrack.camera.virtual import virtual_ptz
from ptztrack.cli import main
from ptztrack.control.information_gain import action_geometry, detection_weight_integral
from ptztrack.detect.published import PublishedDetections
from ptztrack.detect.simulated import RecallModel
from ptztrack.evaluate.metrics import episode_metrics
from ptztrack.geometry.calibration import project_pinhole
from ptztrack.track.observation import ground_points
from ptztrack.types import Detections


@pytest.fixture(scope="module")
def views():
    return {view.name: view for view in published_views(pets_scenario("hog"))}


@pytest.mark.parametrize("name", ["View_003", "View_007"])
def test_a_published_box_maps_to_the_ground_through_its_views_own_calibration(views, name):
    """Feet on ground points projected by hand through the view's calibration (View_007's lens distorts
    strongly): the tracker's homography of the fixed camera gives the points back, and they project
    onto the feet again, within 1e-6 px."""
    view = views[name]
    ground_m = np.array([[-5.0, 2.0], [0.0, 0.0], [3.0, -4.0], [-10.0, 5.0]])
    feet_px = project_pinhole(view.calibration, np.c_[1000.0 * ground_m, np.zeros(len(ground_m))])
    heights_px = np.array([80.0, 70.0, 60.0, 50.0])
    boxes = np.c_[feet_px[:, 0] - 10.0, feet_px[:, 1] - heights_px, np.full(4, 20.0), heights_px, np.full(4, 0.9)]
    virtual, pose = virtual_ptz(view.calibration, view.image_size_px, (160, 120))
    camera = PublishedDetections(virtual.camera, view.calibration, [boxes], np.array([0]), 0.5)
    found = camera.detect(camera, 0, pose, np.random.default_rng(0))
    assert camera.image(0, pose) is None and camera.people(0, pose) is None
    mapped_m, ahead = ground_points(found.feet_px, virtual.camera, pose)
    assert ahead.all() and np.all(found.height_px > 0) and np.all(found.person_index == -1)
    np.testing.assert_allclose(mapped_m, ground_m, atol=1e-9)
    back_px = project_pinhole(view.calibration, np.c_[1000.0 * mapped_m, np.zeros(len(mapped_m))])
    np.testing.assert_allclose(back_px, feet_px, atol=1e-6)
    assert (
        len(
            PublishedDetections(virtual.camera, view.calibration, [boxes], np.array([0]), 0.95).detect(
                camera, 0, pose, np.random.default_rng(0)
            )
        )
        == 0
    )


def test_a_constant_recall_scales_the_ideal_detectors_probability_of_detection(views):
    view = views["View_003"]
    virtual, pose = virtual_ptz(view.calibration, view.image_size_px, (160, 120))
    geometry = action_geometry(virtual.camera, pose[None], 1.75)
    mean_m, covariance_m2 = np.array([[0.0, 0.0], [-5.0, 3.0]]), np.tile(0.25 * np.eye(2), (2, 1, 1))
    ideal, constant = (
        detection_weight_integral(virtual.camera, geometry, curve, mean_m, covariance_m2, 4.0 * np.eye(2))
        for curve in (RecallModel(0.0, 0.0, perfect=True), RecallModel.constant(PUBLISHED_RECALL))
    )
    assert np.all(ideal > 0.5)
    np.testing.assert_allclose(constant, PUBLISHED_RECALL * ideal)
    np.testing.assert_array_equal(RecallModel.constant(0.5)(np.array([3.0, 300.0])), [0.5, 0.5])


def test_a_fixed_cameras_model_learns_its_clutter_from_false_births_and_its_tracker_reads_it(views):
    """A fixed camera shown one detection every other step, at the same place: each starts a track that
    the next step's miss deletes, a false birth; its model, prior recall PUBLISHED_RECALL and no clutter,
    learns the clutter per view from them, and its tracker's clutter is the model's."""
    scenario = pets_scenario("hog", frames=3)
    world = pets_network_world(scenario, 0, False, [views["View_005"]])
    camera = world.cameras[0]
    model = camera.detector_model
    assert model.learning and model.perfect and model.plateau == pytest.approx(PUBLISHED_RECALL)
    assert model.clutter_per_view == 0.0
    belief = belief_of_cameras([(scenario, camera)])
    pose = camera.grid.poses[camera.start_action]
    steps = 40
    for step in range(steps):
        belief.predict()
        feet_px = np.array([[80.0, 90.0]]) if step % 2 == 0 else np.zeros((0, 2))
        belief.updater(0).update(
            Detections(feet_px, np.full(len(feet_px), 40.0), np.full(len(feet_px), -1)), pose, None
        )
    assert model.false_births == steps // 2
    assert model.clutter_per_view == pytest.approx((steps // 2) / (10 + steps))
    tracker = belief.cameras[0]
    assert tracker.clutter_per_view is not None and tracker.clutter_per_view() == model.clutter_per_view
    assert model.perfect


def test_the_pets_network_rows_and_the_ptz_camera_alone_is_the_one_camera_run(tmp_path):
    path = tmp_path / "pets.json"
    arguments = ["experiment", "network", "pets", "--frames", "3", "--seeds", "1", "--executor", "serial", "--quiet"]
    assert main([*arguments, "--json", str(path)]) == 0
    rows = {row["config"]: row for row in json.loads(path.read_text())}
    assert list(rows) == ["ptz+6fixed", "6fixed", "ptz"]
    assert [rows[label]["seeds"] for label in rows] == [1, 1, 1]
    assert [rows[label]["cameras"] for label in rows] == [7, 6, 1]
    for row in rows.values():
        assert {"mota", "mota_sd", "motp_m", "idf1", "mota_per_seed", "mota_all_tracks"} <= set(row)
        in_area = {"mota_tracking_area", "idf1_tracking_area", "false_positives_tracking_area", "misses_tracking_area"}
        assert in_area | {"mota_tracking_area_per_seed"} <= set(row)
        assert row["fixed_recall"] == PUBLISHED_RECALL
    scenario = pets_scenario("hog", frames=3, **{"control.beta": 9.0})
    alone = episode_metrics(run_episode(scenario, "intg", 0))
    assert rows["ptz"]["mota_all_tracks_per_seed"] == [alone["mota"]]
    assert rows["6fixed"]["zoom"] == 1.0 and rows["6fixed"]["detections"] > rows["ptz"]["detections"]
