"""The closed loop: scene -> camera -> tracker -> controller, step by step, recorded.

``run_episode`` knows only the roles: a camera backend with ``observe``, the
tracker's predict and update, and a policy with ``choose``. Random draws come
from independent streams spawned from the seed: the scene, the policy,
one detector stream per frame, and the camera's landing errors. So different policies run with the same seed
meet the same people and, frame by frame, the same detector luck (common
random numbers), which makes their paired comparison far less noisy.
"""

from dataclasses import dataclass

import numpy as np

from typing import Protocol

from ptztrack.camera.actions import ActionGrid
from ptztrack.camera.pose_feedback import PoseSource, commanded_pose, landed_pose, registered_pose_source, true_pose
from ptztrack.camera.recorded import RecordedPTZ
from ptztrack.camera.simulated import SimulatedPTZ
from ptztrack.camera.virtual import virtual_ptz
from ptztrack.config import Scenario
from ptztrack.control.baselines import FixPolicy, PatrolPolicy, RandomPolicy, patrol_route, widest_view_action
from ptztrack.control.exploration import exploration_map
from ptztrack.control.information_policy import InformationGainPolicy
from ptztrack.control.policy import DecisionContext, Policy
from ptztrack.detect.simulated import Detections
from ptztrack.geometry.calibration import load_calibration
from ptztrack.geometry.ptz import PTZCamera
from ptztrack.detect.hog import HogPeopleDetector
from ptztrack.scene.pets import RecordedVideo, load_mot_ground_truth, recorded_scene
from ptztrack.scene.synthetic import GroundTruth, walk_people
from ptztrack.track.kalman import constant_velocity_model
from ptztrack.track.templates import (
    Templates,
    detection_of_each_track,
    refresh_templates,
    template_box_px,
    template_measurements,
    template_noise_covariance,
)
from ptztrack.track.tracker import (
    Tracks,
    no_tracks,
    pixel_noise_covariance,
    predict_tracks,
    update_own_tracks,
    update_tracks,
)

POLICIES = ("fix", "patrol", "random", "intg", "smpl")


class CameraBackend(Protocol):
    """Whatever gives detections for a step and a pose: simulated, recorded, or a real camera."""

    def observe(self, step: int, pose, rng: np.random.Generator) -> Detections: ...


@dataclass(frozen=True)
class World:
    """Everything a run's loop needs besides the policy.

    camera, grid : the PTZ camera model and its action grid.
    truth : the people, for the metrics.
    backend : gives the detections.
    area_bounds_m : [[x0, y0], [x1, y1]], where people can be.
    pose_source : the pose the tracker maps detections with (:mod:`ptztrack.camera.pose_feedback`).
    """

    camera: PTZCamera
    grid: ActionGrid
    truth: GroundTruth
    backend: CameraBackend
    area_bounds_m: np.ndarray
    pose_source: PoseSource


SIMPLE_POSE_SOURCES = {"commanded": commanded_pose, "oracle": true_pose}


def build_world(scenario: Scenario, scene_rng: np.random.Generator) -> World:
    """The synthetic scene, or the recording of ``scenario.recording`` seen by a virtual PTZ camera."""
    source = scenario.pose_feedback.source
    if scenario.recording is None:
        camera, grid = scenario.ptz_camera(), scenario.action_grid()
        truth = walk_people(scenario.people, scenario.area_m, scenario.frames, scenario.frame_rate_hz, scene_rng)
        backend = SimulatedPTZ(camera, truth, scenario.detector)
        return World(camera, grid, truth, backend, scenario.area_bounds_m, SIMPLE_POSE_SOURCES[source])
    recording = scenario.recording
    calibration = load_calibration(recording.calibration, recording.view)
    virtual, whole_frame_pose = virtual_ptz(calibration, recording.recorded_size_px, scenario.camera.image_size_px)
    offsets = scenario.action_grid()
    grid = ActionGrid(
        offsets.pan_deg + whole_frame_pose[0], offsets.tilt_deg + whole_frame_pose[1], offsets.zoom, offsets.max_steps
    )
    scene = recorded_scene(
        load_mot_ground_truth(recording.ground_truth),
        recording.frame_step,
        scenario.frames,
        scenario.frame_rate_hz,
        scenario.people.width_m,
    )
    margin_m = 1.0
    ground_m = scene.annotations.ground_m
    area_bounds_m = np.array([ground_m.min(axis=0) - margin_m, ground_m.max(axis=0) + margin_m])
    detector = scenario.detector
    hog, video = None, None
    if detector.kind == "hog":
        hog = HogPeopleDetector(detector.hog_upsample, detector.hog_hit_threshold, detector.hog_nms_iou)
    if detector.kind == "hog" or scenario.tracker.measurement_source == "spatiogram":
        video = RecordedVideo(recording.video, recording.recorded_size_px)
    backend = RecordedPTZ(virtual, scene, detector, recording.occluded_above, video, hog)
    if source == "registered":
        pose_source = registered_pose_source(scenario, scene.video_frame)
    else:
        pose_source = SIMPLE_POSE_SOURCES[source]
    return World(virtual.camera, grid, scene.truth, backend, area_bounds_m, pose_source)


@dataclass(frozen=True)
class Episode:
    """What happened in one run.

    truth : the people.
    camera : the PTZ camera that looked; area_bounds_m : [[x0, y0], [x1, y1]] where people can be.
    actions : (T,) flat action index taken at each step.
    poses : (T, 3) the poses the camera took, as (pan_deg, tilt_deg, zoom): the actions' poses
        unless ``camera.pose_error`` is set.
    tracker_poses : (T, 3) the poses the tracker mapped detections with (``pose_feedback.source``).
    pose_known : (T,) whether the pose source gave a pose; where not, the tracker used the commanded one.
    tracks : per step, the tracks reported after that step's update (the confirmed ones).
    detections : per step, what the detector reported.
    """

    truth: GroundTruth
    camera: PTZCamera
    area_bounds_m: np.ndarray
    actions: np.ndarray
    poses: np.ndarray
    tracker_poses: np.ndarray
    pose_known: np.ndarray
    tracks: list[Tracks]
    detections: list[Detections]


def make_policy(name: str, scenario: Scenario, world: World) -> Policy:
    """A fresh policy of the given name for one episode in ``world``."""
    camera, grid = world.camera, world.grid
    if name == "fix":
        return FixPolicy(widest_view_action(camera, grid, world.area_bounds_m))
    if name == "patrol":
        return PatrolPolicy(grid, patrol_route(camera, grid, world.area_bounds_m))
    if name == "random":
        return RandomPolicy()
    if name in ("intg", "smpl"):
        exploration = None
        if scenario.control.beta > 0:
            exploration = exploration_map(
                camera,
                grid.poses,
                world.area_bounds_m,
                scenario.detector,
                scenario.control,
                1.0 / scenario.frame_rate_hz,
            )
        return InformationGainPolicy(
            camera,
            grid,
            scenario.detector,
            scenario.control,
            pixel_noise_covariance(scenario.detector),
            scenario.people.width_m,
            name,
            exploration,
        )
    raise ValueError(f"unknown policy {name!r}; expected one of {', '.join(POLICIES)}")


def _episode_seeds(seed: int) -> list[np.random.SeedSequence]:
    """The independent streams of an episode: scene, detector, policy, the camera's landing errors."""
    return np.random.SeedSequence(seed).spawn(4)


def episode_world(scenario: Scenario, seed: int) -> World:
    """The world that ``run_episode(scenario, any_policy, seed)`` runs in, built again: the same people."""
    scene_seed = _episode_seeds(seed)[0]
    return build_world(scenario, np.random.default_rng(scene_seed))


def measure_and_update(
    scenario: Scenario, world: World, step: int, tracks: Tracks, templates: Templates, pose, tracker_pose, rng
) -> tuple[Tracks, Templates, Detections]:
    """The tracker's update of a step, from the measurement source of ``scenario.tracker``.

    tracks : predicted to the step; templates : each track's spatiogram (spatiogram source only);
    pose : where the camera looks; tracker_pose : where the tracker believes it looks; rng : the
    step's detector stream. Returns the updated tracks and templates, and the measurements.
    """
    config, camera = scenario.tracker, world.camera
    V = pixel_noise_covariance(scenario.detector)
    height_m, width_m = scenario.control.person_height_m, scenario.people.width_m
    if config.measurement_source == "detector" or step % config.detector_every_steps == 0:
        detections = world.backend.observe(step, pose, rng)
        updated = update_tracks(tracks, detections.feet_px, camera, tracker_pose, V, config)
        if config.measurement_source == "spatiogram":
            ids, feet_px = detection_of_each_track(
                tracks, updated, detections.feet_px, camera, tracker_pose, V, config.gate_probability
            )
            view = world.backend.view(step, pose)
            templates = refresh_templates(
                templates, updated.ids, view, camera, tracker_pose, ids, feet_px, height_m, width_m
            )
        return updated, templates, detections
    view = world.backend.view(step, pose)
    found = template_measurements(view, camera, tracker_pose, tracks, templates, V, height_m, width_m)
    noise = template_noise_covariance(camera, tracker_pose, found.feet_px, height_m, V)
    updated = update_own_tracks(tracks, found.track_ids, found.feet_px, camera, tracker_pose, noise, config)
    heights_px = template_box_px(camera, tracker_pose, found.feet_px, height_m, width_m)[:, 3]
    detections = Detections(found.feet_px, heights_px, np.full(len(found.feet_px), -1))
    return updated, templates, detections


def run_episode(scenario: Scenario, policy_name: str, seed: int, world: World | None = None) -> Episode:
    """Run one closed-loop episode of the scenario: at most ``scenario.frames`` steps.

    world : ``episode_world(scenario, seed)``, when the caller has built it already (it is built
    otherwise); a caller that also draws the episode's views needs it, and building it may mean
    building a reference index.
    """
    world = world or episode_world(scenario, seed)
    _, detector_seed, policy_seed, landing_seed = _episode_seeds(seed)
    steps = world.truth.positions_m.shape[0]
    policy = make_policy(policy_name, scenario, world)
    frame_seeds = detector_seed.spawn(steps)
    policy_rng = np.random.default_rng(policy_seed)
    landing_rng = np.random.default_rng(landing_seed)
    F, U = constant_velocity_model(1.0 / scenario.frame_rate_hz, scenario.tracker.acceleration_sigma_m_s2)

    action = widest_view_action(world.camera, world.grid, world.area_bounds_m)
    tracks, templates = no_tracks(), {}
    actions, poses, tracker_poses, pose_known, track_history, detection_history = [], [], [], [], [], []
    for step in range(steps):
        tracks = predict_tracks(tracks, F, U)
        context = DecisionContext(step, action, world.grid.reachable(action), tracks, policy_rng)
        previous_action, action = action, policy.choose(context)
        commanded = world.grid.poses[action]
        if step == 0 or action != previous_action:
            pose = landed_pose(commanded, scenario.camera.pose_error, landing_rng)
        believed = world.pose_source(step, commanded, pose)
        tracker_pose = commanded if believed is None else believed
        tracks, templates, detections = measure_and_update(
            scenario, world, step, tracks, templates, pose, tracker_pose, np.random.default_rng(frame_seeds[step])
        )
        actions.append(action)
        poses.append(pose)
        tracker_poses.append(tracker_pose)
        pose_known.append(believed is not None)
        track_history.append(tracks.confirmed(scenario.tracker))
        detection_history.append(detections)
    return Episode(
        world.truth,
        world.camera,
        world.area_bounds_m,
        np.asarray(actions),
        np.asarray(poses),
        np.asarray(tracker_poses),
        np.asarray(pose_known),
        track_history,
        detection_history,
    )
