"""The tracker's pose sources in episodes, and registration over PETS (the scenario's reference index,
registered views, the landing error of a scenario's camera)."""

import numpy as np
import pytest

from ptztrack.builders.episode import run_episode
from ptztrack.builders.recording import pets_scenario
from ptztrack.builders.registration import live_view_model, reference_index, registration_camera
from ptztrack.builders.world import action_grid
from ptztrack.camera import pose_feedback
from ptztrack.config import LiveView, PoseError, ScenarioError, scenario_from_dict
from ptztrack.evaluate.metrics import episode_metrics
from ptztrack.experiments.registration import live_view_settings, registration_views, summarise_registration
from ptztrack.geometry.registration import register
from ptztrack.types import Detections

# Small enough to build in seconds, large enough to register most views (13 references at 480 x 360).
SMALL_REGISTRATION = {
    "image_size_px": (480, 360),
    "reference_zooms": (1.0, 2.0),
    "reference_pan_steps": 3,
    "reference_tilt_steps": 2,
}


def test_a_registered_scenario_needs_a_video():
    with pytest.raises(ScenarioError, match="pose_feedback.source 'registered' needs a recording with a video"):
        scenario_from_dict({"pose_feedback": {"source": "registered"}})


def test_a_lens_distortion_that_folds_the_image_corners_is_refused():
    # PETS's zoom-1 corner is at normalised radius 0.42: barrel distortion beyond k1 -0.82 folds it back.
    live_view_model(pets_scenario(camera={"live_view": {"k1_wide": -0.8}}))
    with pytest.raises(ScenarioError, match="camera.live_view: k1 -0.9 at zoom 1.00 bends the image corners back"):
        live_view_model(pets_scenario(camera={"live_view": {"k1_wide": -0.9}}))


@pytest.fixture(scope="module")
def small_registration(tmp_path_factory):
    """The PETS scenario with a small reference index, cached in a file, and the index."""
    path = tmp_path_factory.mktemp("index") / "index.npz"
    scenario = pets_scenario("ideal", pose_feedback={**SMALL_REGISTRATION, "index": str(path)})
    return scenario, reference_index(scenario)


def test_the_index_is_built_once_and_then_read_from_its_file(small_registration):
    scenario, index = small_registration

    def must_not_build():
        raise AssertionError("the cached index should have been read")

    again = pose_feedback.cached_reference_index(scenario.pose_feedback.index, must_not_build)
    np.testing.assert_array_equal(again.poses, index.poses)
    np.testing.assert_array_equal(again.descriptors, index.descriptors)


@pytest.mark.slow
def test_pets_views_register_to_a_fraction_of_a_percent_and_centimetres(small_registration):
    scenario, index = small_registration
    rows = registration_views(scenario, index, views=8, seed=3)
    summary = summarise_registration(rows)
    assert summary["registered"] >= 6
    assert summary["focal_err_median_pct"] < 0.5
    assert summary["ground_err_median_m"] < 0.1


@pytest.mark.slow
def test_realistic_pets_views_register_within_a_percent_and_fifteen_centimetres(small_registration):
    scenario, index = small_registration
    realistic = scenario.model_copy(update={"camera": scenario.camera.model_copy(update={"live_view": LiveView()})})
    rows = registration_views(realistic, index, views=8, seed=3)
    summary = summarise_registration(rows)
    assert summary["registered"] >= 7
    assert summary["focal_err_median_pct"] < 1.0
    assert summary["ground_err_median_m"] < 0.15
    # The registration knows the view better than the tracker's pinhole model can say (its roll and
    # distortion), and the registered pose places the view's own pixels better than the true pose,
    # for it absorbs the principal point offset.
    assert summary["lens_ground_err_median_m"] < summary["ground_err_median_m"] < summary["oracle_ground_err_median_m"]
    # The reference views are of the odd frames 1-25 (13 views); the live views 300 frames later at least.
    settings = live_view_settings(realistic)
    assert settings["reference_frames"] == [1, 25] and settings["first_live_frame"] == 325
    assert min(row["frame"] for row in rows) >= 325


def test_the_bundle_recovers_the_reference_poses_from_rough_ones(small_registration):
    scenario, index = small_registration
    virtual, whole_frame_pose = registration_camera(scenario)
    offsets = action_grid(scenario)
    truth = pose_feedback.reference_poses(
        whole_frame_pose,
        (offsets.pan_deg.min(), offsets.pan_deg.max()),
        (offsets.tilt_deg.min(), offsets.tilt_deg.max()),
        scenario.pose_feedback.reference_pan_steps,
        scenario.pose_feedback.reference_tilt_steps,
        scenario.pose_feedback.reference_zooms,
    )
    # The rough poses were 0.5 deg and 3 % off; every view of this grid ties to the first.
    assert len(index.poses) == len(truth)
    np.testing.assert_allclose(index.poses[:, :2], truth[:, :2], atol=0.05)
    np.testing.assert_allclose(index.poses[:, 2], truth[:, 2], rtol=0.005)


def test_a_view_of_another_size_is_refused(small_registration):
    scenario, index = small_registration
    other = scenario.model_copy(
        update={"pose_feedback": scenario.pose_feedback.model_copy(update={"image_size_px": (640, 480)})}
    )
    virtual, _ = registration_camera(other)
    with pytest.raises(ValueError, match="index is of 480x360 px views, but pose_feedback.image_size_px is 640x480"):
        pose_feedback.RegisteredPose(virtual, index, None, np.zeros(1, dtype=int))


def test_a_view_of_nothing_is_not_registered(small_registration):
    scenario, index = small_registration
    virtual, _ = registration_camera(scenario)
    assert register(virtual.camera, index, np.zeros((360, 480, 3), dtype=np.uint8)) is None


@pytest.mark.slow
def test_the_tracker_uses_the_commanded_the_true_or_the_registered_pose(small_registration):
    scenario, _ = small_registration
    scenario = scenario.model_copy(
        update={
            "frames": 12,
            "camera": scenario.camera.model_copy(
                update={"pose_error": PoseError(pan_tilt_sigma_deg=2.0, zoom_sigma=0.02)}
            ),
        }
    )
    episodes = {}
    for source in ("commanded", "oracle", "registered"):
        feedback = scenario.pose_feedback.model_copy(update={"source": source})
        episodes[source] = run_episode(scenario.model_copy(update={"pose_feedback": feedback}), "random", 0)
    commanded, oracle, registered = episodes["commanded"], episodes["oracle"], episodes["registered"]
    # The landing errors are their own random stream: the camera lands at the same poses whatever the tracker believes.
    np.testing.assert_array_equal(commanded.actions, oracle.actions)
    np.testing.assert_array_equal(commanded.poses, oracle.poses)
    assert np.abs(commanded.poses[:, :2] - commanded.tracker_poses[:, :2]).max() > 1.0
    np.testing.assert_array_equal(oracle.tracker_poses, oracle.poses)
    known = registered.pose_known
    assert known.mean() >= 0.75
    np.testing.assert_allclose(registered.tracker_poses[known, :2], registered.poses[known, :2], atol=0.2)
    assert episode_metrics(registered)["mota"] > episode_metrics(commanded)["mota"]


def test_the_camera_stays_put_while_the_command_does_not_change():
    scenario = scenario_from_dict({"frames": 15, "camera": {"pose_error": {"pan_tilt_sigma_deg": 1.0}}})
    episode = run_episode(scenario, "fix", 0)
    assert len(np.unique(episode.poses, axis=0)) == 1
    assert np.abs(episode.poses - episode.tracker_poses).max() > 0


class PoseRecordingDetector:
    """Sees nobody; records the pose of each view and the pose the system believed."""

    def __init__(self):
        self.poses, self.believed = [], []

    def detect(self, camera, step, pose, rng, believed_pose=None):
        self.poses.append(np.array(pose))
        self.believed.append(np.array(believed_pose))
        return Detections.empty()


def test_the_detector_sees_the_view_where_the_camera_landed_and_is_told_only_the_trackers_pose():
    scenario = scenario_from_dict({"frames": 8, "camera": {"pose_error": {"pan_tilt_sigma_deg": 1.0}}})
    detector = PoseRecordingDetector()
    episode = run_episode(scenario, "fix", 0, detector=detector)
    np.testing.assert_array_equal(detector.poses, episode.poses)
    np.testing.assert_array_equal(detector.believed, episode.tracker_poses)
    assert np.abs(np.array(detector.poses) - np.array(detector.believed)).max() > 0
