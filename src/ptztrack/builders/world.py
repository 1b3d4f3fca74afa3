"""The scene, the camera backend, the detector and the pose source of a scenario: its
:class:`~ptztrack.loop.steps.World`."""

import logging
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import numpy as np

from ptztrack import registry
from ptztrack.builders.parameters import parameters_from
from ptztrack.builders.recording import recorded_size_px
from ptztrack.builders.registration import registered_pose_source
from ptztrack.camera.actions import ActionGrid
from ptztrack.camera.parameters import LandingErrorParameters
from ptztrack.camera.pose_feedback import commanded_pose, true_pose
from ptztrack.camera.virtual import VirtualPTZ, virtual_ptz
from ptztrack.config import Scenario, ScenarioError
from ptztrack.control.baselines import widest_view_action
from ptztrack.detect.detector_model import OnlineDetectorModel, read_detector_model_file
from ptztrack.detect.simulated import RecallModel
from ptztrack.geometry.area import rectangle_m
from ptztrack.geometry.calibration import PinholeCalibration, load_calibration
from ptztrack.geometry.ptz import PTZCamera, ground_footprint
from ptztrack.loop.steps import World
from ptztrack.names import DETECTOR_MODELS, KEPT_DETECTOR_MODELS
from ptztrack.roles import CameraBackend, Detector, PoseSource
from ptztrack.scene.parameters import CrowdParameters
from ptztrack.scene.pets import (
    RecordedScene,
    RecordedVideo,
    load_mot_ground_truth,
    recorded_scene,
    refuse_annotations_off_the_view,
    refuse_rows_beyond,
)
from ptztrack.scene.synthetic import walk_people
from ptztrack.scene.trajectories import (
    centring_offset_m,
    read_trajectories,
    replay_truth,
    trajectories_outside_area,
    trajectories_too_fast,
)
from ptztrack.types import GroundTruth

log = logging.getLogger(__name__)

CameraSpec = str | CameraBackend | Callable[[Scenario, "BuiltScene"], CameraBackend]
"""A camera backend: a registered name, an object, or a factory ``(scenario, scene) -> backend``."""
DetectorSpec = str | Detector | Callable[[Scenario, "BuiltScene"], Detector]
"""A detector: a registered name, an object, or a factory ``(scenario, scene) -> detector``."""


@dataclass(frozen=True)
class BuiltScene:
    """A scenario's scene before its camera backend and detector: what their factories are given.

    camera : the PTZ camera model; grid : its action grid; truth : the people;
    area_polygon_m : (K, 2) the walkable area, a polygon on the ground.
    recording, virtual : for a recording, its annotated people and the virtual PTZ camera over it;
    calibration, video : its calibration and its video (None without one), each read once here for
    whoever needs them (the camera backend, the pose source).
    """

    camera: PTZCamera
    grid: ActionGrid
    truth: GroundTruth
    area_polygon_m: np.ndarray
    recording: RecordedScene | None = None
    virtual: VirtualPTZ | None = None
    calibration: PinholeCalibration | None = None
    video: RecordedVideo | None = None


def ptz_camera(scenario: Scenario) -> PTZCamera:
    """The synthetic scene's camera (a recording's comes from its calibration)."""
    width_px, height_px = scenario.camera.image_size_px
    return PTZCamera(scenario.camera.position_m, width_px, height_px, scenario.camera.f_min_px)


def action_grid(scenario: Scenario) -> ActionGrid:
    """The scenario's action grid (for a recording, pan and tilt are offsets from the whole-frame view)."""
    actions = scenario.actions
    return ActionGrid(
        pan_deg=actions.pan_deg.values(),
        tilt_deg=actions.tilt_deg.values(),
        zoom=np.asarray(actions.zoom, dtype=float),
        max_steps=actions.max_steps,
    )


def crowd(scenario: Scenario) -> CrowdParameters:
    return parameters_from(scenario.people, CrowdParameters)


def build_scene(scenario: Scenario, scene_rng: np.random.Generator) -> BuiltScene:
    """The synthetic scene (walkers drawn from ``scene_rng``, or the people of ``people.trajectories``
    replayed: :func:`replayed_truth`), or the recording seen by a virtual PTZ camera."""
    if scenario.recording is None:
        if scenario.people.trajectories is not None:
            truth = replayed_truth(scenario, scene_rng)
        else:
            truth = walk_people(crowd(scenario), scenario.area_m, scenario.frames, scenario.frame_rate_hz, scene_rng)
        return BuiltScene(ptz_camera(scenario), action_grid(scenario), truth, rectangle_m(*scenario.area_m))
    recording = scenario.recording
    calibration = load_calibration(recording.calibration, recording.view)
    size_px = recorded_size_px(recording)
    virtual, whole_frame_pose = virtual_ptz(calibration, size_px, scenario.camera.image_size_px, recording.map_grid_px)
    offsets = action_grid(scenario)
    grid = ActionGrid(
        offsets.pan_deg + whole_frame_pose[0], offsets.tilt_deg + whole_frame_pose[1], offsets.zoom, offsets.max_steps
    )
    annotations = load_mot_ground_truth(recording.ground_truth)
    scene = recorded_scene(
        annotations,
        recording.frame_step,
        scenario.frames,
        scenario.frame_rate_hz,
        scenario.people.width_m,
        recording.frame_range,
    )
    misfit = refuse_annotations_off_the_view(
        recording.ground_truth,
        annotations.select(np.isin(annotations.frame, scene.video_frame)),
        calibration,
        size_px,
        recording.calibration,
    )
    if misfit is not None:
        log.warning(misfit)
    if recording.area_m is not None:
        area_polygon_m = np.asarray(recording.area_m, dtype=float)
    else:
        area_polygon_m = visible_ground_m(scenario, virtual.camera, whole_frame_pose, grid)
    video = None
    if recording.video is not None:
        video = RecordedVideo(recording.video, size_px, int(scene.video_frame.max()) + 1)
        refuse_rows_beyond(
            recording.ground_truth,
            annotations.frame,
            annotations.line,
            video.frame_count,
            f"the {video.frame_count} frames of {recording.video}",
        )
    return BuiltScene(virtual.camera, grid, scene.truth, area_polygon_m, scene, virtual, calibration, video)


def replayed_truth(scenario: Scenario, scene_rng: np.random.Generator) -> GroundTruth:
    """The people of the file ``people.trajectories`` at the scenario's steps, moved by
    ``people.trajectories_offset_m`` (None: centred on the area), each of a height drawn uniformly from
    ``people.height_m`` with ``scene_rng`` (one per person of the file, in increasing id order);
    positions far outside the area or too fast to be walking are logged as a warning."""
    people = scenario.people
    # The scenario's validation requires the rate with the file.
    assert people.trajectories is not None and people.trajectories_frame_rate_hz is not None
    trajectories = read_trajectories(people.trajectories, people.trajectories_frame_rate_hz)
    if people.trajectories_offset_m is not None:
        offset_m = np.asarray(people.trajectories_offset_m, dtype=float)
    else:
        offset_m = centring_offset_m(trajectories, scenario.area_m)
    for warning in (
        trajectories_outside_area(trajectories, offset_m, scenario.area_m),
        trajectories_too_fast(trajectories),
    ):
        if warning is not None:
            log.warning(warning)
    heights_m = scene_rng.uniform(*people.height_m, size=len(trajectories.people))
    return replay_truth(trajectories, scenario.frames, scenario.frame_rate_hz, heights_m, people.width_m, offset_m)


def visible_ground_m(scenario: Scenario, camera: PTZCamera, whole_frame_pose, grid: ActionGrid) -> np.ndarray:
    """The walkable area of a recording, from the scene alone: the ground the recorded view shows (the
    virtual camera's view of the whole frame), out to where a standing person of
    ``control.person_height_m`` would look smaller than ``detector.recall_r0_px`` even at the grid's
    largest zoom (no detector model finds anybody beyond); a polygon (K, 2)."""
    focal_px = camera.f_min_px * grid.zoom.max()
    max_range_m = focal_px * scenario.control.person_height_m / scenario.detector.recall_r0_px
    return ground_footprint(camera, whole_frame_pose, max_range_m=max_range_m)


def resolve(kind: str, spec: Any, scenario: Scenario, built: Any, method: str) -> Any:
    """An implementation of a role from its spec: a name registered under ``kind`` (its factory is
    called with ``scenario`` and ``built``), an object that has ``method`` (used as it is), or a
    factory called like a registered one."""
    if isinstance(spec, str):
        return registry.factory(kind, spec)(scenario, built)
    if not isinstance(spec, type) and hasattr(spec, method):
        return spec
    if callable(spec):
        return spec(scenario, built)
    raise TypeError(f"a {kind} spec must be a registered name, an object with {method}(), or a factory; got {spec!r}")


def pose_source(scenario: Scenario, scene: BuiltScene) -> PoseSource:
    """The pose the tracker maps detections with: ``pose_feedback.source`` of the scenario."""
    source = scenario.pose_feedback.source
    if source == "registered":
        if scene.recording is None:
            raise ScenarioError("pose_feedback.source 'registered' needs a recording")
        # The scenario's validation requires a video for 'registered'.
        assert scene.calibration is not None and scene.video is not None
        return registered_pose_source(scenario, scene.recording.video_frame, scene.calibration, scene.video)
    return {"commanded": commanded_pose, "oracle": true_pose}[source]


def landing_error(scenario: Scenario) -> LandingErrorParameters:
    return parameters_from(scenario.camera.pose_error, LandingErrorParameters)


def recall_model(scenario: Scenario) -> RecallModel:
    """The detector's own recall curve as the scenario gives it: perfect for the ideal detector."""
    detector = scenario.detector
    return RecallModel(detector.recall_kd, detector.recall_r0_px, perfect=detector.kind == "ideal")


def detector_model(
    scenario: Scenario, camera: PTZCamera, seed: np.random.SeedSequence | None = None, own: RecallModel | None = None
) -> OnlineDetectorModel:
    """What the policies and the tracker know of the detector (``detector.model``): the scenario's curve with
    its r0 shifted by ``detector.prior_shift_px`` as the prior, learned as the run goes ('online') or kept
    ('a-priori'); the unshifted curve kept ('true'); or an earlier run's ``detector_model.json`` as the prior.
    The ideal detector's model is perfect and kept. seed : the stream of the model's draws. own : the
    a-priori curve of a camera whose detector is not the scenario's, with the scenario's clutter and noise
    as their priors; learned as the run goes unless ``detector.model`` is 'a-priori' or 'true'."""
    detector = scenario.detector
    people = (camera, scenario.control.person_height_m, scenario.people.width_m)
    rng = np.random.default_rng(seed if seed is not None else 0)
    if own is not None:
        prior, learning = own, detector.model not in KEPT_DETECTOR_MODELS
    elif detector.model not in DETECTOR_MODELS:
        return OnlineDetectorModel(*people, **read_detector_model_file(detector.model), rng=rng)
    else:
        prior, learning = recall_model(scenario), False
        if not prior.perfect and detector.model != "true":
            prior = RecallModel(prior.kd_per_px, max(prior.r0_px + detector.prior_shift_px, 0.0))
            learning = detector.model == "online"
    return OnlineDetectorModel(
        *people,
        prior,
        learning=learning,
        false_positives_per_view=detector.false_positives_per_frame,
        pixel_noise_px=detector.pixel_noise_px,
        rng=rng,
    )


def build_world(
    scenario: Scenario,
    scene_rng: np.random.Generator,
    camera: CameraSpec | None = None,
    detector: DetectorSpec | None = None,
    tracker_seed: np.random.SeedSequence | None = None,
    model_seed: np.random.SeedSequence | None = None,
) -> World:
    """The world of ``scenario``: its scene, camera backend, detector and pose source.

    camera : the backend, by default ``camera.backend`` of the scenario ('simulated' for the
    synthetic scene, 'virtual' for a recording); detector : by default ``detector.kind``;
    tracker_seed : the stream of a tracker that draws; model_seed : the detector model's draws.
    """
    return camera_world(scenario, build_scene(scenario, scene_rng), camera, detector, tracker_seed, model_seed)


def camera_world(
    scenario: Scenario,
    scene: BuiltScene,
    camera: CameraSpec | None = None,
    detector: DetectorSpec | None = None,
    tracker_seed: np.random.SeedSequence | None = None,
    model_seed: np.random.SeedSequence | None = None,
) -> World:
    """The world of the camera of ``scene``: its backend, detector and pose source (see :func:`build_world`)."""
    default_backend = "virtual" if scenario.recording is not None else "simulated"
    backend = resolve("cameras", camera or scenario.camera.backend or default_backend, scenario, scene, "people")
    found_by = resolve("detectors", detector or scenario.detector.kind, scenario, scene, "detect")
    return World(
        camera=scene.camera,
        grid=scene.grid,
        truth=scene.truth,
        backend=backend,
        detector=found_by,
        area_polygon_m=scene.area_polygon_m,
        start_action=widest_view_action(scene.camera, scene.grid, scene.area_polygon_m),
        pose_source=pose_source(scenario, scene),
        landing_error=landing_error(scenario),
        tracker_seed=tracker_seed,
        detector_model=detector_model(scenario, scene.camera, model_seed),
    )
