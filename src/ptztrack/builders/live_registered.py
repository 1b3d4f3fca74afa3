"""``ptztrack live --pose registered``: a live camera placed by its own pictures, built from its
calibration (:class:`~ptztrack.camera.live_camera.LiveONVIFCamera` with a sweep).

The camera's spaces are the calibration's (with ``positions: false`` its ground view's preset stands at
normalised 0, and its ends are the world degrees a relative move of -1 and +1 from there reaches).
The sweep starts from the ground view (GotoPreset, then the widest zoom; its world pose the ground
view's pan and tilt at the zoom curve's first zoom factor), or, without one, from an AbsoluteMove to the
action grid's start pose, whose pose the spaces give.
"""

from collections.abc import Callable, Sequence
from typing import Literal

import numpy as np

from ptztrack.builders.camera_calibration import camera_spaces
from ptztrack.camera.live_camera import LiveONVIFCamera, Sweep
from ptztrack.camera.onvif_client import ONVIFClient
from ptztrack.camera.onvif_spaces import CameraSpaces, MoveTimes
from ptztrack.camera.reference_sweep import KnownView
from ptztrack.camera.registered_timeline import RegisteredTimeline
from ptztrack.config import CameraCalibrationFile, ScenarioError
from ptztrack.loop.steps import World

PoseSource = Literal["status", "registered"]
POSE_SOURCES: tuple[PoseSource, ...] = ("status", "registered")


def check_pose_source(calibrations: Sequence[CameraCalibrationFile], pose_source: str) -> None:
    """Refuse a pose source the cameras cannot have: a ScenarioError of one line for GetStatus's poses
    (``status``) of a camera whose calibration says it reports no positions."""
    if pose_source not in POSE_SOURCES:
        raise ValueError(f"pose source {pose_source!r}: expected one of {', '.join(POSE_SOURCES)}")
    if pose_source == "status" and any(not calibration.positions for calibration in calibrations):
        raise ScenarioError("this camera reports no positions: use --pose registered")


def known_view(calibration: CameraCalibrationFile, spaces: CameraSpaces, start_pose) -> KnownView:
    """Where the sweep starts and its world pose (module docstring); ``start_pose`` (3,) the action grid's."""
    if calibration.ground_view is not None:
        ground = calibration.ground_view
        widest = float(calibration.zoom_curve[0][1])
        return KnownView(np.array([ground.pan_deg, ground.tilt_deg, widest]), preset=ground.preset)
    position = spaces.normalised(start_pose)
    return KnownView(spaces.pose(position), position=position)


def registered_camera(
    connect: Callable[[], ONVIFClient], calibration: CameraCalibrationFile, world: World, transport: str
) -> LiveONVIFCamera:
    """The live camera that ``connect()`` reaches (not started), placed by its pictures in ``world`` (its
    action grid and camera model), with the calibration's move times, stream delay and capture times'
    uncertainty."""
    sections = calibration.move_times
    timeline = RegisteredTimeline(MoveTimes(sections.pan, sections.tilt, sections.zoom), calibration.capture_time_sd_s)
    spaces = camera_spaces(calibration)
    sweep = Sweep(known_view(calibration, spaces, world.grid.poses[world.start_action]), world.grid.poses, world.camera)
    return LiveONVIFCamera(connect, spaces, timeline, calibration.image_delay_s, transport, sweep=sweep)
