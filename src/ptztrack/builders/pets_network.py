"""A camera network on PETS 2009 S2.L1: the virtual PTZ camera over View_001's video and the published
detections of the six other calibrated views as fixed cameras, one shared belief.

The PTZ camera is the one-camera PETS run's (:func:`ptztrack.builders.episode.episode_world`: the same
scene, detector, detector model and streams), first in the network, so that a network of it alone is,
step for step, that run. Each other view is a fixed camera backed by its published boxes
(:class:`ptztrack.detect.published.PublishedDetections`): the virtual camera at its optical centre
with the scenario's image (160 x 120 px) at the view's field of view, held at the pose that shows
the recorded view; the scenario's pixel noise, tracker and policy settings; and, as its detector
model, one learned as the run goes as the PTZ camera's is
(:class:`~ptztrack.detect.detector_model.OnlineDetectorModel`, with the same prior weights): its prior
recall :data:`PUBLISHED_RECALL` for anybody wholly in its image, whatever their size, learned as a
constant; its false positives per view learned from the tracks one detection started that died
unconfirmed, from the scenario's (``detector.false_positives_per_frame``) as the prior, and the
existence of a track it detects updated against their density over its image. Boxes scored below the
occupancy experiment's threshold for the same files
(:attr:`ptztrack.occupancy.parameters.OccupancyParameters.min_box_score`) are not used. Every camera
shares the PTZ camera's scene: its people (the annotations, scored) and its walkable area.

The fixed cameras' tracker differs in four ways. Each view's calibration puts a person's feet on the
ground somewhere else than the other views do, by an error that is unknown and, now and then, far
larger than the pixel noise: under Gaussian noise such a detection falls outside the gate of the track
the other cameras made certain, starts a second track of the same person, and keeps it. So the
scenario's pixel noise is the scale of a Student-t noise of :data:`PUBLISHED_NOISE_DOF` degrees of
freedom, which gates a far detection and lets it move its track less; a detection in the gate of a
track starts no track (``TrackerParameters.birth`` 'outside_gates'); what part of the error is
common to a view's detections, its bias, is estimated as the run goes and taken off them
(:mod:`ptztrack.track.sensor_bias`); and a track that only one fixed camera has detected is not reported
until another camera detects it too (:attr:`~ptztrack.network.shared_belief.SharedBelief.needs_a_second_camera`).
"""

from collections.abc import Sequence
from dataclasses import replace

import numpy as np

from ptztrack.builders.network import Coordination, belief_of_cameras, policy_of_cameras
from ptztrack.builders.occupancy import recording_from_dataset
from ptztrack.builders.world import BuiltScene, build_scene, camera_world, detector_model
from ptztrack.camera.actions import ActionGrid
from ptztrack.camera.parameters import LandingErrorParameters
from ptztrack.camera.pose_feedback import commanded_pose
from ptztrack.camera.virtual import virtual_ptz
from ptztrack.config import Scenario, ScenarioError, dataset_from_dict, load_dataset
from ptztrack.control.information_policy import InformationMethod
from ptztrack.detect.published import PublishedDetections
from ptztrack.detect.simulated import RecallModel
from ptztrack.loop.simulated import NetworkWorld
from ptztrack.loop.steps import World
from ptztrack.loop.streams import episode_streams
from ptztrack.network.policy import NetworkInformationPolicy
from ptztrack.network.shared_belief import SharedBelief
from ptztrack.occupancy.multiview import CameraView
from ptztrack.occupancy.parameters import OccupancyParameters
from ptztrack.track.sensor_bias import PixelBias

PUBLISHED_RECALL = 0.9
"""The fixed cameras' detector model: the probability that the published detector finds a person wholly
in the view's image, at any size (people hidden by other tracks count as missed in proportion, as for
every camera): the prior of its learned model. Fixed a priori, before any run on S2.L1: a round figure
for a fine-tuned R-CNN person detector's recall of unoccluded people at its usual score threshold of 0.5;
not measured on these files."""


PUBLISHED_NOISE_DOF = 4.0
"""The fixed cameras' feet-pixel noise: Student-t with 4 degrees of freedom, the value Lange, Little & Taylor
(JASA 1989, "Robust statistical modeling using the t distribution") recommend where it is not estimated."""


def published_views(scenario: Scenario) -> tuple[CameraView, ...]:
    """The views of the recording's dataset file other than the recorded one that have boxes (the built-in
    PETS dataset's View_003 to View_008): their calibrations and published boxes
    (:func:`~ptztrack.builders.occupancy.recording_from_dataset`)."""
    recording = scenario.required_recording("a camera network over a recording")
    if recording.dataset is None:
        raise ScenarioError(
            "a camera network over a recording needs its dataset file (recording.dataset), whose other views' "
            "detections are the fixed cameras"
        )
    dataset = load_dataset(recording.dataset)
    others = [
        view.model_dump()
        for view in dataset.views
        if view.name != recording.dataset_view and view.detections is not None
    ]
    if not others:
        raise ScenarioError(
            f"{recording.dataset}: no view but {recording.dataset_view} has detections: a network needs fixed cameras"
        )
    return recording_from_dataset(dataset_from_dict({**dataset.model_dump(), "views": others}, dataset.name)).views


def published_camera_world(
    scenario: Scenario,
    scene: BuiltScene,
    view: CameraView,
    video_frame: np.ndarray,
    model_seed: np.random.SeedSequence | None = None,
) -> World:
    """The fixed camera of ``view`` (its calibration and boxes) in ``scene`` (see the module's docstring);
    video_frame : (T,) the frame of the view's boxes each step shows; model_seed : the stream of its
    detector model's draws."""
    if view.boxes is None or view.image_size_px is None:
        raise ScenarioError(f"{view.name}: a fixed camera of published detections needs its boxes and image size")
    virtual, pose = virtual_ptz(view.calibration, view.image_size_px, scenario.camera.image_size_px)
    grid = ActionGrid(pose[:1], pose[1:2], pose[2:])
    published = PublishedDetections(
        virtual.camera, view.calibration, view.boxes, video_frame, OccupancyParameters.min_box_score
    )
    return World(
        camera=virtual.camera,
        grid=grid,
        truth=scene.truth,
        backend=published,
        detector=published,
        area_polygon_m=scene.area_polygon_m,
        start_action=0,
        pose_source=commanded_pose,
        landing_error=LandingErrorParameters(),
        detector_model=detector_model(scenario, virtual.camera, model_seed, own=RecallModel.constant(PUBLISHED_RECALL)),
    )


def pets_network_world(scenario: Scenario, seed: int, ptz: bool, views: Sequence[CameraView]) -> NetworkWorld:
    """The network of the episode ``seed``: with ``ptz``, the PTZ camera first (the one-camera run's world),
    then a fixed camera per published view of ``views``, its detector model drawing from a stream spawned
    from the PTZ camera's model's (which spawning leaves as it was)."""
    if not ptz and not views:
        raise ScenarioError("a PETS camera network needs the PTZ camera or a published view")
    streams = episode_streams(seed)
    scene = build_scene(scenario, np.random.default_rng(streams.scene))
    worlds = []
    if ptz:
        worlds.append(camera_world(scenario, scene, tracker_seed=streams.tracker, model_seed=streams.detector_model))
    model_seeds = streams.detector_model.spawn(len(views))
    assert scene.recording is not None  # published_views asked for the recording
    worlds += [
        published_camera_world(scenario, scene, view, scene.recording.video_frame, seed)
        for view, seed in zip(views, model_seeds, strict=True)
    ]
    return NetworkWorld(tuple(worlds))


def published_network_parts(
    scenario: Scenario,
    world: NetworkWorld,
    ptz: bool,
    coordination: Coordination = "joint",
    method: InformationMethod = "intg",
) -> tuple[NetworkInformationPolicy, SharedBelief]:
    """The policy and the one belief of a network whose first camera is the PTZ camera (with ``ptz``)
    and whose other cameras are fixed cameras of published boxes: every camera's information-gain
    policy ``method`` deciding ``coordination``, and the fixed cameras' trackers as the module's
    docstring says."""
    fixed = [index > 0 or not ptz for index in range(len(world.cameras))]
    policy = policy_of_cameras(
        [(scenario, camera, is_fixed) for camera, is_fixed in zip(world.cameras, fixed, strict=True)],
        coordination,
        method,
    )
    tracker = belief_of_cameras([(scenario, camera) for camera in world.cameras])
    tracker.needs_a_second_camera = frozenset(index for index, is_fixed in enumerate(fixed) if is_fixed)
    for camera, is_fixed in zip(tracker.cameras, fixed, strict=True):
        if is_fixed:
            camera.parameters = replace(camera.parameters, noise_dof=PUBLISHED_NOISE_DOF, birth="outside_gates")
            camera.bias = PixelBias.centred(camera.V)
    return policy, tracker
