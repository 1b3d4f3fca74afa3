"""Where a camera that reports no positions was at any moment: the poses registered from its own
pictures (:mod:`ptztrack.geometry.registration`), each at its picture's capture time.

A :class:`RegisteredTimeline` is a :class:`~ptztrack.camera.pose_timeline.PoseTimeline` whose samples
are registered poses, each with its standard deviation ``sd`` (3,). A picture is placed only by its
own registration, at the pose registered from it, its standard deviation
``sqrt(sd_timeline^2 + sd_registered^2)`` per axis (``sd_timeline``, the turn over the capture time's
uncertainty, as the timeline gives it); a picture that did not register is not placed (None), and the
live loop's detector skips it.

A sample is *moving* when its pose differs from the one before by more than ``MOVED_SDS`` times the
two samples' combined standard deviation on any axis, when it was captured before the last move sent
could land (its move-time model), or when no sample since that move has shown the camera away from
where the move started (a stream later than its calibrated delay shows the camera still before it
moves; a move that shows nothing by ``MOVE_SEEN_S`` after its landing is not waited for longer).
The camera stands still where it was last registered until it
is sent elsewhere, so a picture that does not register, ``blind_s`` after the last sample and the last
landing, gives a dead-reckoned sample (:meth:`RegisteredTimeline.dead_reckoned`): where the last
registered sample showed the camera, or where the last move sent after it took it, uncertain by the
sample's ``sd`` and ``DEAD_RECKONING_FRACTION`` of the moves' length since. Such a sample only lets the
next move start (:meth:`~RegisteredTimeline.current`, :meth:`~RegisteredTimeline.ready`), so a camera
that stands where nothing registers can be sent back; no picture is placed by it.
"""

from collections import deque
from collections.abc import Callable

import numpy as np

from ptztrack.camera.onvif_spaces import MoveTimes
from ptztrack.camera.pose_timeline import KEEP_S, PoseAt, PoseTimeline

# A registered pose is taken as moving when it is further from the one before than this many of their
# combined standard deviations on an axis: registration noise alone exceeds it on one of three axes once
# in about 120 samples.
MOVED_SDS = 3.0
# A sample is a picture's own when their capture times are this close: they are the same number, and
# pictures are tens of milliseconds apart.
SAME_PICTURE_S = 1e-6
# A move that no registered pose has shown by this long after its landing is taken as done: a priori.
MOVE_SEEN_S = 1.0
# Pictures that do not register are skipped, and after this long since the last sample and the last
# landing the moves go on by dead reckoning: a priori, a second of a camera that may stand where nothing
# registers.
BLIND_S = 1.0
# A relative move lands within this fraction of its length per axis: a priori, a calibration's degrees
# per unit of the normalised space off by 5 %.
DEAD_RECKONING_FRACTION = 0.05


class RegisteredTimeline(PoseTimeline):
    """Registered poses and the moves sent, shared between threads (module docstring).

    move_times, capture_time_sd_s : as :class:`PoseTimeline` takes them; blind_s : how long after the
    last sample pictures that do not register give dead-reckoned samples. ``asked`` is called whenever
    a thread waits for the pose of a picture (:meth:`wait_past`), which :meth:`wanted` then gives.
    """

    def __init__(
        self,
        move_times: MoveTimes | None = None,
        capture_time_sd_s: float = 0.02,
        blind_s: float = BLIND_S,
    ):
        super().__init__(move_times, capture_time_sd_s)
        self.blind_s = blind_s
        self._sds: deque[np.ndarray] = deque()  # each sample's sd (3,), in step with the samples
        self._reckoned: deque[bool] = deque()  # whether each sample is dead-reckoned, in step with them
        self._moved_from: np.ndarray | None = None  # where the last move was sent from
        self._seen = True  # whether a sample has shown the last move
        self._wanted_s: float | None = None  # the capture time a thread waits for, not yet handed out
        self.asked: Callable[[], None] = lambda: None

    def registered(self, time_s: float, pose, sd) -> bool:
        """A pose (3,) registered from the picture captured at ``time_s``, with its sd (3,); whether it
        is moving (module docstring)."""
        pose, sd = np.asarray(pose, dtype=float), np.asarray(sd, dtype=float)
        with self._condition:
            moving = time_s < self._lands_s
            if self._samples:
                _, before, _ = self._samples[-1]
                limit = MOVED_SDS * np.sqrt(sd**2 + self._sds[-1] ** 2)
                moving = moving or bool(np.any(np.abs(pose - before) > limit))
                if not self._seen and self._target is not None and self._moved_from is not None:
                    self._seen = time_s >= self._target[0] and bool(np.any(np.abs(pose - self._moved_from) > limit))
                    moving = moving or (not self._seen and time_s < self._lands_s + MOVE_SEEN_S)
            self._append(time_s, pose, moving, sd, reckoned=False)
        return moving

    def dead_reckoned(self, time_s: float) -> bool:
        """Add a dead-reckoned sample for the picture captured at ``time_s``, which did not register, once
        ``blind_s`` has passed since the last sample and the last landing; whether it was added."""
        with self._condition:
            if not self._samples:
                return False
            last_s, pose, _ = self._samples[-1]
            if time_s < max(last_s, self._lands_s) + self.blind_s:
                return False
            sd = self._sds[-1]
            if self._target is not None and self._target[0] >= last_s and self._moved_from is not None:
                sd = sd + DEAD_RECKONING_FRACTION * np.abs(self._target[1] - self._moved_from)
                pose = self._target[1]
            self._append(time_s, pose, False, sd, reckoned=True)
        return True

    def wait_past(self, time_s: float, timeout_s: float) -> bool:
        """Ask for the pose of the picture captured at ``time_s`` and wait at most ``timeout_s`` for a
        sample at that time or later; whether there is one."""
        with self._condition:
            if not (self._samples and self._samples[-1][0] >= time_s):
                self._wanted_s = time_s if self._wanted_s is None else max(self._wanted_s, time_s)
        self.asked()
        return super().wait_past(time_s, timeout_s)

    def wanted(self) -> float | None:
        """The newest capture time a thread has asked the pose of since the last call, None if none."""
        with self._condition:
            wanted_s, self._wanted_s = self._wanted_s, None
        return wanted_s

    def newest_s(self) -> float:
        """The capture time of the newest sample; -inf before any."""
        with self._condition:
            return self._samples[-1][0] if self._samples else -np.inf

    def current(self) -> np.ndarray | None:
        """Where the camera stands for a move to start from: the newest sample if it was captured once
        the last move could have landed, else that move's target; None before any."""
        with self._condition:
            newest = self._samples[-1] if self._samples else None
            if newest is not None and (self._target is None or newest[0] >= self._lands_s):
                return newest[1].copy()
            return None if self._target is None else self._target[1].copy()

    def ready(self, time_s: float) -> bool:
        """Whether a new move may be sent at ``time_s``: a pose to start from is known, the last move
        could have landed, and no picture since it shows the camera moving."""
        with self._condition:
            newest = self._samples[-1] if self._samples else None
            if self._target is None:
                return newest is not None
            if time_s < self._lands_s:
                return False
            return newest is None or newest[0] < self._target[0] or not newest[2]

    def sent(self, time_s: float, target) -> None:
        """A move to ``target`` (3,) sent at ``time_s`` from :meth:`current`: it lands no sooner than the
        move-time model takes."""
        target = np.asarray(target, dtype=float)
        here = self.current()
        move_s = 0.0
        if here is not None and self.move_times is not None:
            move_s = float(self.move_times.seconds(here, target))
        with self._condition:
            self._target, self._moved_from = (time_s, target), here
            self._lands_s = time_s + move_s
            # A move within the registration's noise shows nothing to wait for.
            noise = MOVED_SDS * np.sqrt(2.0) * (self._sds[-1] if self._sds else 0.0)
            self._seen = here is None or not np.any(np.abs(target - here) > noise)

    def at(self, time_s: float) -> PoseAt | None:
        """The pose of the picture captured at ``time_s`` from its own registration; None where it did
        not register."""
        with self._condition:
            own = [
                sd
                for (sample_s, _, _), sd, reckoned in zip(self._samples, self._sds, self._reckoned, strict=True)
                if abs(sample_s - time_s) <= SAME_PICTURE_S and not reckoned
            ]
        placed = super().at(time_s) if own else None
        if placed is None:
            return None
        return PoseAt(placed.pose, np.sqrt(placed.sd**2 + own[-1] ** 2))

    def settled(self, time_s: float) -> bool:
        """Whether a picture captured at ``time_s`` shows the camera at rest where its last move took it:
        it has a sample of its own (registered, or dead-reckoned: the camera stands where its moves took
        it, and the next may start), the samples either side of it are not moving, and it was captured
        no sooner than that move could land."""
        with self._condition:
            times = np.array([sample[0] for sample in self._samples])
        return bool(np.any(np.abs(times - time_s) <= SAME_PICTURE_S)) and self._still_since_landing(time_s)

    def _append(self, time_s: float, pose: np.ndarray, moving: bool, sd: np.ndarray, reckoned: bool) -> None:
        """Add a sample (the condition held), dropping those older than KEEP_S, and wake the waiting."""
        self._samples.append((time_s, pose, moving))
        self._sds.append(sd)
        self._reckoned.append(reckoned)
        while self._samples[0][0] < time_s - KEEP_S:
            self._samples.popleft()
            self._sds.popleft()
            self._reckoned.popleft()
        self._condition.notify_all()
