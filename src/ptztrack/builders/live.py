"""Live cameras from the configuration: the calibration's spaces, the virtual ONVIF camera's pictures of
a recording, and a live run turned into an episode that the run metrics score.

The virtual camera (``ptztrack serve-camera``) shows a recording scenario's
virtual PTZ view at the pose its mechanics have reached, the recording
advancing in real time (times ``time_scale``, so that a slower client keeps
the recording's rate). It logs, for every picture, the wall-clock time, the
scenario step shown and the pose: the truth a live run is scored against,
each step taking the truth of the step its image showed.
"""

import threading
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import TYPE_CHECKING, cast, get_args

import cv2
import numpy as np

from ptztrack.builders.episode import episode_world, make_policy, make_tracker
from ptztrack.builders.network import Coordination, belief_of_cameras, policy_of_cameras
from ptztrack.builders.world import detector_model
from ptztrack.camera.live_camera import LiveONVIFCamera
from ptztrack.camera.onvif_client import CameraAddress, CameraError, ONVIFClient
from ptztrack.camera.onvif_spaces import AxisSpeeds, CameraSpaces, MoveTimes
from ptztrack.camera.pose_timeline import PoseTimeline
from ptztrack.camera.recorded import RecordedPTZ
from ptztrack.camera.stream import thumbnail
from ptztrack.camera.virtual import VirtualPTZ
from ptztrack.config import (
    VIRTUAL_CAMERA_CALIBRATION,
    CameraCalibrationFile,
    Scenario,
    ScenarioError,
    load_camera_calibration,
)
from ptztrack.control.information_policy import InformationMethod
from ptztrack.loop.alone import AlonePolicy, AloneTracker
from ptztrack.loop.live import LiveEpisode, PlanAhead, run_live_network, warm_up
from ptztrack.loop.steps import Episode, StepObserver, World
from ptztrack.loop.streams import episode_streams
from ptztrack.network.policy import NetworkInformationPolicy
from ptztrack.roles import NetworkPolicy, NetworkTracker, Policy
from ptztrack.track.tracker import tracks_ahead
from ptztrack.types import GroundTruth
from ptztrack.view.video import RenderView
from ptztrack.virtual_onvif.head import MOVE_LATENCY_S

if TYPE_CHECKING:
    from ptztrack.virtual_onvif.server import VirtualONVIFCamera


def camera_spaces(calibration: CameraCalibrationFile) -> CameraSpaces:
    return CameraSpaces(
        calibration.pan_deg, calibration.tilt_deg, tuple((float(z), float(f)) for z, f in calibration.zoom_curve)
    )


# The virtual camera renders its pictures this many times finer in both directions and averages them down,
# as a camera's lens and sensor average the light over each pixel: its 160 x 120 view point-sampled from a
# 768 x 576 recording would alias, which moves the same scene's features between views (docs: decisions).
# Its maps are computed every SUPERSAMPLED_MAP_GRID_PX-th pixel (VirtualPTZ.map_grid_px).
VIRTUAL_SUPERSAMPLE, SUPERSAMPLED_MAP_GRID_PX = 4, 8


@dataclass
class RecordingFeed:
    """The pictures of the virtual ONVIF camera: ``world``'s view of its recording at a pose, the
    recording's step advancing with the time since ``started_s`` (epoch seconds; the first picture's
    when None), ``step_s`` apart divided by ``time_scale``, from its start again after its last step; a
    camera restarted with the same feed goes on with the recording. ``log`` holds (epoch s, step, pan,
    tilt, zoom) per picture, and ``thumbnails``, where it is a list, each picture's :func:`thumbnail` (to
    tell afterwards which picture a client received).

    Several cameras over one recording (:func:`virtual_onvif_cameras`) have a feed each, with the same
    ``started_s`` (so they show the same step at the same moment) and the same ``render_lock`` (their
    world's video is read by one camera at a time). Its pictures are rendered ``supersample`` times
    finer than the world's camera and area-averaged down to its size."""

    world: World
    step_s: float
    time_scale: float = 1.0
    log: list[tuple[float, int, float, float, float]] = field(default_factory=list)
    thumbnails: list[np.ndarray] | None = None
    started_s: float | None = None
    render_lock: threading.Lock = field(default_factory=threading.Lock, repr=False)
    supersample: int = VIRTUAL_SUPERSAMPLE
    _lock: threading.Lock = field(default_factory=threading.Lock, repr=False)
    _fine: RecordedPTZ | None = field(default=None, init=False, repr=False)

    def render(self, pose, elapsed_s: float) -> np.ndarray:
        """The picture at ``pose``; ``elapsed_s`` (the camera's own clock) is not used: the feed's is."""
        now_s = time.time()
        self.started_s = now_s if self.started_s is None else self.started_s
        steps = self.world.truth.positions_m.shape[0]
        step = int((now_s - self.started_s) * self.time_scale / self.step_s) % steps
        with self.render_lock:
            image = self._fine_backend().image(step, np.asarray(pose, dtype=float))
        if image is None:
            raise RuntimeError("the virtual ONVIF camera needs a recording with a video")
        if self.supersample > 1:
            camera = self.world.camera
            image = cv2.resize(image, (camera.image_width_px, camera.image_height_px), interpolation=cv2.INTER_AREA)
        small = None if self.thumbnails is None else thumbnail(image)
        with self._lock:
            self.log.append((now_s, step, *(float(value) for value in pose)))
            if small is not None and self.thumbnails is not None:
                self.thumbnails.append(small)
        return image

    def _fine_backend(self):
        """The world's recording seen by a camera ``supersample`` times finer (the world's own at 1)."""
        backend = self.world.backend
        if self.supersample == 1 or not isinstance(backend, RecordedPTZ):
            return backend
        if self._fine is None:
            virtual, scale = backend.virtual, self.supersample
            camera = replace(
                virtual.camera,
                image_width_px=virtual.camera.image_width_px * scale,
                image_height_px=virtual.camera.image_height_px * scale,
                f_min_px=virtual.camera.f_min_px * scale,
            )
            fine = VirtualPTZ(camera, virtual.recording, virtual.recorded_size_px, SUPERSAMPLED_MAP_GRID_PX)
            self._fine = replace(backend, virtual=fine)
        return self._fine

    @property
    def duration_s(self) -> float:
        """Wall-clock seconds the recording takes to play once."""
        return self.world.truth.positions_m.shape[0] * self.step_s / self.time_scale

    def rows(self, start: int = 0) -> np.ndarray:
        """The log from row ``start`` on, (n, 5): epoch s, step, pan_deg, tilt_deg, zoom."""
        with self._lock:
            return np.asarray(self.log[start:], dtype=float).reshape(-1, 5)


TRUTH_LOG_HEADER = "time_s,step,pan_deg,tilt_deg,zoom"


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


# The virtual camera's mechanics, a priori: an IP PTZ dome's preset moves (Axis and Sony domes turn at
# 100-450 deg/s; 90 deg/s is a slow one) and a zoom through 1x-4x in a second, each move starting
# MOVE_LATENCY_S after its command (virtual_onvif.head); its stream at PAL's 25 fps.
VIRTUAL_SPEEDS = AxisSpeeds(pan_deg_s=90.0, tilt_deg_s=90.0, zoom_per_s=3.0)
VIRTUAL_FRAME_RATE_HZ = 25.0
# A stream holds a picture back by about one frame interval (the encoder's and the decoder's pipelines).
VIRTUAL_IMAGE_DELAY_S = 1.0 / VIRTUAL_FRAME_RATE_HZ


def virtual_calibration() -> CameraCalibrationFile:
    """The calibration of ``ptztrack serve-camera``'s camera (``--calibration virtual``): its spaces, its
    moves' times from its latency and speeds, and its stream's delay."""
    return _with_virtual_mechanics(VIRTUAL_CAMERA_CALIBRATION)


def _with_virtual_mechanics(spaces: dict) -> CameraCalibrationFile:
    """The calibration of a virtual camera of ``spaces`` (the fields of a calibration): its moves' times,
    ``MOVE_LATENCY_S + distance / speed`` per axis, and its stream's delay."""
    speeds, latency_s = VIRTUAL_SPEEDS, MOVE_LATENCY_S
    move_times = {
        "pan": (latency_s, 1 / speeds.pan_deg_s),
        "tilt": (latency_s, 1 / speeds.tilt_deg_s),
        "zoom": (latency_s, 1 / speeds.zoom_per_s),
    }
    return CameraCalibrationFile.model_validate(
        {**spaces, "move_times": move_times, "image_delay_s": VIRTUAL_IMAGE_DELAY_S}
    )


@dataclass(frozen=True)
class GeometryPriors:
    """The a-priori ranges a hidden geometry of the virtual camera is drawn from (:func:`virtual_geometry`),
    each uniform; the geometry maps the normalised ONVIF spaces to the model's pose.

    pan_span_deg : the pan from normalised -1 to +1 (a dome's 180 degrees to a 350-degree head);
    start_pan : where in the normalised pan the recording's start pose falls (the offset of the pan);
    tilt_down_deg : the depression at normalised tilt -1 (ONVIF's sign: +1 looks up), 60-90 degrees
    down; tilt_up_deg : the depression at +1, 5-30 degrees above the horizon;
    widest_zoom : the zoom factor z0 at normalised 0 (relative to the recording's focal length: a
    camera at most a little narrower than the recording); longest_zoom : zmax at normalised 1;
    zoom_gamma : the curve's shape, through ``zoom_points`` points n in [0, 1]:
    ``zoom(n) = z0 (zmax / z0) ** (n ** gamma)`` (a lens's zoom grows faster or slower than its motor).
    """

    pan_span_deg: tuple[float, float] = (180.0, 350.0)
    start_pan: tuple[float, float] = (-0.6, 0.6)
    tilt_down_deg: tuple[float, float] = (60.0, 90.0)
    tilt_up_deg: tuple[float, float] = (-30.0, -5.0)
    widest_zoom: tuple[float, float] = (1.0, 1.15)
    longest_zoom: tuple[float, float] = (6.0, 10.0)
    zoom_gamma: tuple[float, float] = (0.7, 1.4)
    zoom_points: int = 11


def virtual_geometry(
    scenario: Scenario, seed: int | None = None, path: str | Path | None = None
) -> CameraCalibrationFile:
    """The true calibration of the virtual camera over ``scenario``'s recording: its geometry (pan_deg,
    tilt_deg, zoom_curve), the recording camera's position_m and f_min_px, and the virtual camera's
    mechanics and stream (:func:`virtual_calibration`'s move times and delay).

    The geometry is drawn from ``numpy.random.default_rng(seed)`` within :class:`GeometryPriors`, or
    read from the calibration file at ``path`` (its pan_deg, tilt_deg and zoom_curve; its position_m and
    f_min_px, if given, must be the recording camera's: the virtual camera stands at the recording's
    optical centre, its zoom factor relative to the recording's f_min_px), or with neither is
    :func:`virtual_calibration`'s. The recording's start pan and tilt must lie within it (its zoom is
    brought within the zoom curve: :func:`_virtual_start_pose`). A :class:`ScenarioError` of one line
    otherwise, or for a negative seed, or for both a seed and a path.
    """
    if seed is not None and path is not None:
        raise ScenarioError("a virtual camera's geometry is drawn from a seed or read from a file, not both")
    if seed is None and path is None:
        return virtual_calibration()
    world = episode_world(scenario, 0)
    camera, start = world.camera, world.grid.poses[world.start_action]
    recording: dict[str, tuple[float, ...] | float] = {
        "position_m": tuple(float(value) for value in camera.position_m),
        "f_min_px": float(camera.f_min_px),
    }
    if path is not None:
        source, given = str(path), load_camera_calibration(path)
        for name, value in recording.items():
            if getattr(given, name) is not None and not np.allclose(getattr(given, name), value, rtol=1e-6, atol=0.0):
                raise ScenarioError(
                    f"{path}: {name} {getattr(given, name)} is not the recording camera's {value}: the virtual "
                    f"camera stands at the recording's optical centre (leave {name} out, or give {value})"
                )
        spaces = {"pan_deg": given.pan_deg, "tilt_deg": given.tilt_deg, "zoom_curve": given.zoom_curve}
    else:
        assert seed is not None
        if seed < 0:
            raise ScenarioError(f"the geometry's seed {seed} is negative; expected a whole number >= 0")
        source, spaces = f"the geometry of seed {seed}", _drawn_geometry(np.random.default_rng(seed), start)
    truth = _with_virtual_mechanics({**spaces, **recording})
    for axis, name in ((0, "pan_deg"), (1, "tilt_deg")):
        ends = sorted(getattr(truth, name))
        if not ends[0] <= start[axis] <= ends[1]:
            raise ScenarioError(
                f"{source}: {name} {list(getattr(truth, name))} does not contain the recording's start "
                f"{name.partition('_')[0]} {start[axis]:.6g} deg"
            )
    return truth


def _drawn_geometry(rng: np.random.Generator, start, priors: GeometryPriors = GeometryPriors()) -> dict:
    """pan_deg, tilt_deg and zoom_curve drawn within ``priors`` around the start pose ``start`` (3,)."""
    span_deg, start_pan = rng.uniform(*priors.pan_span_deg), rng.uniform(*priors.start_pan)
    low_deg = float(start[0]) - (start_pan + 1.0) / 2.0 * span_deg
    tilt_deg = (float(rng.uniform(*priors.tilt_down_deg)), float(rng.uniform(*priors.tilt_up_deg)))
    widest, longest = rng.uniform(*priors.widest_zoom), rng.uniform(*priors.longest_zoom)
    gamma = rng.uniform(*priors.zoom_gamma)
    normalised = np.linspace(0.0, 1.0, priors.zoom_points)
    factors = widest * (longest / widest) ** (normalised**gamma)
    return {
        "pan_deg": (low_deg, low_deg + float(span_deg)),
        "tilt_deg": tilt_deg,
        "zoom_curve": [(float(n), float(z)) for n, z in zip(normalised, factors, strict=True)],
    }


def _virtual_start_pose(world: World, spaces: CameraSpaces) -> np.ndarray:
    """Where the virtual camera starts, and its home: the recording's start pose (3,), its zoom brought
    within the spaces' zoom range (a camera whose widest view is narrower than the recording's starts at
    its widest)."""
    start = np.array(world.grid.poses[world.start_action], dtype=float)
    zoom_factors = [factor for _, factor in spaces.zoom_curve]
    start[2] = np.clip(start[2], zoom_factors[0], zoom_factors[-1])
    return start


def pose_timeline(calibration: CameraCalibrationFile) -> PoseTimeline:
    """The timeline of a camera's poses with its calibrated move times and capture times' uncertainty."""
    move_times = MoveTimes(calibration.move_times.pan, calibration.move_times.tilt, calibration.move_times.zoom)
    return PoseTimeline(move_times, calibration.capture_time_sd_s)


def virtual_onvif_camera(
    scenario: Scenario,
    time_scale: float,
    port: int,
    username: str = "",
    password: str = "",
    feed: RecordingFeed | None = None,
    geometry: CameraCalibrationFile | None = None,
    positions: bool = True,
    absolute_moves: bool = True,
    presets_path: Path | None = None,
    move_latency_s: float = MOVE_LATENCY_S,
) -> tuple["VirtualONVIFCamera", RecordingFeed]:
    """The virtual ONVIF camera over ``scenario``'s recording (not started) and the feed that logs its
    truth (``feed``, to go on with one).

    geometry : the camera's true spaces (:func:`virtual_geometry`; None: :func:`virtual_calibration`'s);
    positions, absolute_moves, presets_path, move_latency_s : as
    :class:`~ptztrack.virtual_onvif.server.VirtualONVIFCamera` takes them (a presets file that is not one
    raises an InputError naming it).
    """
    try:  # the server is ipycam's, installed apart (it must not bring opencv-python): only here is it needed
        from ptztrack.virtual_onvif.server import VirtualONVIFCamera
    except ImportError:
        raise RuntimeError(
            "the virtual ONVIF camera needs ipycam: pip install --no-deps ipycam==1.3.0 (docs: Real cameras)"
        ) from None
    if feed is None:
        feed = RecordingFeed(episode_world(scenario, 0), 1.0 / scenario.frame_rate_hz, time_scale)
    world = feed.world
    spaces = camera_spaces(virtual_calibration() if geometry is None else geometry)
    camera = VirtualONVIFCamera(
        feed.render,
        spaces,
        VIRTUAL_SPEEDS,
        _virtual_start_pose(world, spaces),
        (world.camera.image_width_px, world.camera.image_height_px),
        port=port,
        username=username,
        password=password,
        # A camera's stream rate, and at least twice per step of the recording.
        frame_rate_hz=max(VIRTUAL_FRAME_RATE_HZ, 2.0 * scenario.frame_rate_hz * time_scale),
        f_min_px=world.camera.f_min_px,
        move_latency_s=move_latency_s,
        positions=positions,
        absolute_moves=absolute_moves,
        presets_path=presets_path,
    )
    return camera, feed


def camera_presets_path(path: Path, number: int) -> Path:
    """The presets file of camera ``number`` (from 1) of several given ``path``: ``path`` for the first,
    ``-number`` before its suffix for the others (presets.json, presets-2.json, ...)."""
    return path if number == 1 else path.with_name(f"{path.stem}-{number}{path.suffix}")


def virtual_onvif_cameras(
    scenario: Scenario,
    time_scale: float,
    ports: Sequence[int],
    username: str = "",
    password: str = "",
    geometry: CameraCalibrationFile | None = None,
    positions: bool = True,
    absolute_moves: bool = True,
    presets_path: Path | None = None,
) -> list[tuple["VirtualONVIFCamera", RecordingFeed]]:
    """Virtual ONVIF cameras over one play of ``scenario``'s recording (not started), one on each of
    ``ports`` (0: any free port), each with the feed that logs its truth: they show the same recording
    step at the same moment, each at its own pose, and move each by its own mechanics (as
    :func:`virtual_onvif_camera`, each of the one ``geometry`` and modes); camera k keeps its presets in
    :func:`camera_presets_path` of ``presets_path``."""

    def camera(number: int, port: int, feed: RecordingFeed | None) -> tuple["VirtualONVIFCamera", RecordingFeed]:
        presets = None if presets_path is None else camera_presets_path(presets_path, number)
        return virtual_onvif_camera(
            scenario, time_scale, port, username, password, feed, geometry, positions, absolute_moves, presets
        )

    first_camera, first_feed = camera(1, ports[0], None)
    # The recording's clock starts now for every camera, not at each one's first picture.
    first_feed.started_s = time.time()
    cameras = [(first_camera, first_feed)]
    for number, port in enumerate(ports[1:], start=2):
        feed = RecordingFeed(
            first_feed.world, first_feed.step_s, time_scale, started_s=first_feed.started_s,
            render_lock=first_feed.render_lock,
        )  # fmt: skip
        cameras.append(camera(number, port, feed))
    return cameras


def live_world(
    scenario: Scenario, calibration: CameraCalibrationFile, seed: int, model_seed: np.random.SeedSequence | None = None
) -> World:
    """The world a live run decides in: the scenario's grid, detector and area, with the calibration's
    camera position and focal length where it gives them; its detector model draws from ``model_seed``
    (default: the one-camera episode's stream); its HOG reads the luma unless the scenario says otherwise
    (:func:`streamed`)."""
    world = episode_world(streamed(scenario), seed)
    camera = world.camera
    if calibration.position_m is not None:
        camera = replace(camera, position_m=calibration.position_m)
    if calibration.f_min_px is not None:
        camera = replace(camera, f_min_px=calibration.f_min_px)
    model_seed = episode_streams(seed).detector_model if model_seed is None else model_seed
    return replace(world, camera=camera, detector_model=detector_model(scenario, camera, model_seed))


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
    step_s, acceleration_sigma_m_s2 = 1.0 / scenario.frame_rate_hz, scenario.tracker.acceleration_sigma_m_s2
    return lambda tracks, since_capture_s: tracks_ahead(tracks, since_capture_s + step_s, acceleration_sigma_m_s2)


def _live_camera(
    address: CameraAddress, calibration: CameraCalibrationFile, timeout_s: float, transport: str
) -> LiveONVIFCamera:
    """The live ONVIF camera at ``address`` (not started), with the calibration's spaces, move times and
    stream delay."""

    def connect() -> ONVIFClient:
        client = ONVIFClient(address, timeout_s)
        try:
            client.connect()
        except CameraError:
            client.close()
            raise
        return client

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
    Returns every camera's world and its :class:`LiveEpisode` (each step's tracks are the belief's).
    """
    if len(calibrations) != len(addresses) or not addresses:
        raise ValueError(f"{len(addresses)} camera addresses with {len(calibrations)} calibrations")
    # The first camera's detector model draws from the one-camera run's stream, every other from its own.
    model_seed = episode_streams(seed).detector_model
    model_seeds = [model_seed, *model_seed.spawn(len(addresses) - 1)]
    worlds = [
        live_world(scenario, calibration, seed, camera_seed)
        for calibration, camera_seed in zip(calibrations, model_seeds, strict=True)
    ]
    shown: Policy | NetworkInformationPolicy
    if len(worlds) == 1:
        shown = make_policy(policy, scenario, worlds[0])
        alone = make_tracker(None, scenario, worlds[0])
        warm_up(worlds[0], shown, alone)
        network_policy: NetworkPolicy = AlonePolicy(shown)
        tracker: NetworkTracker = AloneTracker(alone)
    elif isinstance(policy, str) and policy in get_args(InformationMethod):
        method = cast(InformationMethod, policy)
        shown = policy_of_cameras([(scenario, world, False) for world in worlds], coordination, method)
        belief = belief_of_cameras([(scenario, world) for world in worlds])
        for world, member, updater in zip(worlds, shown.cameras, belief.cameras, strict=True):
            warm_up(world, member.policy, updater)
        network_policy, tracker = shown, belief
    else:
        raise ValueError(f"a network of cameras decides by intg or smpl, not {policy}")
    cameras: list[LiveONVIFCamera] = []
    try:
        # Each camera starts as soon as it is connected, so that one that cannot be is closed with the others.
        for address, calibration in zip(addresses, calibrations, strict=True):
            cameras.append(_live_camera(address, calibration, timeout_s, transport))
            cameras[-1].start()
        observer = None if observe is None else observe(worlds, shown)
        live = run_live_network(
            worlds, network_policy, tracker, cameras, steps, time_scale, seed, observer, keep_images,
            plan_ahead_of(scenario),
        )  # fmt: skip
    finally:
        for camera in cameras:
            camera.close()
    return worlds, live


def offline_counterpart(scenario: Scenario, world: World, live: LiveEpisode, truth_log) -> Scenario:
    """``scenario`` narrowed to the recording's steps a live run against the virtual camera saw, from the
    first its pictures showed to the last (within one play of the recording), with the live run's
    detector (:func:`streamed`): the offline run to compare it with."""
    recording = scenario.required_recording("the offline counterpart of a live run")
    backend = world.backend
    assert isinstance(backend, RecordedPTZ)
    shown = np.maximum(shown_steps(truth_log, live.capture_time_s), 0)
    first_step, last_step = int(shown[0]), int(shown.max())
    first = int(backend.scene.video_frame[first_step])
    steps = last_step - first_step + 1
    frame_range = (first, first + steps * recording.frame_step)
    narrowed = recording.model_copy(update={"frame_range": frame_range})
    return streamed(scenario).model_copy(update={"recording": narrowed, "frames": steps})
