"""Where a camera that moves in its own time was at any moment: its GetStatus samples, interpolated,
and its move-time model (``camera calibrate``) past the last sample.

Between two samples ``(t0, p0)`` and ``(t1, p1)`` the pose at ``t`` is
``p0 + (p1 - p0) (t - t0) / (t1 - t0)`` and its standard deviation, per
axis, the distance the axis covers in the time a capture time is uncertain
by: ``|p1 - p0| / (t1 - t0) x capture_time_sd_s``. Past the last sample,
the camera heads for the last target sent after it at the speeds of its
move-time model, and the pose is uncertain by what it covers in the time
since the sample, ``speed x sqrt(capture_time_sd_s^2 + (t - t_last)^2 / 3)``
(the uniform distribution's spread over a move that may have begun any time
since), never more than the move's length.
"""

import threading
from collections import deque
from dataclasses import dataclass

import numpy as np

from ptztrack.camera.onvif_spaces import MoveTimes

# Samples older than this are dropped: a picture is looked up within a second of its capture.
KEEP_S = 10.0


@dataclass(frozen=True)
class PoseAt:
    """The pose (3,) (pan_deg, tilt_deg, zoom) at a moment, and its standard deviation (3,)."""

    pose: np.ndarray
    sd: np.ndarray


class PoseTimeline:
    """GetStatus samples and the targets sent, on the epoch clock, shared between threads.

    move_times : the camera's move-time model (None: its moves take no time), which times a move to tell
        when it can have landed; its slopes' inverses are the axes' ``speeds`` (3,) (deg/s, deg/s, zoom
        factor per s), None where a slope is not measured (then a pose past the last sample is the last
        sample's, uncertain by nothing while it stood still and by the move's length while it moved).
    capture_time_sd_s : how uncertain a capture time is (s); a priori half a frame at 25 fps.
    """

    def __init__(self, move_times: MoveTimes | None = None, capture_time_sd_s: float = 0.02):
        slopes = None if move_times is None else np.array([move_times.pan[1], move_times.tilt[1], move_times.zoom[1]])
        self.speeds = 1.0 / slopes if slopes is not None and np.all(slopes > 0) else None
        self.capture_time_sd_s, self.move_times = capture_time_sd_s, move_times
        self._condition = threading.Condition()
        self._samples: deque[tuple[float, np.ndarray, bool]] = deque()
        self._target: tuple[float, np.ndarray] | None = None
        self._lands_s = -np.inf

    def sample(self, time_s: float, pose, moving: bool) -> None:
        """A GetStatus answer: the pose (3,) at ``time_s`` and whether it was moving."""
        with self._condition:
            self._samples.append((time_s, np.asarray(pose, dtype=float), moving))
            while self._samples[0][0] < time_s - KEEP_S:
                self._samples.popleft()
            self._condition.notify_all()

    def sent(self, time_s: float, target) -> None:
        """A move to ``target`` (3,) sent at ``time_s``: it lands no sooner than the move-time model takes
        from where the camera was then."""
        target = np.asarray(target, dtype=float)
        here = self.at(time_s)
        move_s = 0.0
        if here is not None and self.move_times is not None:
            move_s = float(self.move_times.seconds(here.pose, target))
        with self._condition:
            self._target = (time_s, target)
            self._lands_s = time_s + move_s

    def settled(self, time_s: float) -> bool:
        """Whether a picture captured at ``time_s`` shows the camera at rest where its last move took it:
        standing still then (no spread), the samples either side of it not moving (a camera says it moves
        from a command on, before its pose changes), and no sooner than that move could land."""
        at = self.at(time_s)
        return at is not None and not np.any(at.sd > 0) and self._still_since_landing(time_s)

    def _still_since_landing(self, time_s: float) -> bool:
        """Whether ``time_s`` is no sooner than the last move could land and the samples at or before it
        and after it (the nearest each side) do not say the camera moves."""
        with self._condition:
            samples, lands_s = list(self._samples), self._lands_s
        after = int(np.searchsorted([sample[0] for sample in samples], time_s, side="right"))
        around = samples[max(after - 1, 0) : after + 1]
        return time_s >= lands_s and not any(moving for _, _, moving in around)

    def wait_past(self, time_s: float, timeout_s: float) -> bool:
        """Wait at most ``timeout_s`` for a sample at ``time_s`` or later; whether there is one."""
        with self._condition:
            return self._condition.wait_for(lambda: bool(self._samples) and self._samples[-1][0] >= time_s, timeout_s)

    def moving(self) -> bool:
        """Whether the camera may be moving: its last sample said so, or a target went out after it."""
        with self._condition:
            if not self._samples:
                return self._target is not None
            last_s, _, moving = self._samples[-1]
            return moving or (self._target is not None and self._target[0] >= last_s)

    def begun(self, time_s: float) -> bool:
        """Whether a sample was taken by ``time_s``: a picture captured then that :meth:`at` does not place
        is one that cannot be placed, not one taken before the pose was known."""
        with self._condition:
            return bool(self._samples) and self._samples[0][0] <= time_s

    def at(self, time_s: float) -> PoseAt | None:
        """The pose at ``time_s``; None before the first sample."""
        with self._condition:
            samples, target = list(self._samples), self._target
        if not samples or time_s < samples[0][0]:
            return None
        times = np.array([sample[0] for sample in samples])
        after = max(int(np.searchsorted(times, time_s, side="left")), 1)
        if after < len(samples):
            (t0, p0, _), (t1, p1, _) = samples[after - 1], samples[after]
            fraction = (time_s - t0) / (t1 - t0) if t1 > t0 else 1.0
            speed = np.abs(p1 - p0) / max(t1 - t0, 1e-9)
            return PoseAt(p0 + fraction * (p1 - p0), speed * self.capture_time_sd_s)
        return self._past_last(time_s, samples[-1], target)

    def _past_last(self, time_s: float, last, target) -> PoseAt:
        t_last, pose, moving = last
        heading = target[1] if target is not None and (target[0] >= t_last or moving) else pose
        remaining = heading - pose
        if self.speeds is None:
            return PoseAt(pose, np.abs(remaining) / np.sqrt(3.0))
        elapsed_s = time_s - t_last
        covered = np.minimum(self.speeds * elapsed_s, np.abs(remaining))
        spread = self.speeds * np.sqrt(self.capture_time_sd_s**2 + elapsed_s**2 / 3.0)
        return PoseAt(pose + np.sign(remaining) * covered, np.minimum(spread, np.abs(remaining)))
