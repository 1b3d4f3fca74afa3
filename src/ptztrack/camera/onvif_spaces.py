"""An ONVIF PTZ camera's normalised position spaces and the camera model's pose.

ONVIF cameras report and take positions in generic spaces: pan and tilt in
[-1, 1], zoom in [0, 1]. The model's pose is (pan_deg, tilt_deg, zoom), the
zoom being the focal length over the widest one
(:class:`ptztrack.geometry.ptz.PTZCamera`). A camera's calibration file maps
one onto the other: pan and tilt linearly between the degrees at -1 and +1,
zoom through a measured curve of (normalised, zoom) points, piecewise linear
and increasing (lenses are not linear in their zoom motor's position).

Move times follow the model Frigate fits from timed moves: a move of an axis
takes ``intercept + slope x distance`` seconds (distance in degrees, or in
zoom factor), the axes moving at once, so a move takes as long as its
slowest axis.
"""

from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class CameraSpaces:
    """The mapping of a camera's normalised spaces to the model's pose.

    pan_deg, tilt_deg : the degrees at normalised -1 and +1 (either may decrease);
    zoom_curve : (K, 2) (normalised zoom, zoom factor) points, both increasing, K >= 2.
    """

    pan_deg: tuple[float, float]
    tilt_deg: tuple[float, float]
    zoom_curve: tuple[tuple[float, float], ...]

    def pose(self, normalised) -> np.ndarray:
        """The pose (..., 3) (pan_deg, tilt_deg, zoom) of normalised positions (..., 3) (x, y, zoom)."""
        normalised = np.asarray(normalised, dtype=float)
        curve = np.asarray(self.zoom_curve, dtype=float)
        return np.stack(
            [
                _between(self.pan_deg, normalised[..., 0]),
                _between(self.tilt_deg, normalised[..., 1]),
                np.interp(normalised[..., 2], curve[:, 0], curve[:, 1]),
            ],
            axis=-1,
        )

    def normalised(self, pose) -> np.ndarray:
        """The normalised positions (..., 3) of poses (..., 3), clipped to the spaces."""
        pose = np.asarray(pose, dtype=float)
        curve = np.asarray(self.zoom_curve, dtype=float)
        return np.stack(
            [
                np.clip(_fraction(self.pan_deg, pose[..., 0]), -1.0, 1.0),
                np.clip(_fraction(self.tilt_deg, pose[..., 1]), -1.0, 1.0),
                np.interp(pose[..., 2], curve[:, 1], curve[:, 0]),
            ],
            axis=-1,
        )


@dataclass(frozen=True)
class AxisSpeeds:
    """The mechanics a (virtual) camera moves at: degrees per second of pan and tilt, zoom factor per second."""

    pan_deg_s: float
    tilt_deg_s: float
    zoom_per_s: float


@dataclass(frozen=True)
class MoveTimes:
    """``intercept_s + slope x distance`` per axis: (intercept_s, slope) of pan and tilt (s per degree)
    and of zoom (s per unit of zoom factor)."""

    pan: tuple[float, float]
    tilt: tuple[float, float]
    zoom: tuple[float, float]

    def seconds(self, start, end):
        """How long moves from pose ``start`` (3,) to poses ``end`` (..., 3) take: the slowest axis's
        time, an axis that does not move taking none; shape (...)."""
        distance = np.abs(np.asarray(end, dtype=float) - np.asarray(start, dtype=float))
        intercept, slope = np.array([self.pan, self.tilt, self.zoom], dtype=float).T
        return np.max(np.where(distance > 0, intercept + slope * distance, 0.0), axis=-1)


def _between(ends, normalised) -> np.ndarray:
    low, high = ends
    return low + (np.asarray(normalised) + 1.0) / 2.0 * (high - low)


def _fraction(ends, value) -> np.ndarray:
    low, high = ends
    return 2.0 * (np.asarray(value) - low) / (high - low) - 1.0
