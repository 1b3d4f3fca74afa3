"""A fixed camera of a recording whose only evidence is a detector's published boxes.

The camera of one calibrated recorded view (PETS 2009 S2.L1's View_003 to
View_008, say) has no video here, only the boxes a detector found in it
(MOTChallenge files). As a camera of the loop it is the virtual PTZ camera at
the recording camera's optical centre (:func:`ptztrack.camera.virtual.virtual_ptz`),
held at the pose that shows the recorded view: it renders no image, knows
nobody (:class:`~ptztrack.roles.CameraBackend`), and its detections
(:class:`~ptztrack.roles.Detector`) are the boxes of the step's recorded
frame, scored at least ``min_score``, with their feet (bottom centre) and head
(top centre) carried into the virtual camera's image along their rays:

    recorded pixel -> its ray through the calibration, distortion inverted
    (:func:`~ptztrack.geometry.calibration.pixel_rays`) -> the virtual
    camera's pixel of that ray (``K R d``, :func:`~ptztrack.geometry.ptz.projection_matrix`).

The two cameras share their centre, so a ray keeps every point on it: the
ground point the tracker's homography gives a feet pixel is the point where
the box's feet ray meets the ground through the view's own calibration.
"""

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from ptztrack.geometry.calibration import PinholeCalibration, pixel_rays
from ptztrack.geometry.ptz import PTZCamera, projection_matrix
from ptztrack.roles import CameraBackend
from ptztrack.scene.pets import box_feet_px
from ptztrack.types import Detections


def recorded_to_view(calibration: PinholeCalibration, camera: PTZCamera, pose, pixels_px) -> np.ndarray:
    """Recorded (distorted) pixels (N, 2) of a calibrated view to the pixels (N, 2) of ``camera`` at
    ``pose`` (3,) that see along the same rays; NaN for a ray behind ``camera``. ``camera`` must stand at the
    calibration's optical centre (as :func:`~ptztrack.camera.virtual.virtual_ptz` puts it)."""
    _, directions = pixel_rays(calibration, pixels_px)
    homogeneous = directions @ projection_matrix(camera, pose)[:, :3].T
    with np.errstate(divide="ignore", invalid="ignore"):
        pixels = homogeneous[:, :2] / homogeneous[:, 2:]
    return np.where(homogeneous[:, 2:] > 0, pixels, np.nan)


@dataclass(frozen=True)
class PublishedDetections:
    """A fixed camera that shows only a detector's published boxes (see the module's docstring).

    camera : the virtual camera the tracker maps the detections with (at the calibration's centre).
    calibration : the recorded view's calibration (millimetres; distorted pixels).
    boxes : per recorded frame, the boxes (K, 5) ``(left, top, width, height, score)`` px of the view.
    video_frame : (T,) the recorded frame of each step.
    min_score : boxes scored lower are not reported.
    within_image : report only the boxes whose feet and head fall inside ``camera``'s image at the pose
    (a PTZ camera looking at part of the recorded view); False reports every box in front of it.
    """

    camera: PTZCamera
    calibration: PinholeCalibration
    boxes: Sequence[np.ndarray]
    video_frame: np.ndarray
    min_score: float
    within_image: bool = False

    def image(self, step: int, pose) -> None:
        return None

    def people(self, step: int, pose) -> None:
        return None

    def detect(
        self, camera: CameraBackend, step: int, pose, rng: np.random.Generator, believed_pose=None
    ) -> Detections:
        """The boxes of ``step``'s recorded frame scored at least ``min_score``, as feet and heights in the
        virtual camera's image at ``pose``; boxes whose feet or head ray points away from it are left out,
        and with ``within_image`` those whose feet or head fall outside its image.
        Draws nothing from ``rng``: the boxes are the published ones."""
        frame = int(self.video_frame[step])
        found = self.boxes[frame] if frame < len(self.boxes) else np.zeros((0, 5))
        found = found[found[:, 4] >= self.min_score]
        left, top, width = found[:, 0], found[:, 1], found[:, 2]
        heads_px = np.stack([left + width / 2, top], axis=-1)
        points = recorded_to_view(self.calibration, self.camera, pose, np.concatenate([box_feet_px(found), heads_px]))
        feet, heads = points[: len(found)], points[len(found) :]
        seen = np.all(np.isfinite(feet), axis=1) & np.all(np.isfinite(heads), axis=1)
        if self.within_image:
            size_px = (self.camera.image_width_px, self.camera.image_height_px)
            with np.errstate(invalid="ignore"):
                seen &= np.all((feet >= 0) & (feet <= size_px) & (heads >= 0) & (heads <= size_px), axis=1)
        return Detections(
            feet[seen],
            feet[seen, 1] - heads[seen, 1],
            np.full(int(seen.sum()), -1, dtype=int),
            found[seen, 4],
        )
