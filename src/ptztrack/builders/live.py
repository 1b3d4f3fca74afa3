"""Live runs from the configuration: the cameras connected, the loop run, and a live run turned into an
episode that the run metrics score (against a virtual camera's truth log,
:mod:`ptztrack.builders.virtual_camera`)."""

from collections.abc import Callable, Iterator, Sequence
from contextlib import contextmanager
from dataclasses import dataclass, replace
from typing import cast, get_args

import cv2
import numpy as np

from ptztrack.builders.camera_calibration import camera_spaces, pose_timeline
from ptztrack.builders.episode import episode_world, make_policy, make_tracker
from ptztrack.builders.live_registered import PoseSource, check_pose_source, registered_camera
from ptztrack.builders.network import Coordination, belief_of_cameras, policy_of_cameras
from ptztrack.builders.world import detector_model
from ptztrack.camera.live_camera import LiveONVIFCamera
from ptztrack.camera.onvif_client import CameraAddress, CameraError, ONVIFClient
from ptztrack.camera.recorded import RecordedPTZ
from ptztrack.config import (
    CameraCalibrationFile,
    Scenario,
)
from ptztrack.control.information_policy import InformationMethod
from ptztrack.detect.hog import HogPeopleDetector
from ptztrack.loop.alone import AlonePolicy, AloneTracker
from ptztrack.loop.live import LiveEpisode, PlanAhead, run_live_network, warm_up
from ptztrack.loop.steps import Episode, StepObserver, World
from ptztrack.loop.streams import episode_streams
from ptztrack.network.policy import NetworkInformationPolicy
from ptztrack.roles import NetworkPolicy, NetworkTracker, Policy
from ptztrack.track.tracker import tracks_ahead
from ptztrack.types import GroundTruth
from ptztrack.view.video import RenderView


def shown_steps(truth_log, times_s) -> np.ndarray:
    """The recording step (T,) a virtual camera showed at each epoch time (T,), from its truth log (n, 5)
    (:meth:`RecordingFeed.rows`); -1 before its first picture."""
    log = np.asarray(truth_log, dtype=float).reshape(-1, 5)
    index = np.searchsorted(log[:, 0], np.asarray(times_s, dtype=float), side="right") - 1
    return np.where(index >= 0, log[np.maximum(index, 0), 1], -1).astype(int)


def live_as_episode(world: World, live: LiveEpisode, truth_log=None) -> Episode:
    """A live run as an :class:`Episode`, one step per picture used: with a virtual camera's
    ``truth_log`` (n, 5), each step is scored against the truth of the recording step shown at its
    picture's capture time; without, against nobody (a real camera's run: no truth). Where the pose was
    not known, the commanded one stands in, counted as not known."""
    truth = world.truth
    steps = len(live.capture_time_s)
    if truth_log is None:
        positions_m = np.full((steps, 0, 2), np.nan)
        truth = GroundTruth(positions_m, np.zeros(0), np.zeros(0), truth.frame_rate_hz)
        shown = np.arange(steps)
    else:
        shown = np.clip(shown_steps(truth_log, live.capture_time_s), 0, truth.positions_m.shape[0] - 1)
    known = np.all(np.isfinite(live.poses), axis=1)
    poses = np.where(known[:, None], live.poses, live.commanded)
    return Episode(
        GroundTruth(truth.positions_m[shown], truth.heights_m, truth.widths_m, truth.frame_rate_hz),
        world.camera,
        world.area_polygon_m,
        actions=np.array([world.grid.nearest(pose) for pose in live.commanded], dtype=int).reshape(-1),
        commanded=live.commanded.reshape(-1, 3),
        poses=poses.reshape(-1, 3),
        tracker_poses=poses.reshape(-1, 3),
        pose_known=known,
        decision_s=np.nan_to_num(live.decision_s),
        tracks=live.tracks,
        detections=live.detections,
    )


def live_pictures(live: LiveEpisode) -> RenderView:
    """``render_view`` for a live run's video (:mod:`ptztrack.view.video`): the picture each step
    used, as the run kept it (``keep_images``)."""

    def render(step: int, pose) -> np.ndarray:
        image = cv2.imdecode(np.frombuffer(live.images[step], np.uint8), cv2.IMREAD_COLOR)
        if image is None:
            raise ValueError(f"the live run kept no picture for step {step}: run it with keep_images")
        return image

    return render


def live_world(
    scenario: Scenario, calibration: CameraCalibrationFile, seed: int, model_seed: np.random.SeedSequence | None = None
) -> World:
    """The world a live run decides in: the scenario's grid, detector and area, with the calibration's
    camera position and focal length where it gives them; its detector model draws from ``model_seed``
    (default: the one-camera episode's stream); its HOG reads the luma unless the scenario says otherwise
    (:func:`streamed`) and keeps no memo of the views it has seen (a camera's pictures never repeat)."""
    world = episode_world(streamed(scenario), seed)
    camera = world.camera
    if calibration.position_m is not None:
        camera = replace(camera, position_m=calibration.position_m)
    if calibration.f_min_px is not None:
        camera = replace(camera, f_min_px=calibration.f_min_px)
    model_seed = episode_streams(seed).detector_model if model_seed is None else model_seed
    detector = world.detector
    if isinstance(detector, HogPeopleDetector):
        detector = replace(detector, remember_views=False)
    return replace(world, camera=camera, detector=detector, detector_model=detector_model(scenario, camera, model_seed))


def streamed(scenario: Scenario) -> Scenario:
    """``scenario`` with its HOG reading the pictures' luma where it leaves that unset (``hog_luma``): a
    camera's video stream keeps its colour at a quarter of the pixels, and compresses it."""
    if scenario.detector.hog_luma is not None:
        return scenario
    return scenario.model_copy(update={"detector": scenario.detector.model_copy(update={"hog_luma": True})})


def plan_ahead_of(scenario: Scenario) -> PlanAhead:
    """The tracks a live policy plans on: the belief's predicted from the capture of the picture decided on
    to a step after the decision, as an offline policy plans on the tracks predicted to the step its
    picture is taken at."""
    step_s, tracker = 1.0 / scenario.frame_rate_hz, scenario.tracker
    motion = (tracker.acceleration_sigma_m_s2, tracker.velocity_time_constant_s)
    return lambda tracks, since_capture_s: tracks_ahead(tracks, since_capture_s + step_s, *motion)


def _live_camera(
    address: CameraAddress,
    calibration: CameraCalibrationFile,
    timeout_s: float,
    transport: str,
    world: World,
    pose_source: PoseSource,
) -> LiveONVIFCamera:
    """The live ONVIF camera at ``address`` (not started), with the calibration's spaces, move times and
    stream delay, its pose from GetStatus (``pose_source`` 'status') or from its pictures ('registered':
    :func:`~ptztrack.builders.live_registered.registered_camera`, in ``world``)."""

    def connect() -> ONVIFClient:
        client = ONVIFClient(address, timeout_s)
        try:
            client.connect()
        except CameraError:
            client.close()
            raise
        return client

    if pose_source == "registered":
        return registered_camera(connect, calibration, world, transport)
    return LiveONVIFCamera(
        connect, camera_spaces(calibration), pose_timeline(calibration), calibration.image_delay_s, transport
    )


def run_live_episode(
    scenario: Scenario,
    calibrations: Sequence[CameraCalibrationFile],
    addresses: Sequence[CameraAddress],
    policy: str,
    steps: int,
    time_scale: float,
    seed: int,
    coordination: Coordination = "joint",
    timeout_s: float = 5.0,
    transport: str = "tcp",
    keep_images: bool = False,
    observe: Callable[[list[World], Policy | NetworkInformationPolicy], StepObserver | None] | None = None,
    pose_source: PoseSource = "status",
) -> tuple[list[World], tuple[LiveEpisode, ...]]:
    """Connect to the cameras at ``addresses``, one or many (each with its calibration of ``calibrations``,
    in the same order; a :class:`CameraError` if one cannot be used), and run them on ``steps`` of their
    pictures in all with one ground belief (:func:`ptztrack.loop.live.run_live_network`), the recording's
    time passing ``time_scale`` times as fast as the wall clock's. The cameras are released at the end
    (Ctrl-C included).

    One camera runs ``policy`` (any registered name) with the scenario's tracker, as the network of it
    alone. Several run each camera's information-gain policy ``policy`` ('intg' or 'smpl') with its
    calibrated move times, deciding ``coordination`` (the network's policy,
    :func:`ptztrack.builders.network.policy_of_cameras`), each camera's EKF tracker updating the one belief
    in turn (:func:`ptztrack.builders.network.belief_of_cameras`).

    observe : ``observe(worlds, policy)`` gives the run's step observer (a live view, say); ``policy`` is
    the camera's own for one camera, the network's for several.
    transport : the RTSP stream over 'tcp' or 'udp'; keep_images : keep the pictures used (for a video).
    pose_source : each camera's pose from GetStatus ('status') or registered from its pictures against a
    reference index it sweeps at the start ('registered'; :mod:`ptztrack.builders.live_registered`); a
    ScenarioError before connecting for 'status' with a calibration whose camera reports no positions.
    Returns every camera's world and its :class:`LiveEpisode` (each step's tracks are the belief's).
    """
    if len(calibrations) != len(addresses) or not addresses:
        raise ValueError(f"{len(addresses)} camera addresses with {len(calibrations)} calibrations")
    check_pose_source(calibrations, pose_source)
    network = live_network(scenario, calibrations, policy, seed, coordination)
    with connected_cameras(addresses, calibrations, network.worlds, timeout_s, transport, pose_source) as cameras:
        observer = None if observe is None else observe(network.worlds, network.shown)
        live = run_live_network(
            network.worlds, network.policy, network.tracker, cameras, steps, time_scale, seed, observer,
            keep_images, plan_ahead_of(scenario),
        )  # fmt: skip
    return network.worlds, live


@dataclass(frozen=True)
class LiveNetwork:
    """What a live run decides and tracks with: every camera's world, the network's policy and belief,
    and ``shown``, the policy a view draws (the camera's own for one camera, the network's for several)."""

    worlds: list[World]
    policy: NetworkPolicy
    tracker: NetworkTracker
    shown: Policy | NetworkInformationPolicy


def live_network(
    scenario: Scenario,
    calibrations: Sequence[CameraCalibrationFile],
    policy: str,
    seed: int,
    coordination: Coordination = "joint",
) -> LiveNetwork:
    """The worlds, policy and belief of a live run of the cameras of ``calibrations``, warmed up
    (:func:`~ptztrack.loop.live.warm_up`), as :func:`run_live_episode` describes them."""
    # The first camera's detector model draws from the one-camera run's stream, every other from its own.
    model_seed = episode_streams(seed).detector_model
    model_seeds = [model_seed, *model_seed.spawn(len(calibrations) - 1)]
    worlds = [
        live_world(scenario, calibration, seed, camera_seed)
        for calibration, camera_seed in zip(calibrations, model_seeds, strict=True)
    ]
    if len(worlds) == 1:
        shown = make_policy(policy, scenario, worlds[0])
        alone = make_tracker(None, scenario, worlds[0])
        warm_up(worlds[0], shown, alone)
        return LiveNetwork(worlds, AlonePolicy(shown), AloneTracker(alone), shown)
    if not (isinstance(policy, str) and policy in get_args(InformationMethod)):
        raise ValueError(f"a network of cameras decides by intg or smpl, not {policy}")
    method = cast(InformationMethod, policy)
    network_policy = policy_of_cameras([(scenario, world, False) for world in worlds], coordination, method)
    belief = belief_of_cameras([(scenario, world) for world in worlds])
    for world, member, updater in zip(worlds, network_policy.cameras, belief.cameras, strict=True):
        warm_up(world, member.policy, updater)
    return LiveNetwork(worlds, network_policy, belief, network_policy)


@contextmanager
def connected_cameras(
    addresses: Sequence[CameraAddress],
    calibrations: Sequence[CameraCalibrationFile],
    worlds: Sequence[World],
    timeout_s: float = 5.0,
    transport: str = "tcp",
    pose_source: PoseSource = "status",
) -> Iterator[list[LiveONVIFCamera]]:
    """The live cameras at ``addresses`` (each with its calibration and world, in the same order),
    connected and started; a :class:`CameraError` if one cannot be used. All are closed when the block
    ends (Ctrl-C included)."""
    cameras: list[LiveONVIFCamera] = []
    try:
        # Each camera starts as soon as it is connected, so that one that cannot be is closed with the others.
        for address, calibration, world in zip(addresses, calibrations, worlds, strict=True):
            cameras.append(_live_camera(address, calibration, timeout_s, transport, world, pose_source))
            cameras[-1].start()
        yield cameras
    finally:
        for camera in cameras:
            camera.close()


def offline_counterpart(scenario: Scenario, world: World, live: LiveEpisode, truth_log) -> Scenario:
    """``scenario`` narrowed to the recording's steps a live run against the virtual camera saw
    (:func:`shown_span`), with the live run's detector (:func:`streamed`): the offline run to compare it
    with."""
    return recording_steps_scenario(scenario, world, *shown_span(truth_log, live.capture_time_s))


def shown_span(truth_log, times_s) -> tuple[int, int]:
    """The first and the last recording step a virtual camera showed at the epoch times (T,) of a run's
    pictures, from its truth log (n, 5): the step of the first picture and the latest step of any (within
    one play of the recording)."""
    shown = np.maximum(shown_steps(truth_log, times_s), 0)
    return int(shown[0]), int(shown.max())


def recording_steps_scenario(scenario: Scenario, world: World, first_step: int, last_step: int) -> Scenario:
    """``scenario`` narrowed to the recording's steps ``first_step`` to ``last_step`` (those of ``world``,
    built from it), with a live run's detector (:func:`streamed`)."""
    recording = scenario.required_recording("the offline counterpart of a live run")
    backend = world.backend
    assert isinstance(backend, RecordedPTZ)
    first = int(backend.scene.video_frame[first_step])
    steps = last_step - first_step + 1
    frame_range = (first, first + steps * recording.frame_step)
    narrowed = recording.model_copy(update={"frame_range": frame_range})
    return streamed(scenario).model_copy(update={"recording": narrowed, "frames": steps})
