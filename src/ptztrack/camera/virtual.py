"""A virtual PTZ camera inside a calibrated recording (the paper's section 5.2).

The virtual camera stands at the recording camera's optical centre and is an
ordinary :class:`~ptztrack.geometry.ptz.PTZCamera` (level mount, pan about
the vertical), so the tracker and the policies use it unchanged. Its image at
a pose is the recorded frame resampled through the rays of the virtual
pixels: virtual pixel -> ray ``R_v^T K_v^-1 p`` -> recorded pixel through the
recording's full calibration, lens distortion included. This is the paper's
``G_ptz = K_c R_ptz K_ptz^-1`` with the distortion handled exactly, so the
virtual view is a true pinhole image and detections in it map to the ground
through the virtual camera's own homography.

Units: the recording's calibration is in millimetres, ptztrack's world in metres.
"""

from dataclasses import dataclass, field

import cv2
import numpy as np

from ptztrack.geometry.calibration import PinholeCalibration
from ptztrack.geometry.ptz import PTZCamera, intrinsics, rotation_world_to_camera

MM_PER_M = 1000.0
# The sampling maps of the last poses rendered are kept, up to this many bytes: a PTZ camera comes back to
# the same poses (the 140 of the PETS grid take 21 MB at 160 x 120 px).
MAP_CACHE_BYTES = 32 * 2**20


@dataclass(frozen=True)
class VirtualPTZ:
    """A virtual PTZ camera over a recording.

    camera : the virtual camera (centre in metres, virtual image size, f_min).
    recording : the recording camera's calibration (millimetres).
    recorded_size_px : (width, height) of the recorded frames.
    map_grid_px : where each virtual pixel reads the recording is computed exactly for every pixel
        (1) or every ``map_grid_px``-th pixel in both directions and interpolated bilinearly in
        between. The map is smooth: on a grid of 8 px a 640 x 480 view's map is within 0.005 px of
        the exact one (below cv2.remap's 1/32 px resolution) and takes 2.5 ms instead of 150-300 ms.
    """

    camera: PTZCamera
    recording: PinholeCalibration
    recorded_size_px: tuple[int, int]
    map_grid_px: int = 1
    _maps: dict = field(default_factory=dict, init=False, repr=False, compare=False)

    def pixel_centres(self) -> np.ndarray:
        """(h * w, 2) centres of the virtual pixels, row by row: pixel (row, col) at (col + 0.5, row + 0.5)."""
        width, height = self.camera.image_width_px, self.camera.image_height_px
        u, v = np.meshgrid(np.arange(width) + 0.5, np.arange(height) + 0.5)
        return np.c_[u.ravel(), v.ravel()]

    def sampling_maps(self, pose) -> tuple[np.ndarray, np.ndarray]:
        """Where each virtual pixel (centre) reads the recorded frame: two (h, w) float32 maps for cv2.remap
        (read-only: the maps of the last poses are kept, see ``MAP_CACHE_BYTES``)."""
        key = tuple(np.asarray(pose, dtype=float).tolist())
        maps = self._maps.get(key)
        if maps is None:
            maps = self._computed_maps(key)
            for single in maps:
                single.setflags(write=False)
            if (len(self._maps) + 1) * 2 * maps[0].nbytes > MAP_CACHE_BYTES and self._maps:
                del self._maps[next(iter(self._maps))]
            self._maps[key] = maps
        return maps

    def _computed_maps(self, pose) -> tuple[np.ndarray, np.ndarray]:
        width, height, step = self.camera.image_width_px, self.camera.image_height_px, self.map_grid_px
        if step == 1:
            centres, shape = self.pixel_centres(), (height, width)
        else:
            # Nodes at the centres of every step-th pixel, the last ones at or beyond the image's last pixel.
            columns, rows = (np.arange(0, -(-(size - 1) // step) * step + 1, step) for size in (width, height))
            u, v = np.meshgrid(columns + 0.5, rows + 0.5)
            centres, shape = np.c_[u.ravel(), v.ravel()], (len(rows), len(columns))
        pixels = np.c_[centres, np.ones(len(centres))]
        pose = np.asarray(pose, dtype=float)
        rays = pixels @ np.linalg.inv(intrinsics(self.camera, pose[2])).T @ rotation_world_to_camera(pose[0], pose[1])
        maps = self._maps_of_directions(rays, shape)
        if step > 1:
            # Pixel (i, j) lies at (j / step, i / step) among the nodes: multiples of 1/8 for a step of 8,
            # which remap's 1/32 px interpolation weights hold exactly.
            node_u, node_v = np.meshgrid(np.arange(width) / step, np.arange(height) / step)
            maps = cv2.remap(maps, node_u.astype(np.float32), node_v.astype(np.float32), cv2.INTER_LINEAR)
        return maps[..., 0], maps[..., 1]

    def maps_of_directions(self, directions) -> tuple[np.ndarray, np.ndarray]:
        """Sampling maps (two (h, w) float32) of the virtual pixels that look along world ``directions``
        (h * w, 3), row by row."""
        maps = self._maps_of_directions(directions, (self.camera.image_height_px, self.camera.image_width_px))
        return maps[..., 0], maps[..., 1]

    def _maps_of_directions(self, directions, shape: tuple[int, int]) -> np.ndarray:
        """One (rows, columns, 2) float32 array of where world ``directions`` read the recorded frame."""
        recorded = _project_directions(self.recording, directions)
        # The centre of recorded pixel (i, j) is at (i + 0.5, j + 0.5); remap indexes from 0.
        return (recorded - 0.5).reshape(*shape, 2).astype(np.float32)

    def render(self, frame, pose) -> np.ndarray:
        """The virtual view (h, w, 3) of a recorded frame; black where the recording does not reach."""
        return resample(frame, self.sampling_maps(pose), pose[2])

    def _recorded_normalised(self, recorded_px) -> np.ndarray:
        """Normalised (undistorted) recording coordinates (N, 2) of recorded pixels (N, 2)."""
        if len(recorded_px) == 0:
            return np.zeros((0, 2))
        return cv2.undistortPoints(
            np.asarray(recorded_px, dtype=float).reshape(-1, 1, 2), self.recording.K, self.recording.dist
        )[:, 0, :]

    def recorded_directions(self, recorded_px) -> np.ndarray:
        """World directions (N, 3) of recorded (distorted) pixels (N, 2), from the recording's centre."""
        normalised = self._recorded_normalised(recorded_px)
        R = self.recording.R
        # (u, v, 1) R_rec, written out per point (see recorded_to_virtual).
        return normalised[:, :1] * R[0] + normalised[:, 1:] * R[1] + R[2]

    def recorded_to_virtual(self, recorded_px, pose) -> np.ndarray:
        """Recorded (distorted) pixels (N, 2) to virtual pixels (N, 2) at ``pose``; NaN behind the virtual camera."""
        normalised = self._recorded_normalised(recorded_px)
        pose = np.asarray(pose, dtype=float)
        # (u, v, 1) R_rec R_v^T K^T, written out per point: a matrix product over all points at once
        # rounds each row differently depending on how many there are.
        M = self.recording.R @ rotation_world_to_camera(pose[0], pose[1]).T @ intrinsics(self.camera, pose[2]).T
        homogeneous = normalised[:, :1] * M[0] + normalised[:, 1:] * M[1] + M[2]
        with np.errstate(divide="ignore", invalid="ignore"):
            pixels = homogeneous[:, :2] / homogeneous[:, 2:]
        return np.where(homogeneous[:, 2:] > 0, pixels, np.nan)


def resample(frame, maps: tuple[np.ndarray, np.ndarray], zoom: float) -> np.ndarray:
    """A recorded frame read through sampling maps: area-averaged when the view is wider than the
    recording (zoom below 1), bilinear otherwise."""
    return cv2.remap(frame, maps[0], maps[1], cv2.INTER_AREA if zoom < 1 else cv2.INTER_LINEAR)


def _project_directions(recording: PinholeCalibration, directions) -> np.ndarray:
    """Recorded pixels (N, 2) of world directions (N, 3) seen from the recording's centre (distortion included)."""
    camera_directions = directions @ recording.R.T
    rotation_vector = np.zeros(3)
    pixels, _ = cv2.projectPoints(
        camera_directions.reshape(-1, 1, 3), rotation_vector, np.zeros(3), recording.K, recording.dist
    )
    behind = camera_directions[:, 2] <= 0
    pixels = pixels[:, 0, :]
    pixels[behind] = -1e6
    return pixels


def virtual_ptz(
    recording: PinholeCalibration, recorded_size_px=(768, 576), image_size_px=(160, 120), map_grid_px: int = 1
) -> tuple[VirtualPTZ, np.ndarray]:
    """The virtual PTZ camera over a recording, and the pose that reproduces the recorded view.

    At zoom 1 the virtual camera has the recording's field of view at
    ``image_size_px`` (the paper's 160 x 120 "zoom 1"): ``f_min`` is the
    recording's focal length scaled by the width ratio. Returns the camera and
    the (pan_deg, tilt_deg, 1) pose looking through the centre of the
    recorded image, which the recording's principal point need not be (the
    recording's small roll is not reproduced: the mount is level). map_grid_px : see :class:`VirtualPTZ`.
    """
    centre_m = -recording.R.T @ recording.t / MM_PER_M
    focal_px = 0.5 * (recording.K[0, 0] + recording.K[1, 1]) * image_size_px[0] / recorded_size_px[0]
    camera = PTZCamera(
        (float(centre_m[0]), float(centre_m[1]), float(centre_m[2])),
        int(image_size_px[0]),
        int(image_size_px[1]),
        float(focal_px),
    )
    image_centre_px = np.array([[recorded_size_px[0] / 2, recorded_size_px[1] / 2]], dtype=float)
    normalised = cv2.undistortPoints(image_centre_px.reshape(1, 1, 2), recording.K, recording.dist)[0, 0]
    forward = np.array([*normalised, 1.0]) @ recording.R
    forward /= np.linalg.norm(forward)
    pose = np.array([np.rad2deg(np.arctan2(forward[0], forward[1])), np.rad2deg(np.arcsin(-forward[2])), 1.0])
    return VirtualPTZ(camera, recording, tuple(recorded_size_px), map_grid_px), pose
