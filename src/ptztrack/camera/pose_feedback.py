"""Where the camera looks: the pose it lands at, and the pose the tracker believes.

A real PTZ camera lands near, not at, the pose it is sent to
(:class:`~ptztrack.config.PoseError`). The tracker maps detections to the
ground with one of three poses (:class:`~ptztrack.config.PoseFeedback`):
the commanded one, the true one (an oracle, for experiments), or the one
registered from the camera's own image against bundle-adjusted reference
views (the scale-invariant tracking paper; :mod:`ptztrack.geometry.registration`).

A pose source is called as ``source(step, commanded, actual)`` with (3,)
poses (pan_deg, tilt_deg, zoom) and returns the (3,) pose the tracker uses,
or None when it cannot tell (the loop then uses the commanded pose).
"""

from dataclasses import dataclass
from pathlib import Path
from typing import Callable

import numpy as np

from ptztrack.camera.virtual import VirtualPTZ, virtual_ptz
from ptztrack.config import PoseError, PoseFeedback, Scenario
from ptztrack.geometry.calibration import load_calibration
from ptztrack.geometry.registration import ReferenceIndex, build_index, load_index, register, save_index
from ptztrack.scene.pets import RecordedVideo

PoseSource = Callable[[int, np.ndarray, np.ndarray], np.ndarray | None]
# The reference views are rendered from this frame of the recording; live views come from later frames,
# where people have moved.
REFERENCE_FRAME = 0
# The stream that draws how roughly the reference views' poses are known: one for all runs and seeds,
# so that they share one reference index.
REFERENCE_SEED = 20091


def landed_pose(commanded, error: PoseError, rng: np.random.Generator) -> np.ndarray:
    """Where a camera sent to ``commanded`` (3,) lands: (pan_deg, tilt_deg, zoom) with the error model's
    bias and one draw of its noise. The zoom is not clipped to the lens's range: the error is symmetric."""
    commanded = np.asarray(commanded, dtype=float)
    pan_tilt_deg = commanded[:2] + np.asarray(error.pan_tilt_bias_deg) + rng.normal(0.0, error.pan_tilt_sigma_deg, 2)
    zoom = commanded[2] * error.zoom_bias * (1.0 + rng.normal(0.0, error.zoom_sigma))
    return np.array([*pan_tilt_deg, zoom])


def commanded_pose(step: int, commanded, actual) -> np.ndarray:
    """The pose source that trusts the command."""
    return np.asarray(commanded, dtype=float)


def true_pose(step: int, commanded, actual) -> np.ndarray:
    """The oracle pose source: where the camera really looks."""
    return np.asarray(actual, dtype=float)


def reference_poses(whole_frame_pose, pan_range_deg, tilt_range_deg, feedback: PoseFeedback) -> np.ndarray:
    """(L, 3) reference poses: a grid over the pan and tilt ranges (offsets from ``whole_frame_pose``) at
    each reference zoom, the whole-frame pose itself first (the calibrated view fixes the gauge).

    The tilt range is shrunk by 20 %: the extreme tilts of the action grid look mostly outside the
    recording, and their zoomed views are still matched against views a little inside.
    """
    pan_deg = np.linspace(*pan_range_deg, feedback.reference_pan_steps)
    tilt_deg = 0.8 * np.linspace(*tilt_range_deg, feedback.reference_tilt_steps)
    grid = np.array([[pan, tilt, zoom] for zoom in feedback.reference_zooms for tilt in tilt_deg for pan in pan_deg])
    grid[:, :2] += np.asarray(whole_frame_pose)[:2]
    first = np.array([whole_frame_pose[0], whole_frame_pose[1], 1.0])
    return np.vstack([first, grid[np.any(np.abs(grid - first) > 1e-9, axis=1)]])


def build_reference_index(
    virtual: VirtualPTZ, frame_bgr: np.ndarray, poses, feedback: PoseFeedback, rng: np.random.Generator
) -> ReferenceIndex:
    """The reference index of a virtual camera: views of ``frame_bgr`` rendered at ``poses`` (L, 3),
    bundle-adjusted from poses known only roughly (``reference_pose_sigma_deg``,
    ``reference_zoom_spread``), as a real camera's reference views would be; the first exactly."""
    poses = np.asarray(poses, dtype=float)
    rough = poses.copy()
    rough[1:, :2] += rng.normal(0.0, feedback.reference_pose_sigma_deg, (len(poses) - 1, 2))
    rough[1:, 2] *= rng.uniform(1 - feedback.reference_zoom_spread, 1 + feedback.reference_zoom_spread, len(poses) - 1)
    return build_index(virtual.camera, [virtual.render(frame_bgr, pose) for pose in poses], rough)


def cached_reference_index(path: str | Path | None, build: Callable[[], ReferenceIndex]) -> ReferenceIndex:
    """The index at ``path`` if that file exists; otherwise ``build()``, saved there when a path is given."""
    if path is not None and Path(path).exists():
        return load_index(path)
    index = build()
    if path is not None:
        save_index(path, index)
    return index


@dataclass
class RegisteredPose:
    """The pose source that registers the camera's image of each step.

    virtual : the camera at the registration resolution; index : its reference views;
    video : the recording; video_frame : (T,) the frame of each step.
    """

    virtual: VirtualPTZ
    index: ReferenceIndex
    video: RecordedVideo
    video_frame: np.ndarray

    def __post_init__(self):
        size = (self.virtual.camera.image_width_px, self.virtual.camera.image_height_px)
        if tuple(self.index.image_size_px) != size:
            raise ValueError(
                f"the registration index is of {self.index.image_size_px[0]}x{self.index.image_size_px[1]} px views, "
                f"but pose_feedback.image_size_px is {size[0]}x{size[1]}"
            )

    def __call__(self, step: int, commanded, actual) -> np.ndarray | None:
        image = self.virtual.render(self.video.frame(int(self.video_frame[step])), actual)
        registration = register(self.virtual.camera, self.index, image)
        return None if registration is None else registration.pose


def registration_camera(scenario: Scenario) -> tuple[VirtualPTZ, np.ndarray]:
    """The recording scenario's virtual camera at ``pose_feedback.image_size_px``, and its whole-frame pose."""
    recording = scenario.recording
    calibration = load_calibration(recording.calibration, recording.view)
    return virtual_ptz(calibration, recording.recorded_size_px, scenario.pose_feedback.image_size_px)


def reference_index(scenario: Scenario, camera: tuple[VirtualPTZ, np.ndarray] | None = None) -> ReferenceIndex:
    """The reference index of a recording scenario: views over its action grid's pan and tilt range,
    rendered from the recording's frame ``REFERENCE_FRAME``. Read from ``pose_feedback.index`` when
    that file exists; built otherwise (about a minute), and written there when a path is given.

    camera : ``registration_camera(scenario)``, when the caller has it already.
    """
    recording, feedback = scenario.recording, scenario.pose_feedback
    virtual, whole_frame_pose = camera or registration_camera(scenario)
    offsets = scenario.action_grid()
    poses = reference_poses(
        whole_frame_pose,
        (offsets.pan_deg.min(), offsets.pan_deg.max()),
        (offsets.tilt_deg.min(), offsets.tilt_deg.max()),
        feedback,
    )

    def build():
        frame = RecordedVideo(recording.video, recording.recorded_size_px).frame(REFERENCE_FRAME)
        return build_reference_index(virtual, frame, poses, feedback, np.random.default_rng(REFERENCE_SEED))

    return cached_reference_index(feedback.index, build)


def registered_pose_source(scenario: Scenario, video_frame: np.ndarray) -> RegisteredPose:
    """The registered pose source of a recording scenario whose step ``t`` shows frame ``video_frame[t]``."""
    recording = scenario.recording
    camera = registration_camera(scenario)
    video = RecordedVideo(recording.video, recording.recorded_size_px)
    return RegisteredPose(camera[0], reference_index(scenario, camera), video, video_frame)
