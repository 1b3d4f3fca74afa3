"""The virtual ONVIF camera of ``ptztrack serve-camera`` over a recording: its pictures, its mechanics,
its told calibration and the geometries it can hide.

The virtual camera shows a recording scenario's virtual PTZ view at the pose its mechanics have
reached, the recording advancing in real time (times ``time_scale``, so that a slower client keeps
the recording's rate). It logs, for every picture, the wall-clock time, the scenario step shown and
the pose: the truth a live run is scored against, each step taking the truth of the step its image
showed.
"""

import threading
import time
from collections.abc import Sequence
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import TYPE_CHECKING

import cv2
import numpy as np

from ptztrack.builders.camera_calibration import camera_spaces
from ptztrack.builders.episode import episode_world
from ptztrack.camera.onvif_spaces import AxisSpeeds, CameraSpaces
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
from ptztrack.loop.steps import World
from ptztrack.virtual_onvif.head import MOVE_LATENCY_S

if TYPE_CHECKING:
    from ptztrack.virtual_onvif.server import VirtualONVIFCamera


# With ``serve-camera --supersample N`` the virtual camera renders its pictures N times finer in both
# directions and averages them down, as a camera's lens and sensor average the light over each pixel: its
# 160 x 120 view point-sampled from a 768 x 576 recording aliases, which moves the same scene's features
# between views (docs: decisions). The geometry's calibration is measured at VIRTUAL_SUPERSAMPLE; the
# live runs compared with offline ones keep 1, the offline tables' own rendering. The finer maps are
# computed every SUPERSAMPLED_MAP_GRID_PX-th pixel (VirtualPTZ.map_grid_px).
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
    supersample: int = 1
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
    supersample: int = 1,
) -> tuple["VirtualONVIFCamera", RecordingFeed]:
    """The virtual ONVIF camera over ``scenario``'s recording (not started) and the feed that logs its
    truth (``feed``, to go on with one).

    geometry : the camera's true spaces (:func:`virtual_geometry`; None: :func:`virtual_calibration`'s);
    positions, absolute_moves, presets_path, move_latency_s : as
    :class:`~ptztrack.virtual_onvif.server.VirtualONVIFCamera` takes them (a presets file that is not one
    raises an InputError naming it); supersample : a new feed's (:class:`RecordingFeed`).
    """
    try:  # the server is ipycam's, installed apart (it must not bring opencv-python): only here is it needed
        from ptztrack.virtual_onvif.server import VirtualONVIFCamera
    except ImportError:
        raise RuntimeError(
            "the virtual ONVIF camera needs ipycam: pip install --no-deps ipycam==1.3.0 (docs: Real cameras)"
        ) from None
    if feed is None:
        feed = RecordingFeed(
            episode_world(scenario, 0), 1.0 / scenario.frame_rate_hz, time_scale, supersample=supersample
        )
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
    supersample: int = 1,
) -> list[tuple["VirtualONVIFCamera", RecordingFeed]]:
    """Virtual ONVIF cameras over one play of ``scenario``'s recording (not started), one on each of
    ``ports`` (0: any free port), each with the feed that logs its truth: they show the same recording
    step at the same moment, each at its own pose, and move each by its own mechanics (as
    :func:`virtual_onvif_camera`, each of the one ``geometry`` and modes); camera k keeps its presets in
    :func:`camera_presets_path` of ``presets_path``."""

    def camera(number: int, port: int, feed: RecordingFeed | None) -> tuple["VirtualONVIFCamera", RecordingFeed]:
        presets = None if presets_path is None else camera_presets_path(presets_path, number)
        return virtual_onvif_camera(
            scenario,
            time_scale,
            port,
            username,
            password,
            feed,
            geometry,
            positions,
            absolute_moves,
            presets,
            supersample=supersample,
        )

    first_camera, first_feed = camera(1, ports[0], None)
    # The recording's clock starts now for every camera, not at each one's first picture.
    first_feed.started_s = time.time()
    cameras = [(first_camera, first_feed)]
    for number, port in enumerate(ports[1:], start=2):
        feed = RecordingFeed(
            first_feed.world, first_feed.step_s, time_scale, started_s=first_feed.started_s,
            render_lock=first_feed.render_lock, supersample=supersample,
        )  # fmt: skip
        cameras.append(camera(number, port, feed))
    return cameras
