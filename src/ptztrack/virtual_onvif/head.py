"""The virtual ONVIF camera's PTZ head: three axes that each travel towards a target at a speed.

A pose is (pan_deg, tilt_deg, zoom), the model's (:mod:`ptztrack.geometry.ptz`). A command takes
effect ``latency_s`` after it is received, as a real head's does; until then each axis goes on as
it was. From then, each axis it moves travels linearly from where it is to its target at its rate
(degrees or zoom factor per second) times the fraction of full speed asked for, so a move commanded
at t arrives at

    t + latency_s + |target - here(t + latency_s)| / (rate x fraction),

and the head reports the axis MOVING from the command until it arrives. An axis at rest that a
command leaves where it is does not move, and is not reported moving. Stop halts at once.
"""

import threading
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass, replace

import numpy as np

from ptztrack.camera.onvif_spaces import AxisSpeeds, CameraSpaces

# A PTZ dome answers a command in 0.1-0.3 s (a priori): the virtual head's moves start this long after it.
MOVE_LATENCY_S = 0.2


@dataclass(frozen=True)
class _Ramp:
    """One axis's motion: from ``start`` at ``start_s`` linearly to ``end`` at ``end_s`` (monotonic
    seconds), still after; before ``start_s``, as ``before`` goes (None: still at ``start``)."""

    start_s: float
    start: float
    end_s: float
    end: float
    before: "_Ramp | None" = None

    def at(self, t_s: float) -> float:
        if t_s < self.start_s:
            return self.start if self.before is None else self.before.at(t_s)
        if t_s >= self.end_s:
            return self.end
        return self.start + (self.end - self.start) * (t_s - self.start_s) / (self.end_s - self.start_s)

    def moving(self, t_s: float) -> bool:
        return t_s < self.end_s

    def since(self, t_s: float) -> "_Ramp":
        """The same motion from ``t_s`` on: the motions before it that are over by then dropped."""
        if self.before is None:
            return self
        return replace(self, before=None if t_s >= self.start_s else self.before.since(t_s))


def _still(t_s: float, value: float) -> _Ramp:
    return _Ramp(t_s, value, t_s, value)


def head_axes(spaces: CameraSpaces, speeds: AxisSpeeds) -> tuple[np.ndarray, np.ndarray]:
    """A head's axes for a camera's ``spaces`` and ``speeds``: the limits (3, 2), (low, high) of pan_deg,
    tilt_deg and zoom factor, and the full rates (3,) per second."""
    zoom_factors = [zoom for _, zoom in spaces.zoom_curve]
    limits = np.array([sorted(spaces.pan_deg), sorted(spaces.tilt_deg), [zoom_factors[0], zoom_factors[-1]]])
    return limits, np.array([speeds.pan_deg_s, speeds.tilt_deg_s, speeds.zoom_per_s], dtype=float)


class Head:
    """The PTZ head in the model's units, axes (pan_deg, tilt_deg, zoom), each on its own ramp.

    limits : (3, 2) lowest and highest value of each axis; rates_per_s : (3,) each axis's full speed;
    latency_s : how long after a command its moves start (module docstring); clock : monotonic seconds now.
    """

    def __init__(
        self,
        pose: np.ndarray,
        limits: np.ndarray,
        rates_per_s: np.ndarray,
        latency_s: float = MOVE_LATENCY_S,
        clock: Callable[[], float] = time.monotonic,
    ):
        if not latency_s >= 0:
            raise ValueError(f"latency_s {latency_s} must be >= 0")
        self.limits, self.rates_per_s, self.latency_s, self._clock = limits, rates_per_s, latency_s, clock
        self._lock = threading.Lock()
        now_s = clock()
        self._ramps = [_still(now_s, float(value)) for value in pose]

    def now(self) -> tuple[float, np.ndarray, list[bool]]:
        """The clock's time, the pose (3,) then and whether each axis is moving (or about to)."""
        with self._lock:
            t_s = self._clock()
            return t_s, np.array([ramp.at(t_s) for ramp in self._ramps]), [ramp.moving(t_s) for ramp in self._ramps]

    def move_to(self, target: Sequence[float | None], speed: Sequence[float]) -> None:
        """Each axis with a target (None: left as it is) travels to it, clipped to its limits, at ``speed``
        (fraction of full speed)."""
        with self._lock:
            t_s = self._clock()
            for axis, there in enumerate(target):
                if there is not None:
                    self._command(t_s, axis, self.rates_per_s[axis] * speed[axis], target=there)

    def run(self, velocity: Sequence[float | None], duration_s: float) -> None:
        """Each axis with a velocity (fraction of full speed, signed, in the model's direction; None: left as
        it is) runs for ``duration_s``, or until it reaches its limit; a velocity of 0 halts it."""
        with self._lock:
            t_s = self._clock()
            for axis, fraction in enumerate(velocity):
                if fraction is None:
                    continue
                rate_per_s = fraction * self.rates_per_s[axis]
                self._command(t_s, axis, abs(rate_per_s), step=rate_per_s * duration_s)

    def stop(self, axes: Sequence[bool]) -> None:
        """Each axis named halts at once where it is, its commands not yet started dropped."""
        with self._lock:
            t_s = self._clock()
            for axis, stopping in enumerate(axes):
                if stopping:
                    self._ramps[axis] = _still(t_s, self._ramps[axis].at(t_s))

    def _command(
        self, t_s: float, axis: int, rate_per_s: float, target: float | None = None, step: float = 0.0
    ) -> None:
        """A command received at ``t_s``: ``latency_s`` later, ``axis`` heads from where it is then (here) to
        ``target``, or without one to ``here + step``, clipped to its limits, at ``rate_per_s``; an axis at
        rest that it would leave where it is is left alone."""
        ramp = self._ramps[axis]

        def there(here: float) -> float:
            return float(np.clip(here + step if target is None else target, *self.limits[axis]))

        if not ramp.moving(t_s) and there(ramp.end) == ramp.end:
            return
        start_s = t_s + self.latency_s
        here = ramp.at(start_s)
        end = there(here)
        end_s = start_s + (abs(end - here) / rate_per_s if end != here else 0.0)
        self._ramps[axis] = _Ramp(start_s, here, end_s, end, ramp.since(t_s))
