"""The virtual ONVIF camera's PTZ head: three axes that each travel towards a target at a speed.

A pose is (pan_deg, tilt_deg, zoom), the model's (:mod:`ptztrack.geometry.ptz`). Each axis moves
linearly from where it is to its target at its rate (degrees or zoom factor per second) times the
fraction of full speed asked for, so a move takes ``|target - here| / (rate x fraction)`` seconds and
the head reports MOVING until it arrives.
"""

import threading
import time
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from ptztrack.camera.onvif_spaces import AxisSpeeds, CameraSpaces


@dataclass(frozen=True)
class _Ramp:
    """One axis's motion: from ``start`` at ``start_s`` linearly to ``end`` at ``end_s`` (monotonic
    seconds), still before and after."""

    start_s: float
    start: float
    end_s: float
    end: float

    def at(self, t_s: float) -> float:
        if t_s >= self.end_s:
            return self.end
        return self.start + (self.end - self.start) * max(t_s - self.start_s, 0.0) / (self.end_s - self.start_s)

    def moving(self, t_s: float) -> bool:
        return t_s < self.end_s


def _ramp(t_s: float, here: float, there: float, rate_per_s: float) -> _Ramp:
    return _Ramp(t_s, here, t_s + abs(there - here) / rate_per_s, there)


def head_axes(spaces: CameraSpaces, speeds: AxisSpeeds) -> tuple[np.ndarray, np.ndarray]:
    """A head's axes for a camera's ``spaces`` and ``speeds``: the limits (3, 2), (low, high) of pan_deg,
    tilt_deg and zoom factor, and the full rates (3,) per second."""
    zoom_factors = [zoom for _, zoom in spaces.zoom_curve]
    limits = np.array([sorted(spaces.pan_deg), sorted(spaces.tilt_deg), [zoom_factors[0], zoom_factors[-1]]])
    return limits, np.array([speeds.pan_deg_s, speeds.tilt_deg_s, speeds.zoom_per_s], dtype=float)


class Head:
    """The PTZ head in the model's units, axes (pan_deg, tilt_deg, zoom), each on its own ramp.

    limits : (3, 2) lowest and highest value of each axis; rates_per_s : (3,) each axis's full speed.
    """

    def __init__(self, pose: np.ndarray, limits: np.ndarray, rates_per_s: np.ndarray):
        self.limits, self.rates_per_s = limits, rates_per_s
        self._lock = threading.Lock()
        now_s = time.monotonic()
        self._ramps = [_Ramp(now_s, float(value), now_s, float(value)) for value in pose]

    def now(self) -> tuple[float, np.ndarray, list[bool]]:
        """The monotonic time, the pose (3,) then and whether each axis is moving."""
        with self._lock:
            t_s = time.monotonic()
            return t_s, np.array([ramp.at(t_s) for ramp in self._ramps]), [ramp.moving(t_s) for ramp in self._ramps]

    def move_to(self, target: Sequence[float | None], speed: Sequence[float]) -> None:
        """Each axis with a target (None: left as it is) travels to it, clipped to its limits, at ``speed``
        (fraction of full speed)."""
        with self._lock:
            t_s = time.monotonic()
            for axis, there in enumerate(target):
                if there is not None:
                    here = self._ramps[axis].at(t_s)
                    there = float(np.clip(there, *self.limits[axis]))
                    self._ramps[axis] = _ramp(t_s, here, there, self.rates_per_s[axis] * speed[axis])

    def run(self, velocity: Sequence[float | None], duration_s: float) -> None:
        """Each axis with a velocity (fraction of full speed, signed; None: left as it is) runs for
        ``duration_s``, or until it reaches its limit."""
        with self._lock:
            t_s = time.monotonic()
            for axis, fraction in enumerate(velocity):
                if fraction is None:
                    continue
                here = self._ramps[axis].at(t_s)
                if fraction == 0:
                    self._ramps[axis] = _Ramp(t_s, here, t_s, here)
                else:
                    there = float(np.clip(here + fraction * self.rates_per_s[axis] * duration_s, *self.limits[axis]))
                    self._ramps[axis] = _ramp(t_s, here, there, abs(fraction) * self.rates_per_s[axis])

    def stop(self, axes: Sequence[bool]) -> None:
        with self._lock:
            t_s = time.monotonic()
            for axis, stopping in enumerate(axes):
                if stopping:
                    here = self._ramps[axis].at(t_s)
                    self._ramps[axis] = _Ramp(t_s, here, t_s, here)
