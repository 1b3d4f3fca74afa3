"""Where the camera looks: the pose it lands at, and the pose the tracker believes.

A real PTZ camera lands near, not at, the pose it is sent to
(:class:`LandingErrorParameters`). The tracker maps detections to the ground with one
of three poses (``pose_feedback.source`` of a scenario):
the commanded one, the true one (an oracle, for experiments), or the one
registered from the camera's own image against bundle-adjusted reference
views (the scale-invariant tracking paper; :mod:`ptztrack.geometry.registration`).

A pose source is called as ``source(step, commanded, actual)`` with (3,)
poses (pan_deg, tilt_deg, zoom) and returns the (3,) pose the tracker uses,
or None when it cannot tell (the loop then uses the commanded pose).
"""

from collections.abc import Callable, Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ptztrack.camera.live_view import render_view
from ptztrack.camera.parameters import LandingErrorParameters, LiveViewParameters
from ptztrack.camera.virtual import VirtualPTZ
from ptztrack.geometry.registration import ReferenceIndex, build_index, load_index, register, save_index
from ptztrack.scene.pets import RecordedVideo


def landed_pose(commanded, error: LandingErrorParameters, rng: np.random.Generator) -> np.ndarray:
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


def reference_poses(
    whole_frame_pose, pan_range_deg, tilt_range_deg, pan_steps: int, tilt_steps: int, zooms
) -> np.ndarray:
    """(L, 3) reference poses: a grid of ``pan_steps`` x ``tilt_steps`` over the pan and tilt ranges
    (offsets from ``whole_frame_pose``) at each of ``zooms``, the whole-frame pose itself first (the
    calibrated view fixes the gauge).

    The tilt range is shrunk by 20 %: the extreme tilts of the action grid look mostly outside the
    recording, and their zoomed views are still matched against views a little inside.
    """
    pan_deg = np.linspace(pan_range_deg[0], pan_range_deg[1], pan_steps)
    tilt_deg = 0.8 * np.linspace(tilt_range_deg[0], tilt_range_deg[1], tilt_steps)
    grid = np.array([[pan, tilt, zoom] for zoom in zooms for tilt in tilt_deg for pan in pan_deg])
    grid[:, :2] += np.asarray(whole_frame_pose)[:2]
    first = np.array([whole_frame_pose[0], whole_frame_pose[1], 1.0])
    return np.vstack([first, grid[np.any(np.abs(grid - first) > 1e-9, axis=1)]])


def build_reference_index(
    virtual: VirtualPTZ,
    frames_bgr: Sequence[np.ndarray],
    poses,
    pose_sigma_deg: float,
    zoom_spread: float,
    rng: np.random.Generator,
) -> ReferenceIndex:
    """The reference index of a virtual camera: view l rendered from ``frames_bgr[l]`` at ``poses[l]``
    ((L, 3); the camera sweeps its field of regard while people walk), bundle-adjusted from poses
    known only roughly (pan and tilt to ``pose_sigma_deg``, zoom within ``zoom_spread``), as a real
    camera's reference views would be; the first exactly. The reference views are exact pinhole
    views: they stand for views undistorted with the camera's calibration, taken once."""
    poses = np.asarray(poses, dtype=float)
    rough = poses.copy()
    rough[1:, :2] += rng.normal(0.0, pose_sigma_deg, (len(poses) - 1, 2))
    rough[1:, 2] *= rng.uniform(1 - zoom_spread, 1 + zoom_spread, len(poses) - 1)
    views = [virtual.render(frame, pose) for frame, pose in zip(frames_bgr, poses, strict=True)]
    return build_index(virtual.camera, views, rough)


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
    video : the recording; video_frame : (T,) the frame of each step; live : how the camera's
    views depart from the pinhole model (:mod:`ptztrack.camera.live_view`), None for exact views.
    """

    virtual: VirtualPTZ
    index: ReferenceIndex
    video: RecordedVideo
    video_frame: np.ndarray
    live: LiveViewParameters | None = None

    def __post_init__(self):
        size = (self.virtual.camera.image_width_px, self.virtual.camera.image_height_px)
        if tuple(self.index.image_size_px) != size:
            raise ValueError(
                f"the registration index is of {self.index.image_size_px[0]}x{self.index.image_size_px[1]} px views, "
                f"but pose_feedback.image_size_px is {size[0]}x{size[1]}"
            )

    def __call__(self, step: int, commanded, actual) -> np.ndarray | None:
        image = render_view(self.virtual, self.video.frame(int(self.video_frame[step])), actual, self.live)
        registration = register(self.virtual.camera, self.index, image)
        return None if registration is None else registration.pose
